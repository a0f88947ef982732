//! What expressions and substitution arguments see: properties in scope and the expander's builtins.

use super::{Expander, Table, R};
use crate::xacro::expr::Env;
use crate::xacro::value::Value;
use crate::xacro::XacroError;
use std::rc::Rc;

/// Expression names for `${…}`: the current scope's properties and the expander's builtins.
pub(super) struct ExprEnv<'a, 'o> {
    pub(super) x: &'a mut Expander<'o>,
    pub(super) symbols: Rc<Table>,
    /// An expansion error met inside the expression (a lazy property that failed), reported as
    /// it is rather than as the expression's.
    pub(super) pending: Option<XacroError>,
}

impl ExprEnv<'_, '_> {
    fn keep(&mut self, r: R<Option<Value>>) -> Result<Option<Value>, String> {
        r.map_err(|e| {
            let m = e.message.clone();
            self.pending.get_or_insert(e);
            m
        })
    }
}

impl Env for ExprEnv<'_, '_> {
    fn lookup(&mut self, name: &str) -> Result<Option<Value>, String> {
        let symbols = self.symbols.clone();
        let r = self.x.resolve(&symbols, name);
        self.keep(r)
    }

    fn namespace_get(&mut self, ns: &Rc<Table>, name: &str) -> Result<Option<Value>, String> {
        let r = self.x.resolve(ns, name);
        self.keep(r)
    }

    fn call(&mut self, name: &str, args: &[Value]) -> Option<Result<Value, String>> {
        let one = || match args {
            [a] => Ok(a.to_py_str()),
            _ => Err(format!("{name}() takes one argument")),
        };
        Some(match name {
            "xacro.load_yaml" => one().and_then(|f| self.x.load_yaml(&f)),
            "xacro.abs_filename" => {
                one().map(|f| Value::str(&self.x.relative_to_current(&f).display().to_string()))
            }
            "xacro.arg" => one().and_then(|a| {
                self.x
                    .args
                    .get(&a)
                    .map(|v| Value::str(v))
                    .ok_or_else(|| format!("KeyError: '{a}' (no such xacro arg)"))
            }),
            "xacro.message" | "xacro.warning" | "xacro.error" => {
                let text: Vec<String> = args.iter().map(Value::to_py_str).collect();
                self.x.warn(&text.join(" "));
                Ok(Value::str(""))
            }
            "xacro.print_location" => Ok(Value::str("")),
            "xacro.fatal" => {
                let text: Vec<String> = args.iter().map(Value::to_py_str).collect();
                Err(format!("fatal: {}", text.join(" ")))
            }
            _ => return None,
        })
    }
}

/// Names for `$(eval …)`: xacro args (typed as roslaunch's `auto`), `arg()`, `env()`,
/// `optenv()`, `find()`, `dirname()`, `true`/`false`, and the math names.
pub(super) struct SubstEnv<'a, 'o> {
    pub(super) x: &'a mut Expander<'o>,
}

/// roslaunch's `convert_value(value, 'auto')`.
fn auto_value(s: &str) -> Value {
    let num = if s.contains('.') {
        crate::xacro::builtins::parse_float(s).map(Value::Float)
    } else {
        crate::xacro::builtins::parse_int(s).map(Value::Int)
    };
    if let Some(v) = num {
        return v;
    }
    match s.to_lowercase().as_str() {
        "true" => Value::Bool(true),
        "false" => Value::Bool(false),
        _ => Value::str(s),
    }
}

impl Env for SubstEnv<'_, '_> {
    fn lookup(&mut self, name: &str) -> Result<Option<Value>, String> {
        Ok(match name {
            "true" => Some(Value::Bool(true)),
            "false" => Some(Value::Bool(false)),
            "arg" => Some(Value::Builtin("eval.arg")),
            "env" => Some(Value::Builtin("eval.env")),
            "optenv" => Some(Value::Builtin("eval.optenv")),
            "find" => Some(Value::Builtin("eval.find")),
            "dirname" => Some(Value::Builtin("eval.dirname")),
            _ => self.x.args.get(name).map(|v| auto_value(v)),
        })
    }

    fn namespace_get(&mut self, _: &Rc<Table>, _: &str) -> Result<Option<Value>, String> {
        Ok(None)
    }

    fn call(&mut self, name: &str, args: &[Value]) -> Option<Result<Value, String>> {
        let a: Vec<String> = args.iter().map(Value::to_py_str).collect();
        Some(match (name, a.as_slice()) {
            ("eval.arg", [n]) => self
                .x
                .args
                .get(n)
                .map(|v| auto_value(v))
                .ok_or_else(|| format!("Undefined substitution argument {n}")),
            ("eval.env", [n]) => self
                .x
                .opts
                .env
                .get(n)
                .map(|v| Value::str(v))
                .ok_or_else(|| format!("environment variable {n} is not set")),
            ("eval.optenv", [n, rest @ ..]) => Ok(Value::str(
                &self
                    .x
                    .opts
                    .env
                    .get(n)
                    .cloned()
                    .unwrap_or_else(|| rest.join(" ")),
            )),
            ("eval.find", [p]) => self
                .x
                .find(p)
                .map(|s| Value::str(&s))
                .map_err(|e| e.message),
            ("eval.dirname", []) => Ok(Value::str(&self.x.dirname())),
            (n, _) if n.starts_with("eval.") => {
                Err(format!("{}(): wrong number of arguments", &n[5..]))
            }
            _ => return None,
        })
    }
}

/// Only xacro's globals (for the expressions of YAML unit tags).
pub(super) struct GlobalsOnly;

impl Env for GlobalsOnly {
    fn lookup(&mut self, _: &str) -> Result<Option<Value>, String> {
        Ok(None)
    }
    fn namespace_get(&mut self, _: &Rc<Table>, _: &str) -> Result<Option<Value>, String> {
        Ok(None)
    }
    fn call(&mut self, _: &str, _: &[Value]) -> Option<Result<Value, String>> {
        None
    }
}
