//! The builtin functions and methods xacro exposes to expressions (those that need no files): Python's
//! `len str float int bool list dict min max round sorted range abs sum any all zip …`, `math.*`,
//! `xacro.dotify`/`tokenize`, string, dict and list methods, and `%` / `str.format` formatting.

use super::expr::items;
use super::value::{float_repr, py_eq, Dict, Value};
use std::rc::Rc;

fn arity(name: &str, args: &[Value], lo: usize, hi: usize) -> Result<(), String> {
    if args.len() < lo || args.len() > hi {
        let want = if lo == hi {
            format!("{lo}")
        } else {
            format!("{lo} to {hi}")
        };
        return Err(format!(
            "{name}() takes {want} argument(s), {} given",
            args.len()
        ));
    }
    Ok(())
}

fn f(v: &Value, name: &str) -> Result<f64, String> {
    v.as_f64().ok_or_else(|| {
        format!(
            "{name}() needs a number, not {} {}",
            v.type_name(),
            v.repr()
        )
    })
}

/// Python's `int(text)`: optional sign and surrounding whitespace, no fraction.
pub fn parse_int(s: &str) -> Option<i64> {
    let t = s.trim();
    if t.contains('_') {
        return None;
    }
    t.parse::<i64>().ok()
}

/// Python's `float(text)`.
pub fn parse_float(s: &str) -> Option<f64> {
    let t = s.trim();
    if t.is_empty() || t.contains('_') {
        return None;
    }
    let lower = t.to_ascii_lowercase();
    let body = lower.trim_start_matches(['+', '-']);
    if matches!(body, "inf" | "infinity" | "nan") {
        let neg = lower.starts_with('-');
        return Some(match (body, neg) {
            ("nan", _) => f64::NAN,
            (_, true) => f64::NEG_INFINITY,
            _ => f64::INFINITY,
        });
    }
    // Rust accepts forms Python does not ("1." and ".5" both parse in Python too).
    if !t
        .chars()
        .all(|c| c.is_ascii_digit() || matches!(c, '.' | 'e' | 'E' | '+' | '-'))
    {
        return None;
    }
    t.parse().ok()
}

/// Round half to even, as Python's `round(x)`.
fn round_even(x: f64) -> f64 {
    let r = x.round();
    if (x - x.trunc()).abs() == 0.5 {
        2.0 * (x / 2.0).round()
    } else {
        r
    }
}

fn to_int(v: &Value) -> Result<Value, String> {
    Ok(Value::Int(match v {
        Value::Int(i) => *i,
        Value::Bool(b) => i64::from(*b),
        Value::Float(x) => {
            if !x.is_finite() || x.abs() >= 9.2e18 {
                return Err(format!(
                    "cannot convert float {} to integer",
                    float_repr(*x)
                ));
            }
            x.trunc() as i64
        }
        Value::Str(s) => parse_int(s)
            .ok_or_else(|| format!("invalid literal for int() with base 10: {}", v.repr()))?,
        other => return Err(format!("int() cannot convert {}", other.type_name())),
    }))
}

fn to_float(v: &Value) -> Result<Value, String> {
    Ok(Value::Float(match v {
        Value::Str(s) => parse_float(s)
            .ok_or_else(|| format!("could not convert string to float: {}", v.repr()))?,
        other => f(other, "float")?,
    }))
}

fn extreme(name: &str, args: &[Value], want_max: bool) -> Result<Value, String> {
    let pool = if args.len() == 1 {
        items(&args[0])?
    } else {
        args.to_vec()
    };
    let mut best: Option<Value> = None;
    for v in pool {
        best = Some(match best {
            None => v,
            Some(b) => {
                let less = super::expr::less(&v, &b)?;
                let greater = super::expr::less(&b, &v)?;
                if (want_max && greater) || (!want_max && less) {
                    v
                } else {
                    b
                }
            }
        });
    }
    best.ok_or_else(|| format!("{name}() arg is an empty sequence"))
}

/// A builtin function by qualified name.
pub fn call(name: &str, args: &[Value], kwargs: &[(String, Value)]) -> Result<Value, String> {
    let short = name.rsplit('.').next().unwrap_or(name);
    if !kwargs.is_empty() && !matches!(short, "dict" | "round" | "sorted" | "dotify") {
        return Err(format!("{short}() takes no keyword arguments"));
    }
    if let Some(m) = name.strip_prefix("math.") {
        return math(m, args);
    }
    match short {
        "len" => {
            arity(short, args, 1, 1)?;
            Ok(Value::Int(match &args[0] {
                Value::Str(s) => s.chars().count(),
                Value::List(l) | Value::Tuple(l) => l.len(),
                Value::Dict(d) => d.entries.len(),
                other => {
                    return Err(format!(
                        "object of type '{}' has no len()",
                        other.type_name()
                    ))
                }
            } as i64))
        }
        "str" => {
            arity(short, args, 0, 1)?;
            Ok(Value::str(
                &args.first().map_or_else(String::new, Value::to_py_str),
            ))
        }
        "repr" => {
            arity(short, args, 1, 1)?;
            Ok(Value::str(&args[0].repr()))
        }
        "float" => {
            arity(short, args, 0, 1)?;
            args.first().map_or(Ok(Value::Float(0.0)), to_float)
        }
        "int" => {
            arity(short, args, 0, 1)?;
            args.first().map_or(Ok(Value::Int(0)), to_int)
        }
        "bool" => {
            arity(short, args, 0, 1)?;
            Ok(Value::Bool(args.first().is_some_and(Value::truthy)))
        }
        "abs" => {
            arity(short, args, 1, 1)?;
            match &args[0] {
                Value::Int(i) => Ok(Value::Int(i.checked_abs().ok_or("integer overflow")?)),
                Value::Bool(b) => Ok(Value::Int(i64::from(*b))),
                v => Ok(Value::Float(f(v, "abs")?.abs())),
            }
        }
        "round" => round(args, kwargs),
        "min" | "max" => extreme(short, args, short == "max"),
        _ => call_sequence(short, args, kwargs),
    }
}

/// Builtins over sequences.
fn call_sequence(short: &str, args: &[Value], kwargs: &[(String, Value)]) -> Result<Value, String> {
    match short {
        "list" | "tuple" => {
            arity(short, args, 0, 1)?;
            let v = args.first().map_or(Ok(Vec::new()), items)?;
            Ok(if short == "list" {
                Value::List(Rc::new(v))
            } else {
                Value::Tuple(Rc::new(v))
            })
        }
        "sorted" => {
            arity(short, args, 1, 1)?;
            let mut v = items(&args[0])?;
            let mut err = None;
            v.sort_by(|a, b| {
                super::expr::order(a, b).unwrap_or_else(|| {
                    err = Some(format!(
                        "'<' not supported between '{}' and '{}'",
                        a.type_name(),
                        b.type_name()
                    ));
                    std::cmp::Ordering::Equal
                })
            });
            if let Some(e) = err {
                return Err(e);
            }
            if kwargs.iter().any(|(k, v)| k == "reverse" && v.truthy()) {
                v.reverse();
            }
            Ok(Value::List(Rc::new(v)))
        }
        "reversed" => {
            arity(short, args, 1, 1)?;
            let mut v = items(&args[0])?;
            v.reverse();
            Ok(Value::List(Rc::new(v)))
        }
        "range" => range(args),
        "sum" => {
            arity(short, args, 1, 2)?;
            let mut acc = args.get(1).cloned().unwrap_or(Value::Int(0));
            for v in items(&args[0])? {
                acc = super::expr::binary_op("+", &acc, &v)?;
            }
            Ok(acc)
        }
        "any" | "all" => {
            arity(short, args, 1, 1)?;
            let v = items(&args[0])?;
            Ok(Value::Bool(if short == "any" {
                v.iter().any(Value::truthy)
            } else {
                v.iter().all(Value::truthy)
            }))
        }
        "zip" => {
            let lists = args.iter().map(items).collect::<Result<Vec<_>, _>>()?;
            let n = lists.iter().map(Vec::len).min().unwrap_or(0);
            Ok(Value::List(Rc::new(
                (0..n)
                    .map(|k| Value::Tuple(Rc::new(lists.iter().map(|l| l[k].clone()).collect())))
                    .collect(),
            )))
        }
        "enumerate" => {
            arity(short, args, 1, 1)?;
            Ok(Value::List(Rc::new(
                items(&args[0])?
                    .into_iter()
                    .enumerate()
                    .map(|(k, v)| Value::Tuple(Rc::new(vec![Value::Int(k as i64), v])))
                    .collect(),
            )))
        }
        _ => call_other(short, args, kwargs),
    }
}

/// The remaining builtins: dicts, `xacro.tokenize`, `ord`, `divmod`.
fn call_other(short: &str, args: &[Value], kwargs: &[(String, Value)]) -> Result<Value, String> {
    match short {
        "dict" | "dotify" => {
            let mut d = match args.first() {
                Some(Value::Dict(d)) => (**d).clone(),
                Some(other) => {
                    let mut d = Dict::default();
                    for pair in items(other)? {
                        let kv = items(&pair)?;
                        if kv.len() != 2 {
                            return Err("dict() needs pairs".into());
                        }
                        d.insert(kv[0].clone(), kv[1].clone());
                    }
                    d
                }
                None => Dict::default(),
            };
            for (k, v) in kwargs {
                d.insert(Value::str(k), v.clone());
            }
            d.dotted = short == "dotify";
            Ok(Value::Dict(Rc::new(d)))
        }
        "tokenize" => {
            arity(short, args, 1, 3)?;
            let s = args[0].to_py_str();
            let sep = args
                .get(1)
                .map_or_else(|| ",; ".to_string(), Value::to_py_str);
            let skip_empty = args.get(2).is_none_or(Value::truthy);
            Ok(Value::List(Rc::new(
                s.split(|c| sep.contains(c))
                    .filter(|p| !skip_empty || !p.is_empty())
                    .map(Value::str)
                    .collect(),
            )))
        }
        "ord" => {
            arity(short, args, 1, 1)?;
            let s = args[0].to_py_str();
            let mut cs = s.chars();
            match (cs.next(), cs.next()) {
                (Some(c), None) => Ok(Value::Int(i64::from(u32::from(c)))),
                _ => Err("ord() expected a character".into()),
            }
        }
        "divmod" => {
            arity(short, args, 2, 2)?;
            Ok(Value::Tuple(Rc::new(vec![
                super::expr::binary_op("//", &args[0], &args[1])?,
                super::expr::binary_op("%", &args[0], &args[1])?,
            ])))
        }
        other => Err(format!(
            "{other}() is not supported in xacro expressions here"
        )),
    }
}

fn round(args: &[Value], kwargs: &[(String, Value)]) -> Result<Value, String> {
    let nd = args
        .get(1)
        .or_else(|| kwargs.iter().find(|(k, _)| k == "ndigits").map(|(_, v)| v));
    arity("round", args, 1, 2)?;
    let nd = match nd {
        None | Some(Value::None) => None,
        Some(Value::Int(n)) => Some(*n),
        Some(other) => {
            return Err(format!(
                "round() ndigits must be an int, not {}",
                other.type_name()
            ))
        }
    };
    match (&args[0], nd) {
        (Value::Int(i), _) => Ok(Value::Int(*i)),
        (v, None) => to_int(&Value::Float(round_even(f(v, "round")?))),
        (v, Some(n)) => {
            let x = f(v, "round")?;
            if !x.is_finite() {
                return Ok(Value::Float(x));
            }
            if n < 0 {
                let p = 10f64.powi(-n as i32);
                return Ok(Value::Float(round_even(x / p) * p));
            }
            // Correctly rounded decimal text, as CPython rounds (half to even on the exact value).
            let text = format!("{x:.*}", n.min(340) as usize);
            Ok(Value::Float(text.parse().unwrap_or(x)))
        }
    }
}

fn range(args: &[Value]) -> Result<Value, String> {
    arity("range", args, 1, 3)?;
    let ints = args
        .iter()
        .map(|a| match a {
            Value::Int(i) => Ok(*i),
            Value::Bool(b) => Ok(i64::from(*b)),
            o => Err(format!("range() needs integers, not {}", o.type_name())),
        })
        .collect::<Result<Vec<i64>, String>>()?;
    let (start, stop, step) = match ints.as_slice() {
        [n] => (0, *n, 1),
        [a, b] => (*a, *b, 1),
        [a, b, c] => (*a, *b, *c),
        _ => unreachable_range(),
    };
    if step == 0 {
        return Err("range() arg 3 must not be zero".into());
    }
    let mut out = Vec::new();
    let mut k = start;
    while (step > 0 && k < stop) || (step < 0 && k > stop) {
        if out.len() >= 1 << 20 {
            return Err("range() too long".into());
        }
        out.push(Value::Int(k));
        k += step;
    }
    Ok(Value::List(Rc::new(out)))
}

fn unreachable_range() -> (i64, i64, i64) {
    (0, 0, 1)
}

fn math(m: &str, args: &[Value]) -> Result<Value, String> {
    let one = |g: fn(f64) -> f64| -> Result<Value, String> {
        arity(m, args, 1, 1)?;
        let x = f(&args[0], m)?;
        let y = g(x);
        if y.is_nan() && !x.is_nan() {
            return Err(format!("math domain error in {m}({})", float_repr(x)));
        }
        Ok(Value::Float(y))
    };
    let two = |g: fn(f64, f64) -> f64| -> Result<Value, String> {
        arity(m, args, 2, 2)?;
        Ok(Value::Float(g(f(&args[0], m)?, f(&args[1], m)?)))
    };
    match m {
        "sin" => one(f64::sin),
        "cos" => one(f64::cos),
        "tan" => one(f64::tan),
        "asin" => one(f64::asin),
        "acos" => one(f64::acos),
        "atan" => one(f64::atan),
        "sinh" => one(f64::sinh),
        "cosh" => one(f64::cosh),
        "tanh" => one(f64::tanh),
        "asinh" => one(f64::asinh),
        "acosh" => one(f64::acosh),
        "atanh" => one(f64::atanh),
        "sqrt" => one(f64::sqrt),
        "exp" => one(f64::exp),
        "expm1" => one(f64::exp_m1),
        "log10" => one(f64::log10),
        "log2" => one(f64::log2),
        "log1p" => one(f64::ln_1p),
        "fabs" => one(f64::abs),
        "radians" => one(f64::to_radians),
        "degrees" => one(f64::to_degrees),
        "atan2" => two(f64::atan2),
        "pow" => two(f64::powf),
        "hypot" => two(f64::hypot),
        "copysign" => two(f64::copysign),
        "fmod" => two(|a, b| a % b),
        "log" => {
            arity(m, args, 1, 2)?;
            let x = f(&args[0], m)?;
            if x <= 0.0 {
                return Err("math domain error in log".into());
            }
            Ok(Value::Float(match args.get(1) {
                Some(b) => x.ln() / f(b, m)?.ln(),
                None => x.ln(),
            }))
        }
        "floor" | "ceil" | "trunc" => {
            arity(m, args, 1, 1)?;
            if let Value::Int(i) = args[0] {
                return Ok(Value::Int(i));
            }
            let x = f(&args[0], m)?;
            to_int(&Value::Float(match m {
                "floor" => x.floor(),
                "ceil" => x.ceil(),
                _ => x.trunc(),
            }))
        }
        "isnan" | "isinf" => {
            arity(m, args, 1, 1)?;
            let x = f(&args[0], m)?;
            Ok(Value::Bool(if m == "isnan" {
                x.is_nan()
            } else {
                x.is_infinite()
            }))
        }
        other => Err(format!("math.{other}() is not supported")),
    }
}

/// A method of a string, dict or list.
pub fn method(
    recv: &Value,
    m: &str,
    args: &[Value],
    kwargs: &[(String, Value)],
) -> Result<Value, String> {
    if !kwargs.is_empty() && m != "format" && m != "split" {
        return Err(format!("{m}() takes no keyword arguments"));
    }
    match recv {
        Value::Str(s) => str_method(s, m, args, kwargs),
        Value::Dict(d) => match m {
            "get" => {
                arity(m, args, 1, 2)?;
                Ok(d.get(&args[0])
                    .cloned()
                    .unwrap_or_else(|| args.get(1).cloned().unwrap_or(Value::None)))
            }
            "keys" => Ok(Value::List(Rc::new(
                d.entries.iter().map(|(k, _)| k.clone()).collect(),
            ))),
            "values" => Ok(Value::List(Rc::new(
                d.entries.iter().map(|(_, v)| v.clone()).collect(),
            ))),
            _ => Ok(Value::List(Rc::new(
                d.entries
                    .iter()
                    .map(|(k, v)| Value::Tuple(Rc::new(vec![k.clone(), v.clone()])))
                    .collect(),
            ))),
        },
        Value::List(l) | Value::Tuple(l) => {
            arity(m, args, 1, 1)?;
            if m == "count" {
                return Ok(Value::Int(
                    l.iter().filter(|v| py_eq(v, &args[0])).count() as i64
                ));
            }
            l.iter()
                .position(|v| py_eq(v, &args[0]))
                .map(|k| Value::Int(k as i64))
                .ok_or_else(|| format!("{} is not in list", args[0].repr()))
        }
        other => Err(format!(
            "'{}' object has no attribute '{m}'",
            other.type_name()
        )),
    }
}

fn strs(args: &[Value]) -> Vec<String> {
    args.iter().map(Value::to_py_str).collect()
}

/// `str.split` and `str.rsplit` (Python's rules for no separator and `maxsplit`).
fn str_split(
    s: &str,
    m: &str,
    args: &[Value],
    kwargs: &[(String, Value)],
) -> Result<Value, String> {
    let list = |v: Vec<&str>| Value::List(Rc::new(v.into_iter().map(Value::str).collect()));
    Ok({
        let sep = args
            .first()
            .or_else(|| kwargs.iter().find(|(k, _)| k == "sep").map(|(_, v)| v))
            .filter(|v| !matches!(v, Value::None))
            .map(Value::to_py_str);
        let max = args
            .get(1)
            .or_else(|| kwargs.iter().find(|(k, _)| k == "maxsplit").map(|(_, v)| v))
            .and_then(|v| {
                if let Value::Int(i) = v {
                    Some(*i)
                } else {
                    None
                }
            })
            .unwrap_or(-1);
        match sep {
            Some(sep) if sep.is_empty() => return Err("empty separator".into()),
            Some(sep) if max < 0 => list(s.split(sep.as_str()).collect()),
            Some(sep) if m == "split" => list(s.splitn(max as usize + 1, sep.as_str()).collect()),
            Some(sep) => {
                let mut v: Vec<&str> = s.rsplitn(max as usize + 1, sep.as_str()).collect();
                v.reverse();
                list(v)
            }
            None => {
                let words: Vec<&str> = s.split_whitespace().collect();
                if max < 0 || words.len() <= max as usize {
                    list(words)
                } else {
                    // Python keeps the rest after `max` splits as one item.
                    let mut out: Vec<&str> = words[..max as usize].to_vec();
                    let mut rest = s.trim_start();
                    for w in &out {
                        rest = rest[rest.find(w).unwrap_or(0) + w.len()..].trim_start();
                    }
                    out.push(rest);
                    list(out)
                }
            }
        }
    })
}

/// `str.zfill` and `str.join`.
fn str_join_zfill(s: &str, m: &str, args: &[Value]) -> Result<Value, String> {
    Ok(match m {
        "zfill" => {
            arity(m, args, 1, 1)?;
            let w = if let Value::Int(i) = args[0] {
                i.max(0) as usize
            } else {
                0
            };
            let n = s.chars().count();
            if n >= w {
                Value::str(s)
            } else {
                let (sign, rest) = if s.starts_with(['+', '-']) {
                    s.split_at(1)
                } else {
                    ("", s)
                };
                Value::str(&format!("{sign}{}{rest}", "0".repeat(w - n)))
            }
        }
        "join" => {
            arity(m, args, 1, 1)?;
            let parts = items(&args[0])?;
            let mut out = Vec::new();
            for p in parts {
                match p {
                    Value::Str(t) => out.push(t.to_string()),
                    other => {
                        return Err(format!(
                            "sequence item: expected str instance, {} found",
                            other.type_name()
                        ))
                    }
                }
            }
            Value::str(&out.join(s))
        }
        _ => Value::None,
    })
}

fn str_method(
    s: &str,
    m: &str,
    args: &[Value],
    kwargs: &[(String, Value)],
) -> Result<Value, String> {
    let a = strs(args);
    Ok(match m {
        "split" | "rsplit" => str_split(s, m, args, kwargs)?,
        "zfill" | "join" => str_join_zfill(s, m, args)?,
        "strip" | "lstrip" | "rstrip" => {
            let set: Option<Vec<char>> = a.first().map(|c| c.chars().collect());
            let pat = |c: char| set.as_ref().map_or(c.is_whitespace(), |s| s.contains(&c));
            Value::str(match m {
                "strip" => s.trim_matches(pat),
                "lstrip" => s.trim_start_matches(pat),
                _ => s.trim_end_matches(pat),
            })
        }
        "lower" => Value::str(&s.to_lowercase()),
        "upper" => Value::str(&s.to_uppercase()),
        "title" | "capitalize" => {
            let mut c = s.chars();
            Value::str(&c.next().map_or_else(String::new, |f| {
                f.to_uppercase().collect::<String>() + &c.as_str().to_lowercase()
            }))
        }
        "isdigit" => Value::Bool(!s.is_empty() && s.chars().all(|c| c.is_ascii_digit())),
        "replace" => {
            arity(m, args, 2, 2)?;
            Value::str(&s.replace(a[0].as_str(), &a[1]))
        }
        "startswith" | "endswith" => {
            arity(m, args, 1, 1)?;
            Value::Bool(if m == "startswith" {
                s.starts_with(a[0].as_str())
            } else {
                s.ends_with(a[0].as_str())
            })
        }
        "find" => {
            arity(m, args, 1, 1)?;
            Value::Int(
                s.find(a[0].as_str())
                    .map_or(-1, |b| s[..b].chars().count() as i64),
            )
        }
        "count" => {
            arity(m, args, 1, 1)?;
            Value::Int(s.matches(a[0].as_str()).count() as i64)
        }
        "format" => Value::str(&str_format(s, args, kwargs)?),
        other => return Err(format!("'str' object has no attribute '{other}'")),
    })
}

/// `str.format`: `{}`, `{0}`, `{name}`, with a format spec (`{:.3f}`, `{:>8}`, `{:d}`).
fn str_format(fmt: &str, args: &[Value], kwargs: &[(String, Value)]) -> Result<String, String> {
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
        let v = match &key {
            Some(k) => match args {
                Value::Dict(d) => d
                    .get(&Value::str(k))
                    .cloned()
                    .ok_or_else(|| format!("KeyError: '{k}'"))?,
                _ => return Err("format requires a mapping".into()),
            },
            None => {
                let v = list
                    .get(next)
                    .cloned()
                    .ok_or("not enough arguments for format string")?;
                next += 1;
                v
            }
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
        's' => (false, v.to_py_str()),
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
        'c' => (false, v.to_py_str()),
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

#[cfg(test)]
mod tests {
    use super::*;

    fn pct(fmt: &str, v: Value) -> String {
        match percent_format(fmt, &v) {
            Ok(s) => s.to_py_str(),
            Err(e) => format!("error: {e}"),
        }
    }

    #[test]
    fn percent_formatting_matches_python() {
        // Expected strings typed from CPython 3.11.
        assert_eq!(pct("%d", Value::Int(42)), "42");
        assert_eq!(pct("%05d", Value::Int(42)), "00042");
        assert_eq!(pct("%-4d|", Value::Int(7)), "7   |");
        assert_eq!(pct("%+.2f", Value::Float(1.23456)), "+1.23");
        assert_eq!(pct("%f", Value::Float(0.5)), "0.500000");
        assert_eq!(pct("%e", Value::Float(12345.678)), "1.234568e+04");
        assert_eq!(pct("%g", Value::Float(0.0001)), "0.0001");
        assert_eq!(pct("%g", Value::Float(0.00001)), "1e-05");
        assert_eq!(pct("%g", Value::Float(1234567.0)), "1.23457e+06");
        assert_eq!(pct("%g", Value::Float(2.5)), "2.5");
        assert_eq!(
            pct(
                "%s and %s",
                Value::Tuple(Rc::new(vec![Value::Int(1), Value::Float(0.5)]))
            ),
            "1 and 0.5"
        );
        assert_eq!(pct("%x", Value::Int(255)), "ff");
        assert_eq!(pct("100%%", Value::Tuple(Rc::new(vec![]))), "100%");
        assert_eq!(
            pct("%d %d", Value::Int(1)),
            "error: not enough arguments for format string"
        );
    }

    #[test]
    fn conversions_match_python() {
        assert_eq!(parse_int(" 12 "), Some(12));
        assert_eq!(parse_int("1.0"), None);
        assert_eq!(parse_int("1_000"), None);
        assert_eq!(parse_float("1e3"), Some(1000.0));
        assert_eq!(parse_float("-inf"), Some(f64::NEG_INFINITY));
        assert_eq!(parse_float("abc"), None);
        assert_eq!(round_even(0.5), 0.0);
        assert_eq!(round_even(1.5), 2.0);
        assert_eq!(round_even(-2.5), -2.0);
    }
}
