//! The methods of strings, dicts and lists.

use super::arity;
use super::format::str_format;
use crate::xacro::expr::items;
use crate::xacro::value::{py_eq, Value};
use std::rc::Rc;

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
