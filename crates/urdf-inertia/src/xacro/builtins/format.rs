//! `str.format` and `%` formatting, with Python's `repr` of floats and its `e`, `f`, `g` conversions.

use crate::xacro::value::Value;

/// `str.format`: `{}`, `{0}`, `{name}`, with a format spec (`{:.3f}`, `{:>8}`, `{:d}`).
pub(super) fn str_format(
    fmt: &str,
    args: &[Value],
    kwargs: &[(String, Value)],
) -> Result<String, String> {
    let mut out = String::new();
    let mut auto = 0;
    let mut chars = fmt.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '{' if chars.peek() == Some(&'{') => {
                chars.next();
                out.push('{');
            }
            '}' if chars.peek() == Some(&'}') => {
                chars.next();
                out.push('}');
            }
            '{' => {
                let mut field = String::new();
                for d in chars.by_ref() {
                    if d == '}' {
                        break;
                    }
                    field.push(d);
                }
                let (key, spec) = field.split_once(':').unwrap_or((&field, ""));
                let v = if key.is_empty() {
                    auto += 1;
                    args.get(auto - 1)
                } else if let Ok(k) = key.parse::<usize>() {
                    args.get(k)
                } else {
                    kwargs.iter().find(|(k, _)| k == key).map(|(_, v)| v)
                };
                let v = v.ok_or_else(|| format!("format: no argument for {{{field}}}"))?;
                out.push_str(&format_spec(v, spec)?);
            }
            c => out.push(c),
        }
    }
    Ok(out)
}

/// One `format()` spec: `[[fill]align][sign][0][width][.precision][type]`.
fn format_spec(v: &Value, spec: &str) -> Result<String, String> {
    if spec.is_empty() {
        return Ok(v.to_py_str());
    }
    let mut rest = spec;
    let mut align = None;
    let mut fill = ' ';
    let cs: Vec<char> = rest.chars().collect();
    if cs.len() >= 2 && matches!(cs[1], '<' | '>' | '^' | '=') {
        fill = cs[0];
        align = Some(cs[1]);
        rest = &rest[cs[0].len_utf8() + 1..];
    } else if !cs.is_empty() && matches!(cs[0], '<' | '>' | '^' | '=') {
        align = Some(cs[0]);
        rest = &rest[1..];
    }
    let mut flags = String::new();
    while let Some(c) = rest
        .chars()
        .next()
        .filter(|c| matches!(c, '+' | '-' | ' ' | '0'))
    {
        flags.push(c);
        rest = &rest[1..];
    }
    let conv = rest.chars().last().filter(char::is_ascii_alphabetic);
    if conv.is_some() {
        rest = &rest[..rest.len() - 1];
    }
    let pct = format!(
        "%{flags}{rest}{}",
        conv.unwrap_or(match v {
            Value::Int(_) | Value::Bool(_) => 'd',
            Value::Float(_) => 'r',
            _ => 's',
        })
    );
    let body = if pct.ends_with('r') && matches!(v, Value::Float(_)) {
        // No type with a float: str(), padded.
        let w: usize = rest.trim_start_matches('0').parse().unwrap_or(0);
        format!("{:>w$}", v.to_py_str())
    } else {
        percent_one(&pct, v)?
    };
    Ok(match align {
        Some(a) => {
            let w: usize = rest.split('.').next().unwrap_or("").parse().unwrap_or(0);
            let body = body.trim_start().to_string();
            let n = body.chars().count();
            if n >= w {
                body
            } else {
                let pad = w - n;
                let fills = |k: usize| fill.to_string().repeat(k);
                match a {
                    '<' => format!("{body}{}", fills(pad)),
                    '^' => format!("{}{body}{}", fills(pad / 2), fills(pad - pad / 2)),
                    _ => format!("{}{body}", fills(pad)),
                }
            }
        }
        None => body,
    })
}

/// `fmt % args` (printf-style): `%s %r %d %i %f %F %e %E %g %G %x %o %%`, flags `-+ 0#`, width,
/// precision; `args` a tuple, a dict (for `%(name)s`) or a single value.
pub fn percent_format(fmt: &str, args: &Value) -> Result<Value, String> {
    let list: Vec<Value> = match args {
        Value::Tuple(t) => t.to_vec(),
        other => vec![other.clone()],
    };
    let mut next = 0;
    let mut out = String::new();
    let b: Vec<char> = fmt.chars().collect();
    let mut i = 0;
    while i < b.len() {
        if b[i] != '%' {
            out.push(b[i]);
            i += 1;
            continue;
        }
        let start = i;
        i += 1;
        let mut key = None;
        if b.get(i) == Some(&'(') {
            let close = b[i..]
                .iter()
                .position(|c| *c == ')')
                .ok_or("incomplete format key")?;
            key = Some(b[i + 1..i + close].iter().collect::<String>());
            i += close + 1;
        }
        while i < b.len() && !b[i].is_ascii_alphabetic() && b[i] != '%' {
            i += 1;
        }
        let Some(&conv) = b.get(i) else {
            return Err("incomplete format".into());
        };
        i += 1;
        if conv == '%' {
            out.push('%');
            continue;
        }
        let spec: String = std::iter::once('%')
            .chain(b[start + 1..i].iter().copied())
            .collect();
        let spec = match &key {
            Some(k) => spec.replacen(&format!("({k})"), "", 1),
            None => spec,
        };
        let v = if let Some(k) = &key {
            match args {
                Value::Dict(d) => d
                    .get(&Value::str(k))
                    .cloned()
                    .ok_or_else(|| format!("KeyError: '{k}'"))?,
                _ => return Err("format requires a mapping".into()),
            }
        } else {
            let v = list
                .get(next)
                .cloned()
                .ok_or("not enough arguments for format string")?;
            next += 1;
            v
        };
        out.push_str(&percent_one(&spec, &v)?);
    }
    if key_free(fmt) && next < list.len() && !matches!(args, Value::Dict(_)) {
        return Err("not all arguments converted during string formatting".into());
    }
    Ok(Value::str(&out))
}

fn key_free(fmt: &str) -> bool {
    !fmt.contains("%(")
}

/// One conversion: `spec` is `%[flags][width][.precision]type`.
fn percent_one(spec: &str, v: &Value) -> Result<String, String> {
    let body = &spec[1..];
    let conv = body.chars().last().unwrap_or('s');
    let mut flags = String::new();
    let mut rest = &body[..body.len() - conv.len_utf8()];
    while let Some(c) = rest
        .chars()
        .next()
        .filter(|c| matches!(c, '-' | '+' | ' ' | '0' | '#'))
    {
        flags.push(c);
        rest = &rest[1..];
    }
    let (w, p) = rest
        .split_once('.')
        .map_or((rest, None), |(w, p)| (w, Some(p)));
    let width: usize = w.parse().unwrap_or(0);
    let prec: Option<usize> = p.map(|p| p.parse().unwrap_or(0));
    let sign = |neg: bool| {
        if neg {
            "-"
        } else if flags.contains('+') {
            "+"
        } else if flags.contains(' ') {
            " "
        } else {
            ""
        }
    };
    let (neg, digits) = convert(conv, v, prec, flags.contains('#'))?;
    let digits = if matches!(conv, 's' | 'r' | 'a') {
        prec.map_or(digits.clone(), |p| digits.chars().take(p).collect())
    } else {
        digits
    };
    let s = sign(neg);
    let len = s.len() + digits.chars().count();
    if len >= width {
        return Ok(format!("{s}{digits}"));
    }
    let pad = width - len;
    Ok(if flags.contains('-') {
        format!("{s}{digits}{}", " ".repeat(pad))
    } else if flags.contains('0') && !matches!(conv, 's' | 'r' | 'a') {
        format!("{s}{}{digits}", "0".repeat(pad))
    } else {
        format!("{}{s}{digits}", " ".repeat(pad))
    })
}

/// One conversion's sign and digits (`%d`, `%f`, …) before padding.
fn convert(
    conv: char,
    v: &Value,
    prec: Option<usize>,
    alt: bool,
) -> Result<(bool, String), String> {
    let num = || {
        v.as_f64().ok_or_else(|| {
            format!(
                "%{conv} format: a number is required, not {}",
                v.type_name()
            )
        })
    };
    Ok(match conv {
        's' | 'c' => (false, v.to_py_str()),
        'r' | 'a' => (false, v.repr()),
        'd' | 'i' | 'u' => {
            let x = match v {
                Value::Int(i) => *i,
                Value::Bool(b) => i64::from(*b),
                _ => {
                    let f = num()?;
                    if !f.is_finite() {
                        return Err("cannot convert float to integer".into());
                    }
                    f.trunc() as i64
                }
            };
            (x < 0, x.unsigned_abs().to_string())
        }
        'x' | 'X' | 'o' => {
            let Value::Int(x) = v else {
                return Err(format!("%{conv} format: an integer is required"));
            };
            let a = x.unsigned_abs();
            (
                *x < 0,
                match conv {
                    'x' => format!("{a:x}"),
                    'X' => format!("{a:X}"),
                    _ => format!("{a:o}"),
                },
            )
        }
        'f' | 'F' => {
            let x = num()?;
            (x.is_sign_negative(), fixed(x.abs(), prec.unwrap_or(6)))
        }
        'e' | 'E' => {
            let x = num()?;
            let s = sci(x.abs(), prec.unwrap_or(6));
            (x < 0.0, if conv == 'E' { s.to_uppercase() } else { s })
        }
        'g' | 'G' => {
            let x = num()?;
            let s = general(x.abs(), prec.unwrap_or(6), alt);
            (x < 0.0, if conv == 'G' { s.to_uppercase() } else { s })
        }
        other => return Err(format!("unsupported format character '{other}'")),
    })
}

fn fixed(x: f64, prec: usize) -> String {
    if !x.is_finite() {
        return non_finite(x);
    }
    format!("{x:.prec$}")
}

fn non_finite(x: f64) -> String {
    if x.is_nan() { "nan" } else { "inf" }.into()
}

/// `%e`: mantissa with `prec` decimals, exponent with a sign and at least two digits.
fn sci(x: f64, prec: usize) -> String {
    if !x.is_finite() {
        return non_finite(x);
    }
    let s = format!("{x:.prec$e}");
    let (m, e) = s.split_once('e').unwrap_or((&s, "0"));
    let e: i32 = e.parse().unwrap_or(0);
    format!("{m}e{}{:02}", if e < 0 { '-' } else { '+' }, e.abs())
}

/// `%g`: `prec` significant digits, scientific when the exponent is below -4 or at least `prec`,
/// trailing zeros removed (kept with `#`).
fn general(x: f64, prec: usize, keep_zeros: bool) -> String {
    if !x.is_finite() {
        return non_finite(x);
    }
    let p = prec.max(1);
    if x == 0.0 {
        return if keep_zeros {
            format!("{:.*}", p - 1, 0.0)
        } else {
            "0".into()
        };
    }
    let s = format!("{x:.*e}", p - 1);
    let exp: i32 = s
        .split_once('e')
        .and_then(|(_, e)| e.parse().ok())
        .unwrap_or(0);
    let strip = |t: String| {
        if keep_zeros || !t.contains('.') {
            t
        } else {
            t.trim_end_matches('0').trim_end_matches('.').to_string()
        }
    };
    if exp < -4 || exp >= p as i32 {
        let (m, _) = s.split_once('e').unwrap_or((&s, ""));
        format!(
            "{}e{}{:02}",
            strip(m.to_string()),
            if exp < 0 { '-' } else { '+' },
            exp.abs()
        )
    } else {
        strip(format!("{x:.*}", (p as i32 - 1 - exp).max(0) as usize))
    }
}
