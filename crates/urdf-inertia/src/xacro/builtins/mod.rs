//! The builtin functions and methods xacro exposes to expressions (those that need no files): Python's
//! `len str float int bool list dict min max round sorted range abs sum any all zip …`, `math.*`,
//! `xacro.dotify`/`tokenize`, string, dict and list methods, and `%` / `str.format` formatting.

use super::expr::items;
use super::value::{float_repr, Dict, Value};
use std::rc::Rc;

mod format;
mod strings;

pub use format::percent_format;
pub use strings::method;

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

#[cfg(test)]
mod tests {
    use super::*;

    fn pct(fmt: &str, v: &Value) -> String {
        match percent_format(fmt, v) {
            Ok(s) => s.to_py_str(),
            Err(e) => format!("error: {e}"),
        }
    }

    #[test]
    fn percent_formatting_matches_python() {
        // Expected strings typed from CPython 3.11.
        assert_eq!(pct("%d", &Value::Int(42)), "42");
        assert_eq!(pct("%05d", &Value::Int(42)), "00042");
        assert_eq!(pct("%-4d|", &Value::Int(7)), "7   |");
        assert_eq!(pct("%+.2f", &Value::Float(1.23456)), "+1.23");
        assert_eq!(pct("%f", &Value::Float(0.5)), "0.500000");
        assert_eq!(pct("%e", &Value::Float(12345.678)), "1.234568e+04");
        assert_eq!(pct("%g", &Value::Float(0.0001)), "0.0001");
        assert_eq!(pct("%g", &Value::Float(0.00001)), "1e-05");
        assert_eq!(pct("%g", &Value::Float(1234567.0)), "1.23457e+06");
        assert_eq!(pct("%g", &Value::Float(2.5)), "2.5");
        assert_eq!(
            pct(
                "%s and %s",
                &Value::Tuple(Rc::new(vec![Value::Int(1), Value::Float(0.5)]))
            ),
            "1 and 0.5"
        );
        assert_eq!(pct("%x", &Value::Int(255)), "ff");
        assert_eq!(pct("100%%", &Value::Tuple(Rc::new(vec![]))), "100%");
        assert_eq!(
            pct("%d %d", &Value::Int(1)),
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
