//! `xacro.load_yaml`: a YAML file as the values `PyYAML`'s `safe_load` gives (YAML 1.1 scalars:
//! `yes`/`on` are booleans, `1.5` a float but `1e-3` a string, `0755` octal), with xacro's unit tags
//! (`!degrees 90`, `!millimeters 5`, …). Mappings become dotted dicts (`d.key` as well as
//! `d['key']`). The events come from saphyr-parser (a maintained pure-Rust YAML parser); the
//! resolution of plain scalars is `PyYAML`'s, which saphyr's YAML 1.2 rules would change.
//! One difference is deliberate: a timestamp (`2001-12-14`) stays a string, where `PyYAML` makes a
//! `datetime.date` (printed `datetime.date(2001, 12, 14)`); description files use none.

use super::value::{Dict, Value};
use saphyr_parser::{Event, Parser, ScalarStyle, Tag};
use std::collections::HashMap;
use std::rc::Rc;

/// Deepest nesting of collections accepted (a hostile file cannot exhaust the stack).
const MAX_DEPTH: usize = 200;

enum Frame {
    Seq(usize, Vec<Value>),
    Map(usize, Dict, Option<Value>),
}

/// Parses YAML text. The error names the line.
pub fn load(
    text: &str,
    eval_unit: &mut dyn FnMut(&str) -> Result<f64, String>,
) -> Result<Value, String> {
    let mut anchors: HashMap<usize, Value> = HashMap::new();
    let mut stack: Vec<Frame> = Vec::new();
    let mut result: Option<Value> = None;
    let mut documents = 0;
    for ev in Parser::new_from_str(text) {
        let (ev, span) = ev.map_err(|e| format!("YAML error: {e}"))?;
        let line = span.start.line();
        let value = match ev {
            Event::DocumentStart(_) => {
                documents += 1;
                if documents > 1 {
                    return Err(format!(
                        "line {line}: more than one YAML document (load_yaml reads one)"
                    ));
                }
                continue;
            }
            Event::Scalar(v, style, anchor, tag) => {
                let v = scalar(&v, style, tag.as_deref(), eval_unit)
                    .map_err(|e| format!("line {line}: {e}"))?;
                if anchor > 0 {
                    anchors.insert(anchor, v.clone());
                }
                v
            }
            Event::Alias(id) => anchors
                .get(&id)
                .cloned()
                .ok_or_else(|| format!("line {line}: unknown alias"))?,
            Event::SequenceStart(anchor, _) => {
                if stack.len() >= MAX_DEPTH {
                    return Err(format!(
                        "line {line}: YAML nested deeper than {MAX_DEPTH} levels"
                    ));
                }
                stack.push(Frame::Seq(anchor, Vec::new()));
                continue;
            }
            Event::MappingStart(anchor, _) => {
                if stack.len() >= MAX_DEPTH {
                    return Err(format!(
                        "line {line}: YAML nested deeper than {MAX_DEPTH} levels"
                    ));
                }
                stack.push(Frame::Map(
                    anchor,
                    Dict {
                        dotted: true,
                        ..Dict::default()
                    },
                    None,
                ));
                continue;
            }
            Event::SequenceEnd => match stack.pop() {
                Some(Frame::Seq(anchor, items)) => {
                    let v = Value::List(Rc::new(items));
                    if anchor > 0 {
                        anchors.insert(anchor, v.clone());
                    }
                    v
                }
                _ => return Err(format!("line {line}: unbalanced YAML sequence")),
            },
            Event::MappingEnd => match stack.pop() {
                Some(Frame::Map(anchor, d, _)) => {
                    let v = Value::Dict(Rc::new(d));
                    if anchor > 0 {
                        anchors.insert(anchor, v.clone());
                    }
                    v
                }
                _ => return Err(format!("line {line}: unbalanced YAML mapping")),
            },
            _ => continue,
        };
        attach(&mut stack, &mut result, value);
    }
    Ok(result.unwrap_or(Value::None))
}

/// Puts a finished value where it belongs: the document, a sequence, or a mapping's key or value.
fn attach(stack: &mut [Frame], result: &mut Option<Value>, value: Value) {
    match stack.last_mut() {
        None => *result = Some(value),
        Some(Frame::Seq(_, items)) => items.push(value),
        Some(Frame::Map(_, d, key)) => match key.take() {
            None => *key = Some(value),
            Some(k) => {
                // `<<: *base` merges the base mapping's keys (those not given here).
                if matches!(&k, Value::Str(s) if &**s == "<<") {
                    merge(d, &value);
                } else {
                    d.insert(k, value);
                }
            }
        },
    }
}

fn merge(d: &mut Dict, value: &Value) {
    match value {
        Value::Dict(base) => {
            for (k, v) in &base.entries {
                if d.get(k).is_none() {
                    d.insert(k.clone(), v.clone());
                }
            }
        }
        Value::List(l) => l.iter().for_each(|v| merge(d, v)),
        _ => {}
    }
}

/// Unit tags xacro registers, with their factor to SI units.
fn unit(tag: &str) -> Option<f64> {
    Some(match tag {
        "radians" | "meters" => 1.0,
        "degrees" => std::f64::consts::PI / 180.0,
        "millimeters" => 0.001,
        "foot" => 0.3048,
        "inches" => 0.0254,
        _ => return None,
    })
}

fn scalar(
    v: &str,
    style: ScalarStyle,
    tag: Option<&Tag>,
    eval_unit: &mut dyn FnMut(&str) -> Result<f64, String>,
) -> Result<Value, String> {
    if let Some(t) = tag {
        if t.handle == "!" {
            if let Some(factor) = unit(&t.suffix) {
                return Ok(Value::Float(eval_unit(v)? * factor));
            }
            return Err(format!("unknown YAML tag !{}", t.suffix));
        }
        let core = t.suffix.trim_start_matches("tag:yaml.org,2002:");
        return Ok(match core {
            "str" => Value::str(v),
            "int" => Value::Int(int(v).ok_or_else(|| format!("`{v}` is not an int"))?),
            "float" => Value::Float(
                float(v)
                    .or_else(|| int(v).map(|i| i as f64))
                    .ok_or_else(|| format!("`{v}` is not a float"))?,
            ),
            "bool" => Value::Bool(boolean(v).ok_or_else(|| format!("`{v}` is not a bool"))?),
            "null" => Value::None,
            other => return Err(format!("unsupported YAML tag !!{other}")),
        });
    }
    if style != ScalarStyle::Plain {
        return Ok(Value::str(v));
    }
    Ok(resolve_plain(v))
}

/// `PyYAML`'s implicit resolution of a plain scalar.
pub fn resolve_plain(v: &str) -> Value {
    if matches!(v, "" | "~" | "null" | "Null" | "NULL") {
        return Value::None;
    }
    if let Some(b) = boolean(v) {
        return Value::Bool(b);
    }
    if let Some(i) = int(v) {
        return Value::Int(i);
    }
    if let Some(f) = float(v) {
        return Value::Float(f);
    }
    Value::str(v)
}

fn boolean(v: &str) -> Option<bool> {
    match v {
        "yes" | "Yes" | "YES" | "true" | "True" | "TRUE" | "on" | "On" | "ON" => Some(true),
        "no" | "No" | "NO" | "false" | "False" | "FALSE" | "off" | "Off" | "OFF" => Some(false),
        _ => None,
    }
}

/// YAML 1.1 ints: decimal, `0b…`, `0x…`, octal with a leading 0, underscores allowed.
fn int(v: &str) -> Option<i64> {
    let (neg, body) = match v.as_bytes().first()? {
        b'-' => (true, &v[1..]),
        b'+' => (false, &v[1..]),
        _ => (false, v),
    };
    if body.is_empty() || body.starts_with('_') {
        return None;
    }
    let clean: String = body.chars().filter(|c| *c != '_').collect();
    let (radix, digits) = if let Some(b) = clean.strip_prefix("0b") {
        (2, b.to_string())
    } else if let Some(x) = clean.strip_prefix("0x") {
        (16, x.to_string())
    } else if clean.len() > 1 && clean.starts_with('0') {
        (8, clean[1..].to_string())
    } else {
        (10, clean.clone())
    };
    if digits.is_empty() || !digits.chars().all(|c| c.is_digit(radix)) {
        return None;
    }
    let n = i64::from_str_radix(&digits, radix).ok()?;
    Some(if neg { -n } else { n })
}

/// YAML 1.1 floats: a point is required (`1.`, `.5`, `1.5e+3`; the exponent needs its sign), and
/// `.inf`, `.nan`.
fn float(v: &str) -> Option<f64> {
    let (neg, body) = match v.as_bytes().first()? {
        b'-' => (true, &v[1..]),
        b'+' => (false, &v[1..]),
        _ => (false, v),
    };
    let sign = if neg { -1.0 } else { 1.0 };
    match body {
        ".inf" | ".Inf" | ".INF" => return Some(sign * f64::INFINITY),
        ".nan" | ".NaN" | ".NAN" if v == body => return Some(f64::NAN),
        _ => {}
    }
    let (mantissa, exp) = match body.find(['e', 'E']) {
        Some(k) => (&body[..k], Some(&body[k + 1..])),
        None => (body, None),
    };
    let (int_part, frac) = mantissa.split_once('.')?;
    let ok_digits = |s: &str| s.chars().all(|c| c.is_ascii_digit() || c == '_');
    if !ok_digits(int_part) || !ok_digits(frac) {
        return None;
    }
    if int_part.is_empty() && !frac.starts_with(|c: char| c.is_ascii_digit()) {
        return None;
    }
    if int_part.starts_with('_') {
        return None;
    }
    if let Some(e) = exp {
        if !(e.starts_with(['+', '-']) && e.len() > 1 && e[1..].chars().all(|c| c.is_ascii_digit()))
        {
            return None;
        }
    }
    let clean: String = body.chars().filter(|c| *c != '_').collect();
    let text = if clean.starts_with('.') {
        format!("0{clean}")
    } else {
        clean
    };
    text.parse::<f64>().ok().map(|x| sign * x)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn no_units(_: &str) -> Result<f64, String> {
        Err("no".into())
    }

    #[test]
    fn scalars_resolve_as_pyyaml_safe_load() {
        // What `yaml.safe_load` (PyYAML 6.0) gives for each plain scalar.
        assert!(matches!(resolve_plain("1.5"), Value::Float(x) if x == 1.5));
        assert!(matches!(resolve_plain("1.0e-3"), Value::Float(x) if x == 0.001));
        assert!(matches!(resolve_plain("1e-3"), Value::Str(s) if &*s == "1e-3"));
        assert!(matches!(resolve_plain("1.0e5"), Value::Str(_)));
        assert!(matches!(resolve_plain("42"), Value::Int(42)));
        assert!(matches!(resolve_plain("0755"), Value::Int(493)));
        assert!(matches!(resolve_plain("-0x1F"), Value::Int(-31)));
        assert!(matches!(resolve_plain("yes"), Value::Bool(true)));
        assert!(matches!(resolve_plain("Off"), Value::Bool(false)));
        assert!(matches!(resolve_plain("~"), Value::None));
        assert!(matches!(resolve_plain("-.inf"), Value::Float(x) if x == f64::NEG_INFINITY));
        assert!(matches!(resolve_plain("ur5e"), Value::Str(_)));
        assert!(matches!(resolve_plain(".5"), Value::Float(x) if x == 0.5));
    }

    #[test]
    fn documents_become_dotted_dicts_and_lists() {
        let text = "base: &b\n  mass: 4.0\n  xyz: [0, 0.1, '2']\narm:\n  <<: *b\n  mass: 2\nangle: !degrees 90\n";
        let mut units = |s: &str| s.trim().parse::<f64>().map_err(|e| e.to_string());
        let v = load(text, &mut units).expect("loads");
        let Value::Dict(d) = v else { panic!("a dict") };
        assert!(d.dotted);
        assert_eq!(
            d.get(&Value::str("base")).map(Value::to_py_str).as_deref(),
            Some("{'mass': 4.0, 'xyz': [0, 0.1, '2']}")
        );
        assert_eq!(
            d.get(&Value::str("arm")).map(Value::to_py_str).as_deref(),
            Some("{'mass': 2, 'xyz': [0, 0.1, '2']}")
        );
        assert_eq!(
            d.get(&Value::str("angle")).map(Value::to_py_str).as_deref(),
            Some("1.5707963267948966")
        );
        assert!(load("a: [1, 2\n", &mut no_units).is_err());
    }
}
