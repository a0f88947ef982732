//! `${…}` expressions: the subset of Python that robot descriptions use, parsed and evaluated.
//!
//! Literals (numbers, strings, lists, tuples, dicts, `True`/`False`/`None`), arithmetic with Python's
//! int/float rules (`/` is true division, `//` and `%` floor), `**`, comparisons (chained, `in`,
//! `not in`, `is`), `and`/`or`/`not`, `x if c else y`, indexing and slicing, attribute access, calls
//! with keyword arguments, list comprehensions, `%` string formatting and `str.format`. Names are
//! looked up through [`Env`] (xacro's properties), then in xacro's globals: `math`'s names (also as
//! `math.*`), `list dict map len str float int bool True False min max round`, `sorted range`,
//! `python.*` (which adds `abs`, `sum`, `any`, `all`, `zip`, …) and `xacro.*`. A construct outside
//! the subset (lambda, f-strings, bit operations) is an error naming it, never a guess.

use super::value::Value;
use std::rc::Rc;

mod eval;
mod lex;
mod ops;
mod parse;

use eval::Eval;
pub use ops::{binary_op, is_global, items, less, order};
pub use parse::{parse, Expr};

/// What expressions need from the expander: properties, and the builtins that touch files or the
/// run (`xacro.load_yaml`, `xacro.arg`, `xacro.warning`, …).
pub trait Env {
    /// A property (or block, or include name space) by name, `None` if there is none.
    fn lookup(&mut self, name: &str) -> Result<Option<Value>, String>;
    /// A name inside an include's name space (`ns.name`).
    fn namespace_get(
        &mut self,
        ns: &Rc<super::expand::Table>,
        name: &str,
    ) -> Result<Option<Value>, String>;
    /// Calls a builtin that needs the expander; `None` if `name` is not one of those.
    fn call(&mut self, name: &str, args: &[Value]) -> Option<Result<Value, String>>;
}

/// Evaluates `src` with `env`.
pub fn eval_str(src: &str, env: &mut dyn Env) -> Result<Value, String> {
    let e = parse(src)?;
    Eval {
        env,
        locals: Vec::new(),
    }
    .eval(&e)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::xacro::value::Dict;

    /// Properties from a fixed list; no expander builtins.
    struct Fixed(Vec<(&'static str, Value)>);

    impl Env for Fixed {
        fn lookup(&mut self, name: &str) -> Result<Option<Value>, String> {
            Ok(self
                .0
                .iter()
                .find(|(k, _)| *k == name)
                .map(|(_, v)| v.clone()))
        }
        fn namespace_get(
            &mut self,
            _: &Rc<super::super::expand::Table>,
            _: &str,
        ) -> Result<Option<Value>, String> {
            Ok(None)
        }
        fn call(&mut self, _: &str, _: &[Value]) -> Option<Result<Value, String>> {
            None
        }
    }

    fn ev(src: &str) -> String {
        let mut d = Dict {
            dotted: true,
            ..Dict::default()
        };
        d.insert(Value::str("mass"), Value::Float(1.5));
        let mut inner = Dict::default();
        inner.insert(Value::str("c"), Value::Int(7));
        let mut outer = Dict::default();
        outer.insert(Value::str("b"), Value::Dict(Rc::new(inner)));
        let mut env = Fixed(vec![
            ("x", Value::Int(3)),
            ("r", Value::Float(0.5)),
            ("name", Value::str("arm")),
            (
                "l",
                Value::List(Rc::new(vec![Value::Int(1), Value::Int(2), Value::Int(3)])),
            ),
            ("link", Value::Dict(Rc::new(d))),
            ("a", Value::Dict(Rc::new(outer))),
        ]);
        match eval_str(src, &mut env) {
            Ok(v) => v.to_py_str(),
            Err(e) => format!("error: {e}"),
        }
    }

    #[test]
    fn arithmetic_follows_python() {
        // Expected values are what CPython 3.11 prints for the same expressions.
        assert_eq!(ev("1 + 2 * 3"), "7");
        assert_eq!(ev("7 / 2"), "3.5");
        assert_eq!(ev("6 / 2"), "3.0");
        assert_eq!(ev("7 // 2"), "3");
        assert_eq!(ev("-7 // 2"), "-4");
        assert_eq!(ev("-7 % 3"), "2");
        assert_eq!(ev("7 % -3"), "-2");
        assert_eq!(ev("2 ** 10"), "1024");
        assert_eq!(ev("2 ** -1"), "0.5");
        assert_eq!(ev("-2 ** 2"), "-4");
        assert_eq!(ev("1./12 * 3"), "0.25");
        assert_eq!(ev("0.1 + 0.2"), "0.30000000000000004");
        assert_eq!(ev("x * r"), "1.5");
        assert_eq!(ev("-pi/2"), "-1.5707963267948966");
        assert_eq!(ev("radians(180)"), "3.141592653589793");
        assert_eq!(ev("math.degrees(pi)"), "180.0");
        assert_eq!(ev("math.sqrt(16)"), "4.0");
        assert_eq!(ev("math.floor(2.5)"), "2");
        assert_eq!(ev("1 / 0"), "error: division by zero");
    }

    #[test]
    fn logic_strings_and_containers() {
        assert_eq!(ev("1 < x <= 3"), "True");
        assert_eq!(ev("x == 3 and not r > 1"), "True");
        assert_eq!(ev("0 or 'b'"), "b");
        assert_eq!(ev("'yes' if x > 2 else 'no'"), "yes");
        assert_eq!(ev("name + '_link'"), "arm_link");
        assert_eq!(ev("'a' in name"), "True");
        assert_eq!(ev("4 not in l"), "True");
        assert_eq!(ev("l[-1]"), "3");
        assert_eq!(ev("l[1:]"), "[2, 3]");
        assert_eq!(ev("name[::-1]"), "mra");
        assert_eq!(ev("a['b']['c']"), "7");
        assert_eq!(ev("link.mass"), "1.5");
        assert_eq!(ev("len(l) + len(name)"), "6");
        assert_eq!(ev("'%s_%d' % (name, x)"), "arm_3");
        assert_eq!(ev("'%.3f' % r"), "0.500");
        assert_eq!(ev("'{}-{}'.format(name, x)"), "arm-3");
        assert_eq!(ev("'1 2 3'.split(' ')[1]"), "2");
        assert_eq!(ev("[2 * v for v in l if v > 1]"), "[4, 6]");
        assert_eq!(ev("dict(a=1, b=0.5)"), "{'a': 1, 'b': 0.5}");
        assert_eq!(ev("min(3, 1.5)"), "1.5");
        assert_eq!(ev("max(l)"), "3");
        assert_eq!(ev("round(2.5)"), "2");
        assert_eq!(ev("round(0.125, 2)"), "0.12");
        assert_eq!(ev("int('12') + float('0.5')"), "12.5");
        assert_eq!(ev("str(0.5) + str(True)"), "0.5True");
        assert_eq!(ev("python.abs(-2)"), "2");
        assert_eq!(
            ev("undefined + 1"),
            "error: name 'undefined' is not defined"
        );
        assert!(ev("lambda x: x").starts_with("error: lambda"));
        assert!(ev("1 +").starts_with("error:"));
    }
}
