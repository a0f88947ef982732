//! xacro's globals (`math`, builtins, modules) and the operators on values: arithmetic with Python's
//! int/float rules, comparison, membership, indexing and slicing.

use crate::xacro::value::{py_eq, Value};
use std::rc::Rc;

/// Whether `name` is one of xacro's global symbols.
pub fn is_global(name: &str) -> bool {
    global(name).is_some()
}

/// Names of xacro's globals, with the builtin each one is.
pub(super) fn global(name: &str) -> Option<Value> {
    let b = |s: &'static str| Some(Value::Builtin(s));
    match name {
        "math" | "python" | "xacro" => Some(Value::Module(match name {
            "math" => "math",
            "python" => "python",
            _ => "xacro",
        })),
        "list" | "dict" | "map" | "len" | "str" | "float" | "int" | "bool" | "min" | "max"
        | "round" | "sorted" | "range" => b(builtin_name(name)?),
        "load_yaml" => b("xacro.load_yaml"),
        "abs_filename" => b("xacro.abs_filename"),
        "dotify" => b("xacro.dotify"),
        _ => math_name(name),
    }
}

fn builtin_name(name: &str) -> Option<&'static str> {
    const NAMES: [&str; 26] = [
        "list",
        "dict",
        "map",
        "len",
        "str",
        "float",
        "int",
        "bool",
        "min",
        "max",
        "round",
        "sorted",
        "range",
        "abs",
        "all",
        "any",
        "divmod",
        "enumerate",
        "filter",
        "ord",
        "repr",
        "reversed",
        "sum",
        "tuple",
        "zip",
        "isinstance",
    ];
    NAMES.into_iter().find(|n| *n == name)
}

fn math_name(name: &str) -> Option<Value> {
    const FNS: [&str; 32] = [
        "math.sin",
        "math.cos",
        "math.tan",
        "math.asin",
        "math.acos",
        "math.atan",
        "math.atan2",
        "math.sinh",
        "math.cosh",
        "math.tanh",
        "math.asinh",
        "math.acosh",
        "math.atanh",
        "math.sqrt",
        "math.exp",
        "math.expm1",
        "math.log",
        "math.log10",
        "math.log2",
        "math.log1p",
        "math.pow",
        "math.fabs",
        "math.floor",
        "math.ceil",
        "math.trunc",
        "math.radians",
        "math.degrees",
        "math.hypot",
        "math.fmod",
        "math.copysign",
        "math.isnan",
        "math.isinf",
    ];
    match name {
        "pi" => return Some(Value::Float(std::f64::consts::PI)),
        "e" => return Some(Value::Float(std::f64::consts::E)),
        "tau" => return Some(Value::Float(std::f64::consts::TAU)),
        "inf" => return Some(Value::Float(f64::INFINITY)),
        "nan" => return Some(Value::Float(f64::NAN)),
        _ => {}
    }
    FNS.into_iter()
        .find(|f| &f[5..] == name)
        .map(Value::Builtin)
}

pub(super) fn module_attr(module: &str, name: &str) -> Option<Value> {
    match module {
        "math" => math_name(name),
        "python" => match name {
            "True" => Some(Value::Bool(true)),
            "False" => Some(Value::Bool(false)),
            _ => builtin_name(name).map(Value::Builtin),
        },
        _ => {
            const XACRO: [&str; 10] = [
                "xacro.load_yaml",
                "xacro.abs_filename",
                "xacro.dotify",
                "xacro.arg",
                "xacro.message",
                "xacro.warning",
                "xacro.error",
                "xacro.print_location",
                "xacro.fatal",
                "xacro.tokenize",
            ];
            XACRO
                .into_iter()
                .find(|f| &f[6..] == name)
                .map(Value::Builtin)
        }
    }
}

pub(super) fn num(v: &Value, what: &str) -> Result<f64, String> {
    v.as_f64()
        .ok_or_else(|| format!("{what} needs a number, not {} {}", v.type_name(), v.repr()))
}

pub(super) fn int_of(v: &Value) -> Option<i64> {
    match v {
        Value::Int(i) => Some(*i),
        Value::Bool(b) => Some(i64::from(*b)),
        _ => None,
    }
}

pub(super) fn overflow() -> String {
    "integer overflow (beyond 64 bits)".into()
}

/// Python's arithmetic on two ints (`/` is true division; `//` and `%` floor).
fn int_op(op: &str, x: i64, y: i64) -> Result<Value, String> {
    use Value::{Float, Int};
    Ok(match op {
        "+" => Int(x.checked_add(y).ok_or_else(overflow)?),
        "-" => Int(x.checked_sub(y).ok_or_else(overflow)?),
        "*" => Int(x.checked_mul(y).ok_or_else(overflow)?),
        "/" => {
            if y == 0 {
                return Err("division by zero".into());
            }
            Float(x as f64 / y as f64)
        }
        "//" => {
            if y == 0 {
                return Err("integer division or modulo by zero".into());
            }
            Int(x.div_euclid(y) - i64::from(y < 0 && x.rem_euclid(y) != 0))
        }
        "%" => {
            if y == 0 {
                return Err("integer division or modulo by zero".into());
            }
            let r = x.rem_euclid(y);
            Int(if y < 0 && r != 0 { r + y } else { r })
        }
        "**" => {
            if y < 0 {
                Float((x as f64).powf(y as f64))
            } else {
                let e = u32::try_from(y).map_err(|_| overflow())?;
                Int(x.checked_pow(e).ok_or_else(overflow)?)
            }
        }
        _ => return Err(format!("unknown operator {op}")),
    })
}

/// `+` and `*` on strings, lists and tuples, and `%` formatting; `None` for numbers.
fn sequence_op(op: &str, a: &Value, b: &Value) -> Result<Option<Value>, String> {
    use Value::{List, Str, Tuple};
    match (op, a, b) {
        ("+", Str(x), Str(y)) => {
            if x.len() + y.len() > crate::xacro::MAX_TEXT {
                return Err("string too long (over 16 MiB)".into());
            }
            return Ok(Some(Value::str(&format!("{x}{y}"))));
        }
        ("+", List(x), List(y)) => {
            return Ok(Some(List(Rc::new(
                x.iter().chain(y.iter()).cloned().collect(),
            ))))
        }
        ("+", Tuple(x), Tuple(y)) => {
            return Ok(Some(Tuple(Rc::new(
                x.iter().chain(y.iter()).cloned().collect(),
            ))))
        }
        ("*", Str(s), n) | ("*", n, Str(s)) if int_of(n).is_some() => {
            let k = int_of(n).unwrap_or(0).max(0) as usize;
            if s.len().saturating_mul(k) > crate::xacro::MAX_TEXT {
                return Err("string repetition too large".into());
            }
            return Ok(Some(Value::str(&s.repeat(k))));
        }
        ("*", List(l), n) | ("*", n, List(l)) if int_of(n).is_some() => {
            let k = int_of(n).unwrap_or(0).max(0) as usize;
            if l.len().saturating_mul(k) > 1 << 20 {
                return Err("list repetition too large".into());
            }
            let mut out = Vec::new();
            for _ in 0..k {
                out.extend(l.iter().cloned());
            }
            return Ok(Some(List(Rc::new(out))));
        }
        ("%", Str(fmt), args) => {
            return crate::xacro::builtins::percent_format(fmt, args).map(Some)
        }
        _ => {}
    }
    Ok(None)
}

/// Python's binary arithmetic.
pub fn binary_op(op: &str, a: &Value, b: &Value) -> Result<Value, String> {
    use Value::Float;
    if let Some(v) = sequence_op(op, a, b)? {
        return Ok(v);
    }
    if let (Some(x), Some(y)) = (int_of(a), int_of(b)) {
        return int_op(op, x, y);
    }
    let (Some(x), Some(y)) = (a.as_f64(), b.as_f64()) else {
        return Err(format!(
            "unsupported operand type(s) for {op}: '{}' and '{}'",
            a.type_name(),
            b.type_name()
        ));
    };
    Ok(Float(match op {
        "+" => x + y,
        "-" => x - y,
        "*" => x * y,
        "/" => {
            if y == 0.0 {
                return Err("float division by zero".into());
            }
            x / y
        }
        "//" => {
            if y == 0.0 {
                return Err("float floor division by zero".into());
            }
            (x / y).floor()
        }
        "%" => {
            if y == 0.0 {
                return Err("float modulo".into());
            }
            let r = x % y;
            if r != 0.0 && (r < 0.0) != (y < 0.0) {
                r + y
            } else {
                r
            }
        }
        "**" => {
            if x < 0.0 && y.fract() != 0.0 {
                return Err("a negative number to a fractional power is complex".into());
            }
            x.powf(y)
        }
        _ => return Err(format!("unknown operator {op}")),
    }))
}

pub(super) fn compare(op: &str, a: &Value, b: &Value) -> Result<bool, String> {
    use std::cmp::Ordering;
    match op {
        "==" => return Ok(py_eq(a, b)),
        "!=" => return Ok(!py_eq(a, b)),
        "in" | "not in" => {
            let found = contains(b, a)?;
            return Ok(found == (op == "in"));
        }
        "is" | "is not" => {
            let same = match (a, b) {
                (Value::None, Value::None) => true,
                (Value::Bool(x), Value::Bool(y)) => x == y,
                _ => false,
            };
            return Ok(same == (op == "is"));
        }
        _ => {}
    }
    let ord = order(a, b).ok_or_else(|| {
        format!(
            "'{op}' not supported between instances of '{}' and '{}'",
            a.type_name(),
            b.type_name()
        )
    })?;
    Ok(match op {
        "<" => ord == Ordering::Less,
        ">" => ord == Ordering::Greater,
        "<=" => ord != Ordering::Greater,
        _ => ord != Ordering::Less,
    })
}

/// Python's ordering of two values (`None` where Python raises `TypeError`).
pub fn order(a: &Value, b: &Value) -> Option<std::cmp::Ordering> {
    match (a, b) {
        (Value::Str(x), Value::Str(y)) => Some(x.cmp(y)),
        (Value::List(x), Value::List(y)) | (Value::Tuple(x), Value::Tuple(y)) => {
            for (p, q) in x.iter().zip(y.iter()) {
                if !py_eq(p, q) {
                    return order(p, q);
                }
            }
            Some(x.len().cmp(&y.len()))
        }
        (Value::Int(x), Value::Int(y)) => Some(x.cmp(y)),
        _ => a.as_f64()?.partial_cmp(&b.as_f64()?),
    }
}

fn contains(container: &Value, item: &Value) -> Result<bool, String> {
    match container {
        Value::Str(s) => match item {
            Value::Str(i) => Ok(s.contains(&**i)),
            other => Err(format!(
                "'in <string>' requires string as left operand, not {}",
                other.type_name()
            )),
        },
        Value::List(l) | Value::Tuple(l) => Ok(l.iter().any(|v| py_eq(v, item))),
        Value::Dict(d) => Ok(d.get(item).is_some()),
        Value::Namespace(_) | Value::Block(_) => Ok(false),
        other => Err(format!(
            "argument of type '{}' is not iterable",
            other.type_name()
        )),
    }
}

/// The items of an iterable (strings give their characters, dicts their keys).
pub fn items(v: &Value) -> Result<Vec<Value>, String> {
    match v {
        Value::List(l) | Value::Tuple(l) => Ok(l.to_vec()),
        Value::Str(s) => Ok(s.chars().map(|c| Value::str(&c.to_string())).collect()),
        Value::Dict(d) => Ok(d.entries.iter().map(|(k, _)| k.clone()).collect()),
        other => Err(format!("'{}' object is not iterable", other.type_name())),
    }
}

fn index_of(i: &Value, len: usize) -> Result<usize, String> {
    let i = int_of(i).ok_or_else(|| format!("indices must be integers, not {}", i.type_name()))?;
    let n = len as i64;
    let k = if i < 0 { i + n } else { i };
    if k < 0 || k >= n {
        return Err(format!("index {i} out of range (length {len})"));
    }
    Ok(k as usize)
}

pub(super) fn subscript(v: &Value, i: &Value) -> Result<Value, String> {
    match v {
        Value::List(l) | Value::Tuple(l) => Ok(l[index_of(i, l.len())?].clone()),
        Value::Str(s) => {
            let chars: Vec<char> = s.chars().collect();
            Ok(Value::str(&chars[index_of(i, chars.len())?].to_string()))
        }
        Value::Dict(d) => d
            .get(i)
            .cloned()
            .ok_or_else(|| format!("KeyError: {}", i.repr())),
        other => Err(format!(
            "'{}' object is not subscriptable",
            other.type_name()
        )),
    }
}

pub(super) fn slice_bounds(parts: [Option<i64>; 3], len: usize) -> Result<Vec<usize>, String> {
    let n = len as i64;
    let step = parts[2].unwrap_or(1);
    if step == 0 {
        return Err("slice step cannot be zero".into());
    }
    let clamp = |x: i64, lo: i64, hi: i64| x.max(lo).min(hi);
    let norm = |x: i64| if x < 0 { x + n } else { x };
    let mut out = Vec::new();
    if step > 0 {
        let start = clamp(parts[0].map_or(0, norm), 0, n);
        let stop = clamp(parts[1].map_or(n, norm), 0, n);
        let mut k = start;
        while k < stop {
            out.push(k as usize);
            k += step;
        }
    } else {
        let start = clamp(parts[0].map_or(n - 1, norm), -1, n - 1);
        let stop = clamp(parts[1].map_or(-1, norm), -1, n - 1);
        let mut k = start;
        while k > stop {
            out.push(k as usize);
            k += step;
        }
    }
    Ok(out)
}

/// `a < b` in Python.
pub fn less(a: &Value, b: &Value) -> Result<bool, String> {
    compare("<", a, b)
}
