//! The values of xacro's Python expressions and how Python prints them (`str`, `repr`).

use super::dom::Element;
use std::fmt::Write as _;
use std::rc::Rc;

/// A Python value as xacro expressions produce it.
#[derive(Debug, Clone)]
pub enum Value {
    None,
    Bool(bool),
    Int(i64),
    Float(f64),
    Str(Rc<str>),
    List(Rc<Vec<Value>>),
    Tuple(Rc<Vec<Value>>),
    Dict(Rc<Dict>),
    /// A block: a macro's `*param`/`**param` or a property block (`**name`).
    Block(Rc<Element>),
    /// A symbol table reached by name: `ns` of an include.
    Namespace(Rc<super::expand::Table>),
    /// A module-like name space of builtins: `math`, `python`, `xacro`.
    Module(&'static str),
    /// A builtin function, by its qualified name (`len`, `math.sin`, `xacro.load_yaml`).
    Builtin(&'static str),
    /// A method bound to its receiver (`'a b'.split`).
    Method(Rc<Value>, Rc<str>),
}

/// A dict in insertion order. `dotted` dicts (from YAML, xacro's `dotify`) also give their keys as
/// attributes (`d.key`).
#[derive(Debug, Clone, Default)]
pub struct Dict {
    pub entries: Vec<(Value, Value)>,
    pub dotted: bool,
}

impl Dict {
    pub fn get(&self, key: &Value) -> Option<&Value> {
        self.entries
            .iter()
            .find(|(k, _)| py_eq(k, key))
            .map(|(_, v)| v)
    }

    pub fn insert(&mut self, key: Value, value: Value) {
        if let Some(slot) = self.entries.iter_mut().find(|(k, _)| py_eq(k, &key)) {
            slot.1 = value;
        } else {
            self.entries.push((key, value));
        }
    }
}

impl Value {
    pub fn str(s: &str) -> Value {
        Value::Str(Rc::from(s))
    }

    /// Python's type name, for messages.
    pub fn type_name(&self) -> &'static str {
        match self {
            Value::None => "NoneType",
            Value::Bool(_) => "bool",
            Value::Int(_) => "int",
            Value::Float(_) => "float",
            Value::Str(_) => "str",
            Value::List(_) => "list",
            Value::Tuple(_) => "tuple",
            Value::Dict(_) => "dict",
            Value::Block(_) => "block",
            Value::Namespace(_) => "namespace",
            Value::Module(_) => "module",
            Value::Builtin(_) | Value::Method(..) => "function",
        }
    }

    /// Python's truth value.
    pub fn truthy(&self) -> bool {
        match self {
            Value::None => false,
            Value::Bool(b) => *b,
            Value::Int(i) => *i != 0,
            Value::Float(f) => *f != 0.0,
            Value::Str(s) => !s.is_empty(),
            Value::List(l) | Value::Tuple(l) => !l.is_empty(),
            Value::Dict(d) => !d.entries.is_empty(),
            _ => true,
        }
    }

    /// The number, if this is one (bools are ints in Python).
    pub fn as_f64(&self) -> Option<f64> {
        match self {
            Value::Bool(b) => Some(f64::from(u8::from(*b))),
            Value::Int(i) => Some(*i as f64),
            Value::Float(f) => Some(*f),
            _ => None,
        }
    }

    /// Python's `str(value)`.
    pub fn to_py_str(&self) -> String {
        match self {
            Value::Str(s) => s.to_string(),
            other => other.repr(),
        }
    }

    /// Python's `repr(value)`.
    pub fn repr(&self) -> String {
        match self {
            Value::None => "None".into(),
            Value::Bool(true) => "True".into(),
            Value::Bool(false) => "False".into(),
            Value::Int(i) => i.to_string(),
            Value::Float(f) => float_repr(*f),
            Value::Str(s) => str_repr(s),
            Value::List(l) => format!("[{}]", join_repr(l)),
            Value::Tuple(l) if l.len() == 1 => format!("({},)", l[0].repr()),
            Value::Tuple(l) => format!("({})", join_repr(l)),
            Value::Dict(d) => {
                let items: Vec<String> = d
                    .entries
                    .iter()
                    .map(|(k, v)| format!("{}: {}", k.repr(), v.repr()))
                    .collect();
                format!("{{{}}}", items.join(", "))
            }
            Value::Block(e) => format!("<Element {}>", e.name),
            Value::Namespace(_) => "<namespace>".into(),
            Value::Module(m) => format!("<module '{m}'>"),
            Value::Builtin(f) => format!("<built-in function {f}>"),
            Value::Method(_, m) => format!("<built-in method {m}>"),
        }
    }
}

fn join_repr(l: &[Value]) -> String {
    l.iter().map(Value::repr).collect::<Vec<_>>().join(", ")
}

/// Python's `repr` of a string: single quotes unless the text holds one and no double quote.
pub fn str_repr(s: &str) -> String {
    let q = if s.contains('\'') && !s.contains('"') {
        '"'
    } else {
        '\''
    };
    let mut out = String::with_capacity(s.len() + 2);
    out.push(q);
    for c in s.chars() {
        match c {
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            '\r' => out.push_str("\\r"),
            '\t' => out.push_str("\\t"),
            c if c == q => {
                out.push('\\');
                out.push(c);
            }
            c if (c as u32) < 0x20 || c as u32 == 0x7f => {
                let _ = write!(out, "\\x{:02x}", c as u32);
            }
            c => out.push(c),
        }
    }
    out.push(q);
    out
}

/// The shortest decimal digits that read back as `x` (`x` finite, non-zero, positive) and the
/// decimal exponent of the first digit: `x = 0.d1d2… × 10^(exp + 1)`.
fn shortest_digits(x: f64) -> (String, i32) {
    // Rust's `{:e}` prints the shortest round-trip digits, as Python's repr does.
    let s = format!("{x:e}");
    let (mantissa, exp) = s.split_once('e').unwrap_or((&s, "0"));
    let digits: String = mantissa.chars().filter(char::is_ascii_digit).collect();
    (digits, exp.parse().unwrap_or(0))
}

/// Python's `repr(float)` (and `str(float)`): the shortest round-trip digits, positional for
/// exponents from -4 to 15 with at least one digit after the point, scientific otherwise
/// (`1e-05`, `1.5e+16`).
pub fn float_repr(x: f64) -> String {
    if x.is_nan() {
        return "nan".into();
    }
    if x.is_infinite() {
        return if x > 0.0 { "inf" } else { "-inf" }.into();
    }
    if x == 0.0 {
        return if x.is_sign_negative() { "-0.0" } else { "0.0" }.into();
    }
    let sign = if x < 0.0 { "-" } else { "" };
    let (digits, exp) = shortest_digits(x.abs());
    if (-4..16).contains(&exp) {
        let point = exp + 1;
        if point <= 0 {
            format!("{sign}0.{}{digits}", "0".repeat((-point) as usize))
        } else if (point as usize) >= digits.len() {
            format!(
                "{sign}{digits}{}.0",
                "0".repeat(point as usize - digits.len())
            )
        } else {
            let (a, b) = digits.split_at(point as usize);
            format!("{sign}{a}.{b}")
        }
    } else {
        let (first, rest) = digits.split_at(1);
        let frac = if rest.is_empty() {
            String::new()
        } else {
            format!(".{rest}")
        };
        let esign = if exp < 0 { '-' } else { '+' };
        format!("{sign}{first}{frac}e{esign}{:02}", exp.abs())
    }
}

/// Python's `==` across types: numbers by value, sequences and dicts element-wise.
pub fn py_eq(a: &Value, b: &Value) -> bool {
    match (a, b) {
        (Value::None, Value::None) => true,
        (Value::Str(x), Value::Str(y)) => x == y,
        (Value::List(x), Value::List(y)) | (Value::Tuple(x), Value::Tuple(y)) => {
            x.len() == y.len() && x.iter().zip(y.iter()).all(|(p, q)| py_eq(p, q))
        }
        (Value::Dict(x), Value::Dict(y)) => {
            x.entries.len() == y.entries.len()
                && x.entries
                    .iter()
                    .all(|(k, v)| y.get(k).is_some_and(|w| py_eq(v, w)))
        }
        (Value::Int(x), Value::Int(y)) => x == y,
        _ => match (a.as_f64(), b.as_f64()) {
            (Some(x), Some(y)) => x == y,
            _ => false,
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn floats_print_as_python_repr() {
        // Expected values typed from CPython 3.11's repr().
        let cases = [
            (0.1, "0.1"),
            (1.0, "1.0"),
            (-2.5, "-2.5"),
            (100.0, "100.0"),
            (1e16, "1e+16"),
            (1.5e16, "1.5e+16"),
            (1e15, "1000000000000000.0"),
            (0.0001, "0.0001"),
            (0.00001, "1e-05"),
            (1.2345e-7, "1.2345e-07"),
            (std::f64::consts::PI, "3.141592653589793"),
            (std::f64::consts::PI / 2.0, "1.5707963267948966"),
            (0.1 + 0.2, "0.30000000000000004"),
            (1e300, "1e+300"),
            (-0.0, "-0.0"),
            (f64::INFINITY, "inf"),
            (123456789.125, "123456789.125"),
        ];
        for (x, want) in cases {
            assert_eq!(float_repr(x), want, "{x:e}");
        }
    }

    #[test]
    fn containers_print_as_python_str() {
        let l = Value::List(Rc::new(vec![
            Value::Int(1),
            Value::str("a'b"),
            Value::Float(2.0),
            Value::Bool(true),
            Value::None,
        ]));
        assert_eq!(l.to_py_str(), "[1, \"a'b\", 2.0, True, None]");
        let mut d = Dict::default();
        d.insert(Value::str("x"), Value::Float(0.5));
        assert_eq!(Value::Dict(Rc::new(d)).to_py_str(), "{'x': 0.5}");
        assert_eq!(
            Value::Tuple(Rc::new(vec![Value::Int(1)])).to_py_str(),
            "(1,)"
        );
    }
}
