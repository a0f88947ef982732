//! The parser: tokens to an [`Expr`] tree, by recursive descent over Python's grammar (the subset).

use super::lex::{lex_with_assign, Tok};
use crate::xacro::value::{float_repr, Value};

/// A parsed expression.
#[derive(Debug, Clone)]
pub enum Expr {
    Const(Value),
    Name(String),
    Attr(Box<Expr>, String),
    Index(Box<Expr>, Box<Expr>),
    Slice(Box<Expr>, [Option<Box<Expr>>; 3]),
    Call(Box<Expr>, Vec<Expr>, Vec<(String, Expr)>),
    Neg(Box<Expr>),
    Pos(Box<Expr>),
    Not(Box<Expr>),
    Bin(&'static str, Box<Expr>, Box<Expr>),
    And(Box<Expr>, Box<Expr>),
    Or(Box<Expr>, Box<Expr>),
    Compare(Box<Expr>, Vec<(&'static str, Expr)>),
    IfElse(Box<Expr>, Box<Expr>, Box<Expr>),
    List(Vec<Expr>),
    Tuple(Vec<Expr>),
    Dict(Vec<(Expr, Expr)>),
    /// `[elt for names in iter if cond…]`
    Comp(Box<Expr>, Vec<String>, Box<Expr>, Vec<Expr>),
}

/// A call's positional and keyword arguments.
pub(super) type CallArgs = (Vec<Expr>, Vec<(String, Expr)>);

/// Deepest nesting of an expression (parentheses, brackets, operators), so that a hostile one
/// cannot exhaust the stack.
const MAX_NESTING: usize = 200;

struct Parser {
    toks: Vec<Tok>,
    at: usize,
    depth: usize,
}

fn is_kw(t: Option<&Tok>, kw: &str) -> bool {
    matches!(t, Some(Tok::Name(n)) if n == kw)
}

impl Parser {
    fn peek(&self) -> Option<&Tok> {
        self.toks.get(self.at)
    }
    fn peek_op(&self, op: &str) -> bool {
        matches!(self.peek(), Some(Tok::Op(o)) if *o == op)
    }
    fn eat_op(&mut self, op: &str) -> bool {
        let yes = self.peek_op(op);
        if yes {
            self.at += 1;
        }
        yes
    }
    fn eat_kw(&mut self, kw: &str) -> bool {
        let yes = is_kw(self.peek(), kw);
        if yes {
            self.at += 1;
        }
        yes
    }
    fn expect_op(&mut self, op: &str) -> Result<(), String> {
        if self.eat_op(op) {
            Ok(())
        } else {
            Err(format!("expected `{op}` {}", self.here()))
        }
    }
    fn here(&self) -> String {
        match self.peek() {
            None => "at the end of the expression".into(),
            Some(t) => format!("before {}", describe(t)),
        }
    }

    /// testlist: `a` or `a, b` (a tuple).
    fn testlist(&mut self) -> Result<Expr, String> {
        let first = self.test()?;
        if !self.peek_op(",") {
            return Ok(first);
        }
        let mut items = vec![first];
        while self.eat_op(",") {
            if self.at_end_of_list() {
                break;
            }
            items.push(self.test()?);
        }
        Ok(Expr::Tuple(items))
    }

    fn at_end_of_list(&self) -> bool {
        self.peek().is_none() || self.peek_op(")") || self.peek_op("]") || self.peek_op("}")
    }

    fn test(&mut self) -> Result<Expr, String> {
        self.depth += 1;
        if self.depth > MAX_NESTING {
            return Err(format!(
                "expression nested deeper than {MAX_NESTING} levels"
            ));
        }
        let r = self.test_inner();
        self.depth -= 1;
        r
    }

    fn test_inner(&mut self) -> Result<Expr, String> {
        if is_kw(self.peek(), "lambda") {
            return Err("lambda is not supported in xacro expressions here".into());
        }
        let e = self.or_test()?;
        if self.eat_kw("if") {
            let cond = self.or_test()?;
            if !self.eat_kw("else") {
                return Err(format!("expected `else` {}", self.here()));
            }
            let other = self.test()?;
            return Ok(Expr::IfElse(Box::new(cond), Box::new(e), Box::new(other)));
        }
        Ok(e)
    }

    fn or_test(&mut self) -> Result<Expr, String> {
        let mut e = self.and_test()?;
        while self.eat_kw("or") {
            e = Expr::Or(Box::new(e), Box::new(self.and_test()?));
        }
        Ok(e)
    }

    fn and_test(&mut self) -> Result<Expr, String> {
        let mut e = self.not_test()?;
        while self.eat_kw("and") {
            e = Expr::And(Box::new(e), Box::new(self.not_test()?));
        }
        Ok(e)
    }

    fn not_test(&mut self) -> Result<Expr, String> {
        if self.eat_kw("not") {
            return Ok(Expr::Not(Box::new(self.not_test()?)));
        }
        self.comparison()
    }

    fn comp_op(&mut self) -> Option<&'static str> {
        for op in ["==", "!=", "<=", ">=", "<", ">"] {
            if self.eat_op(op) {
                return Some(op);
            }
        }
        if self.eat_kw("in") {
            return Some("in");
        }
        if is_kw(self.peek(), "not") && is_kw(self.toks.get(self.at + 1), "in") {
            self.at += 2;
            return Some("not in");
        }
        if self.eat_kw("is") {
            return Some(if self.eat_kw("not") { "is not" } else { "is" });
        }
        None
    }

    fn comparison(&mut self) -> Result<Expr, String> {
        let first = self.arith()?;
        let mut rest = Vec::new();
        while let Some(op) = self.comp_op() {
            rest.push((op, self.arith()?));
        }
        Ok(if rest.is_empty() {
            first
        } else {
            Expr::Compare(Box::new(first), rest)
        })
    }

    fn arith(&mut self) -> Result<Expr, String> {
        let mut e = self.term()?;
        loop {
            let op = if self.eat_op("+") {
                "+"
            } else if self.eat_op("-") {
                "-"
            } else {
                return Ok(e);
            };
            e = Expr::Bin(op, Box::new(e), Box::new(self.term()?));
        }
    }

    fn term(&mut self) -> Result<Expr, String> {
        let mut e = self.factor()?;
        loop {
            let op = ["*", "//", "/", "%"]
                .into_iter()
                .find(|op| self.peek_op(op));
            let Some(op) = op else { return Ok(e) };
            self.at += 1;
            e = Expr::Bin(op, Box::new(e), Box::new(self.factor()?));
        }
    }

    fn factor(&mut self) -> Result<Expr, String> {
        self.depth += 1;
        if self.depth > MAX_NESTING {
            return Err(format!(
                "expression nested deeper than {MAX_NESTING} levels"
            ));
        }
        let r = self.factor_inner();
        self.depth -= 1;
        r
    }

    fn factor_inner(&mut self) -> Result<Expr, String> {
        if self.eat_op("-") {
            return Ok(Expr::Neg(Box::new(self.factor()?)));
        }
        if self.eat_op("+") {
            return Ok(Expr::Pos(Box::new(self.factor()?)));
        }
        let base = self.atom_expr()?;
        if self.eat_op("**") {
            return Ok(Expr::Bin("**", Box::new(base), Box::new(self.factor()?)));
        }
        Ok(base)
    }

    fn atom_expr(&mut self) -> Result<Expr, String> {
        let mut e = self.atom()?;
        loop {
            if self.eat_op(".") {
                match self.peek().cloned() {
                    Some(Tok::Name(n)) => {
                        self.at += 1;
                        e = Expr::Attr(Box::new(e), n);
                    }
                    _ => return Err(format!("expected a name after `.` {}", self.here())),
                }
            } else if self.eat_op("(") {
                let (args, kwargs) = self.call_args()?;
                e = Expr::Call(Box::new(e), args, kwargs);
            } else if self.eat_op("[") {
                e = self.subscript(e)?;
            } else {
                return Ok(e);
            }
        }
    }

    fn subscript(&mut self, e: Expr) -> Result<Expr, String> {
        let mut parts: [Option<Box<Expr>>; 3] = [None, None, None];
        let mut k = 0;
        let mut slice = false;
        loop {
            if self.peek_op(":") {
                self.at += 1;
                slice = true;
                k += 1;
                if k > 2 {
                    return Err("too many `:` in a slice".into());
                }
                continue;
            }
            if self.eat_op("]") {
                break;
            }
            if parts[k].is_some() {
                return Err(format!("expected `]` {}", self.here()));
            }
            parts[k] = Some(Box::new(if slice {
                self.test()?
            } else {
                self.testlist()?
            }));
        }
        if slice {
            Ok(Expr::Slice(Box::new(e), parts))
        } else {
            let [Some(i), None, None] = parts else {
                return Err("empty subscript `[]`".into());
            };
            Ok(Expr::Index(Box::new(e), i))
        }
    }

    fn call_args(&mut self) -> Result<CallArgs, String> {
        let mut args = Vec::new();
        let mut kwargs = Vec::new();
        while !self.eat_op(")") {
            if self.peek_op("*") || self.peek_op("**") {
                return Err("`*args` and `**kwargs` in calls are not supported".into());
            }
            if let Some(Tok::Name(n)) = self.peek().cloned() {
                if matches!(self.toks.get(self.at + 1), Some(Tok::Op("="))) {
                    self.at += 2;
                    kwargs.push((n, self.test()?));
                    if !self.eat_op(",") {
                        self.expect_op(")")?;
                        break;
                    }
                    continue;
                }
            }
            args.push(self.test()?);
            if !self.eat_op(",") {
                self.expect_op(")")?;
                break;
            }
        }
        Ok((args, kwargs))
    }

    fn atom(&mut self) -> Result<Expr, String> {
        let Some(t) = self.peek().cloned() else {
            return Err("the expression ends too early".into());
        };
        self.at += 1;
        Ok(match t {
            Tok::Int(i) => Expr::Const(Value::Int(i)),
            Tok::Float(f) => Expr::Const(Value::Float(f)),
            Tok::Str(mut s) => {
                // Adjacent strings concatenate.
                while let Some(Tok::Str(more)) = self.peek() {
                    s.push_str(more);
                    self.at += 1;
                }
                Expr::Const(Value::str(&s))
            }
            Tok::Name(n) => match n.as_str() {
                "True" => Expr::Const(Value::Bool(true)),
                "False" => Expr::Const(Value::Bool(false)),
                "None" => Expr::Const(Value::None),
                "and" | "or" | "if" | "else" | "in" | "is" | "for" | "lambda" | "import"
                | "def" | "class" | "return" | "yield" | "del" | "global" | "while" => {
                    return Err(format!("unexpected keyword `{n}`"))
                }
                _ => Expr::Name(n),
            },
            Tok::Op("(") => {
                if self.eat_op(")") {
                    return Ok(Expr::Tuple(Vec::new()));
                }
                let first = self.test()?;
                if self.eat_op(")") {
                    return Ok(first);
                }
                let mut items = vec![first];
                while self.eat_op(",") {
                    if self.peek_op(")") {
                        break;
                    }
                    items.push(self.test()?);
                }
                self.expect_op(")")?;
                Expr::Tuple(items)
            }
            Tok::Op("[") => self.list_display()?,
            Tok::Op("{") => self.dict_display()?,
            other @ Tok::Op(_) => return Err(format!("unexpected {}", describe(&other))),
        })
    }

    fn list_display(&mut self) -> Result<Expr, String> {
        if self.eat_op("]") {
            return Ok(Expr::List(Vec::new()));
        }
        let first = self.test()?;
        if self.eat_kw("for") {
            let mut names = Vec::new();
            loop {
                match self.peek().cloned() {
                    Some(Tok::Name(n)) => {
                        self.at += 1;
                        names.push(n);
                    }
                    _ => return Err(format!("expected a name after `for` {}", self.here())),
                }
                if !self.eat_op(",") {
                    break;
                }
            }
            if !self.eat_kw("in") {
                return Err(format!("expected `in` {}", self.here()));
            }
            let iter = self.or_test()?;
            let mut conds = Vec::new();
            while self.eat_kw("if") {
                conds.push(self.or_test()?);
            }
            if is_kw(self.peek(), "for") {
                return Err("nested `for` in a comprehension is not supported".into());
            }
            self.expect_op("]")?;
            return Ok(Expr::Comp(Box::new(first), names, Box::new(iter), conds));
        }
        let mut items = vec![first];
        while self.eat_op(",") {
            if self.peek_op("]") {
                break;
            }
            items.push(self.test()?);
        }
        self.expect_op("]")?;
        Ok(Expr::List(items))
    }

    fn dict_display(&mut self) -> Result<Expr, String> {
        let mut items = Vec::new();
        while !self.eat_op("}") {
            let k = self.test()?;
            if !self.eat_op(":") {
                return Err("sets are not supported (expected `:` in a dict)".into());
            }
            let v = self.test()?;
            items.push((k, v));
            if !self.eat_op(",") {
                self.expect_op("}")?;
                break;
            }
        }
        Ok(Expr::Dict(items))
    }
}

fn describe(t: &Tok) -> String {
    match t {
        Tok::Int(i) => format!("`{i}`"),
        Tok::Float(f) => format!("`{}`", float_repr(*f)),
        Tok::Str(s) => format!("the string {}", crate::xacro::value::str_repr(s)),
        Tok::Name(n) => format!("`{n}`"),
        Tok::Op(o) => format!("`{o}`"),
    }
}

/// Parses an expression (`${…}`'s content).
pub fn parse(src: &str) -> Result<Expr, String> {
    // A lone `=` (keyword arguments) is lexed here: the operator table holds `==` only.
    let toks = lex_with_assign(src)?;
    if toks.is_empty() {
        return Err("empty expression".into());
    }
    let mut p = Parser {
        toks,
        at: 0,
        depth: 0,
    };
    let e = p.testlist()?;
    if p.at < p.toks.len() {
        return Err(format!("unexpected {}", describe(&p.toks[p.at])));
    }
    Ok(e)
}
