//! Evaluation of an [`Expr`] against an [`Env`].

use super::ops::{
    binary_op, compare, global, int_of, items, module_attr, num, overflow, slice_bounds, subscript,
};
use super::parse::Expr;
use super::Env;
use crate::xacro::value::{Dict, Value};
use std::rc::Rc;

pub(super) struct Eval<'e> {
    pub(super) env: &'e mut dyn Env,
    pub(super) locals: Vec<(String, Value)>,
}

impl Eval<'_> {
    pub(super) fn eval(&mut self, e: &Expr) -> Result<Value, String> {
        Ok(match e {
            Expr::Const(v) => v.clone(),
            Expr::Name(n) => self.name(n)?,
            Expr::Attr(obj, name) => {
                let o = self.eval(obj)?;
                self.attr(&o, name)?
            }
            Expr::Index(obj, i) => {
                let o = self.eval(obj)?;
                let i = self.eval(i)?;
                subscript(&o, &i)?
            }
            Expr::Slice(obj, parts) => self.slice(obj, parts)?,
            Expr::Call(f, args, kwargs) => self.call_expr(f, args, kwargs)?,
            Expr::Neg(x) => self.neg(x)?,
            Expr::Pos(x) => self.pos(x)?,
            Expr::Not(x) => Value::Bool(!self.eval(x)?.truthy()),
            Expr::Bin(op, a, b) => {
                let a = self.eval(a)?;
                let b = self.eval(b)?;
                binary_op(op, &a, &b)?
            }
            Expr::And(a, b) => {
                let a = self.eval(a)?;
                if a.truthy() {
                    self.eval(b)?
                } else {
                    a
                }
            }
            Expr::Or(a, b) => {
                let a = self.eval(a)?;
                if a.truthy() {
                    a
                } else {
                    self.eval(b)?
                }
            }
            Expr::Compare(first, rest) => {
                let mut left = self.eval(first)?;
                for (op, r) in rest {
                    let right = self.eval(r)?;
                    if !compare(op, &left, &right)? {
                        return Ok(Value::Bool(false));
                    }
                    left = right;
                }
                Value::Bool(true)
            }
            Expr::IfElse(c, a, b) => {
                if self.eval(c)?.truthy() {
                    self.eval(a)?
                } else {
                    self.eval(b)?
                }
            }
            Expr::List(items) => Value::List(Rc::new(self.all(items)?)),
            Expr::Tuple(items) => Value::Tuple(Rc::new(self.all(items)?)),
            Expr::Dict(items) => {
                let mut d = Dict::default();
                for (k, v) in items {
                    let k = self.eval(k)?;
                    let v = self.eval(v)?;
                    d.insert(k, v);
                }
                Value::Dict(Rc::new(d))
            }
            Expr::Comp(elt, names, iter, conds) => self.comprehension(elt, names, iter, conds)?,
        })
    }

    fn call_expr(
        &mut self,
        f: &Expr,
        args: &[Expr],
        kwargs: &[(String, Expr)],
    ) -> Result<Value, String> {
        let fv = self.eval(f)?;
        let args = args
            .iter()
            .map(|a| self.eval(a))
            .collect::<Result<Vec<_>, _>>()?;
        let kwargs = kwargs
            .iter()
            .map(|(k, v)| Ok((k.clone(), self.eval(v)?)))
            .collect::<Result<Vec<_>, String>>()?;
        self.call(&fv, &args, &kwargs)
    }

    fn neg(&mut self, x: &Expr) -> Result<Value, String> {
        Ok(match self.eval(x)? {
            Value::Int(i) => Value::Int(i.checked_neg().ok_or_else(overflow)?),
            Value::Bool(b) => Value::Int(-i64::from(b)),
            v => Value::Float(-num(&v, "unary -")?),
        })
    }

    fn pos(&mut self, x: &Expr) -> Result<Value, String> {
        Ok(match self.eval(x)? {
            Value::Bool(b) => Value::Int(i64::from(b)),
            v @ (Value::Int(_) | Value::Float(_)) => v,
            v => return Err(format!("bad operand type for unary +: '{}'", v.type_name())),
        })
    }

    fn all(&mut self, items: &[Expr]) -> Result<Vec<Value>, String> {
        items.iter().map(|i| self.eval(i)).collect()
    }

    fn comprehension(
        &mut self,
        elt: &Expr,
        names: &[String],
        iter: &Expr,
        conds: &[Expr],
    ) -> Result<Value, String> {
        let seq = items(&self.eval(iter)?)?;
        let mut out = Vec::new();
        let depth = self.locals.len();
        for item in seq {
            if names.len() == 1 {
                self.locals.push((names[0].clone(), item));
            } else {
                let parts = items(&item)?;
                if parts.len() != names.len() {
                    return Err(format!(
                        "cannot unpack {} values into {} names",
                        parts.len(),
                        names.len()
                    ));
                }
                for (n, v) in names.iter().zip(parts) {
                    self.locals.push((n.clone(), v));
                }
            }
            let mut keep = true;
            for c in conds {
                if !self.eval(c)?.truthy() {
                    keep = false;
                    break;
                }
            }
            if keep {
                out.push(self.eval(elt)?);
            }
            self.locals.truncate(depth);
        }
        Ok(Value::List(Rc::new(out)))
    }

    fn slice(&mut self, obj: &Expr, parts: &[Option<Box<Expr>>; 3]) -> Result<Value, String> {
        let o = self.eval(obj)?;
        let mut bounds = [None; 3];
        for (k, p) in parts.iter().enumerate() {
            if let Some(p) = p {
                let v = self.eval(p)?;
                if !matches!(v, Value::None) {
                    bounds[k] = Some(
                        int_of(&v).ok_or_else(|| "slice indices must be integers".to_string())?,
                    );
                }
            }
        }
        Ok(match &o {
            Value::List(l) => Value::List(Rc::new(
                slice_bounds(bounds, l.len())?
                    .into_iter()
                    .map(|k| l[k].clone())
                    .collect(),
            )),
            Value::Tuple(l) => Value::Tuple(Rc::new(
                slice_bounds(bounds, l.len())?
                    .into_iter()
                    .map(|k| l[k].clone())
                    .collect(),
            )),
            Value::Str(s) => {
                let chars: Vec<char> = s.chars().collect();
                let picked: String = slice_bounds(bounds, chars.len())?
                    .into_iter()
                    .map(|k| chars[k])
                    .collect();
                Value::str(&picked)
            }
            other => {
                return Err(format!(
                    "'{}' object is not subscriptable",
                    other.type_name()
                ))
            }
        })
    }

    fn name(&mut self, n: &str) -> Result<Value, String> {
        if let Some((_, v)) = self.locals.iter().rev().find(|(k, _)| k == n) {
            return Ok(v.clone());
        }
        if let Some(v) = self.env.lookup(n)? {
            return Ok(v);
        }
        global(n).ok_or_else(|| format!("name '{n}' is not defined"))
    }

    fn attr(&mut self, o: &Value, name: &str) -> Result<Value, String> {
        match o {
            Value::Module(m) => module_attr(m, name)
                .ok_or_else(|| format!("module '{m}' has no attribute '{name}'")),
            Value::Namespace(t) => self
                .env
                .namespace_get(t, name)?
                .ok_or_else(|| format!("name '{name}' is not defined")),
            Value::Dict(d) if d.dotted && d.get(&Value::str(name)).is_some() => {
                Ok(d.get(&Value::str(name)).cloned().unwrap_or(Value::None))
            }
            Value::Dict(d) if d.dotted && !is_method("dict", name) => {
                Err(format!("The yaml dictionary has no key '{name}'"))
            }
            _ => {
                let kind = o.type_name();
                if is_method(kind, name) {
                    Ok(Value::Method(Rc::new(o.clone()), Rc::from(name)))
                } else {
                    Err(format!("'{kind}' object has no attribute '{name}'"))
                }
            }
        }
    }

    fn call(
        &mut self,
        f: &Value,
        args: &[Value],
        kwargs: &[(String, Value)],
    ) -> Result<Value, String> {
        match f {
            Value::Builtin(name) => {
                if kwargs.is_empty() {
                    if let Some(r) = self.env.call(name, args) {
                        return r;
                    }
                }
                crate::xacro::builtins::call(name, args, kwargs)
            }
            Value::Method(recv, m) => crate::xacro::builtins::method(recv, m, args, kwargs),
            other => Err(format!("'{}' object is not callable", other.type_name())),
        }
    }
}

fn is_method(kind: &str, name: &str) -> bool {
    let methods: &[&str] = match kind {
        "str" => &[
            "split",
            "rsplit",
            "strip",
            "lstrip",
            "rstrip",
            "lower",
            "upper",
            "replace",
            "startswith",
            "endswith",
            "join",
            "format",
            "find",
            "count",
            "title",
            "capitalize",
            "isdigit",
            "zfill",
        ],
        "dict" => &["get", "keys", "values", "items"],
        "list" | "tuple" => &["index", "count"],
        _ => &[],
    };
    methods.contains(&name)
}
