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

use super::value::{float_repr, py_eq, Dict, Value};
use std::rc::Rc;

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

#[derive(Debug, Clone, PartialEq)]
enum Tok {
    Int(i64),
    Float(f64),
    Str(String),
    Name(String),
    Op(&'static str),
}

const OPS: [&str; 27] = [
    "**", "//", "==", "!=", "<=", ">=", "<>", "<", ">", "+", "-", "*", "/", "%", "(", ")", "[",
    "]", "{", "}", ",", ":", ".", "~", "&", "|", "^",
];

fn lex(src: &str) -> Result<Vec<Tok>, String> {
    let b = src.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        if c.is_ascii_whitespace() {
            i += 1;
        } else if c.is_ascii_digit() || (c == b'.' && b.get(i + 1).is_some_and(u8::is_ascii_digit))
        {
            i = lex_number(src, i, &mut out)?;
        } else if c == b'\'' || c == b'"' {
            i = lex_string(src, i, &mut out)?;
        } else if c.is_ascii_alphabetic() || c == b'_' || c >= 0x80 {
            let start = i;
            while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'_' || b[i] >= 0x80) {
                i += 1;
            }
            let word = &src[start..i];
            // String prefixes: r'…' is a raw string; f-strings and bytes are outside the subset.
            if i < b.len() && (b[i] == b'\'' || b[i] == b'"') {
                match word {
                    "r" | "R" => {
                        i = lex_raw_string(src, i, &mut out)?;
                        continue;
                    }
                    "f" | "F" | "b" | "B" | "rb" | "br" | "fr" | "rf" => {
                        return Err(format!(
                            "{word}'…' strings are not supported in xacro expressions"
                        ))
                    }
                    _ => {}
                }
            }
            out.push(Tok::Name(word.to_string()));
        } else if let Some(op) = OPS.iter().find(|op| src[i..].starts_with(**op)) {
            if matches!(*op, "~" | "&" | "|" | "^" | "<>") {
                return Err(format!("the operator `{op}` is not supported"));
            }
            out.push(Tok::Op(op));
            i += op.len();
        } else {
            let ch = src[i..].chars().next().unwrap_or('?');
            return Err(format!("invalid character `{ch}` in expression"));
        }
    }
    Ok(out)
}

fn lex_number(src: &str, start: usize, out: &mut Vec<Tok>) -> Result<usize, String> {
    let b = src.as_bytes();
    let mut i = start;
    if b[i] == b'0' && matches!(b.get(i + 1), Some(b'x' | b'X')) {
        i += 2;
        let s = i;
        while i < b.len() && b[i].is_ascii_hexdigit() {
            i += 1;
        }
        let v = i64::from_str_radix(&src[s..i], 16)
            .map_err(|_| format!("invalid number `{}`", &src[start..i]))?;
        out.push(Tok::Int(v));
        return Ok(i);
    }
    let mut float = false;
    while i < b.len() && (b[i].is_ascii_digit() || b[i] == b'_') {
        i += 1;
    }
    if i < b.len() && b[i] == b'.' {
        float = true;
        i += 1;
        while i < b.len() && (b[i].is_ascii_digit() || b[i] == b'_') {
            i += 1;
        }
    }
    if i < b.len() && (b[i] == b'e' || b[i] == b'E') {
        let mut j = i + 1;
        if j < b.len() && (b[j] == b'+' || b[j] == b'-') {
            j += 1;
        }
        if j < b.len() && b[j].is_ascii_digit() {
            float = true;
            i = j;
            while i < b.len() && b[i].is_ascii_digit() {
                i += 1;
            }
        }
    }
    let text: String = src[start..i].chars().filter(|c| *c != '_').collect();
    if i < b.len() && (b[i].is_ascii_alphabetic() || b[i] == b'_') {
        return Err(format!("invalid number `{}…`", &src[start..=i]));
    }
    if float {
        out.push(Tok::Float(
            text.parse()
                .map_err(|_| format!("invalid number `{text}`"))?,
        ));
    } else {
        match text.parse::<i64>() {
            Ok(v) => out.push(Tok::Int(v)),
            Err(_) => return Err(format!("integer `{text}` is too large")),
        }
    }
    Ok(i)
}

fn lex_raw_string(src: &str, start: usize, out: &mut Vec<Tok>) -> Result<usize, String> {
    let q = src.as_bytes()[start] as char;
    let rest = &src[start + 1..];
    let end = rest
        .find(q)
        .ok_or_else(|| "unterminated string in expression".to_string())?;
    out.push(Tok::Str(rest[..end].to_string()));
    Ok(start + 1 + end + 1)
}

fn lex_string(src: &str, start: usize, out: &mut Vec<Tok>) -> Result<usize, String> {
    let q = src.as_bytes()[start] as char;
    if src[start..].starts_with(&format!("{q}{q}{q}")) {
        return Err("triple-quoted strings are not supported in xacro expressions".into());
    }
    let mut s = String::new();
    let mut chars = src[start + 1..].char_indices();
    while let Some((k, c)) = chars.next() {
        if c == q {
            out.push(Tok::Str(s));
            return Ok(start + 1 + k + 1);
        }
        if c != '\\' {
            s.push(c);
            continue;
        }
        let Some((_, e)) = chars.next() else { break };
        match e {
            'n' => s.push('\n'),
            't' => s.push('\t'),
            'r' => s.push('\r'),
            '0' => s.push('\0'),
            '\\' | '\'' | '"' => s.push(e),
            '\n' => {}
            'x' | 'u' => {
                let n = if e == 'x' { 2 } else { 4 };
                let hex: String = (0..n)
                    .filter_map(|_| chars.next().map(|(_, c)| c))
                    .collect();
                let ch = u32::from_str_radix(&hex, 16)
                    .ok()
                    .and_then(char::from_u32)
                    .ok_or_else(|| format!("invalid escape `\\{e}{hex}` in string"))?;
                s.push(ch);
            }
            other => {
                s.push('\\');
                s.push(other);
            }
        }
    }
    Err("unterminated string in expression".into())
}

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
type CallArgs = (Vec<Expr>, Vec<(String, Expr)>);

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
            other => return Err(format!("unexpected {}", describe(&other))),
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
        Tok::Str(s) => format!("the string {}", super::value::str_repr(s)),
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

/// [`lex`], with each lone `=` (not part of `==`, `<=`, `>=`, `!=`) as an `=` token.
fn lex_with_assign(src: &str) -> Result<Vec<Tok>, String> {
    let mut toks = Vec::new();
    let mut piece = String::new();
    let mut in_str: Option<char> = None;
    let chars: Vec<char> = src.chars().collect();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        if let Some(q) = in_str {
            piece.push(c);
            if c == '\\' && i + 1 < chars.len() {
                piece.push(chars[i + 1]);
                i += 1;
            } else if c == q {
                in_str = None;
            }
        } else if c == '\'' || c == '"' {
            in_str = Some(c);
            piece.push(c);
        } else if c == '='
            && chars.get(i + 1) != Some(&'=')
            && !matches!(piece.chars().last(), Some('=' | '<' | '>' | '!'))
        {
            toks.extend(lex(&piece)?);
            toks.push(Tok::Op("="));
            piece.clear();
        } else {
            piece.push(c);
            if c == '=' && chars.get(i + 1) == Some(&'=') {
                piece.push('=');
                i += 1;
            }
        }
        i += 1;
    }
    toks.extend(lex(&piece)?);
    Ok(toks)
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

struct Eval<'e> {
    env: &'e mut dyn Env,
    locals: Vec<(String, Value)>,
}

/// Whether `name` is one of xacro's global symbols.
pub fn is_global(name: &str) -> bool {
    global(name).is_some()
}

/// Names of xacro's globals, with the builtin each one is.
fn global(name: &str) -> Option<Value> {
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
    match name {
        "pi" => return Some(Value::Float(std::f64::consts::PI)),
        "e" => return Some(Value::Float(std::f64::consts::E)),
        "tau" => return Some(Value::Float(std::f64::consts::TAU)),
        "inf" => return Some(Value::Float(f64::INFINITY)),
        "nan" => return Some(Value::Float(f64::NAN)),
        _ => {}
    }
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
    FNS.into_iter()
        .find(|f| &f[5..] == name)
        .map(Value::Builtin)
}

fn module_attr(module: &str, name: &str) -> Option<Value> {
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

fn num(v: &Value, what: &str) -> Result<f64, String> {
    v.as_f64()
        .ok_or_else(|| format!("{what} needs a number, not {} {}", v.type_name(), v.repr()))
}

fn int_of(v: &Value) -> Option<i64> {
    match v {
        Value::Int(i) => Some(*i),
        Value::Bool(b) => Some(i64::from(*b)),
        _ => None,
    }
}

fn overflow() -> String {
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
            if x.len() + y.len() > super::MAX_TEXT {
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
            if s.len().saturating_mul(k) > super::MAX_TEXT {
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
        ("%", Str(fmt), args) => return super::builtins::percent_format(fmt, args).map(Some),
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

fn compare(op: &str, a: &Value, b: &Value) -> Result<bool, String> {
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

/// Python's ordering of two values (`None` where Python raises TypeError).
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

fn subscript(v: &Value, i: &Value) -> Result<Value, String> {
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

fn slice_bounds(parts: [Option<i64>; 3], len: usize) -> Result<Vec<usize>, String> {
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

impl Eval<'_> {
    fn eval(&mut self, e: &Expr) -> Result<Value, String> {
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
                super::builtins::call(name, args, kwargs)
            }
            Value::Method(recv, m) => super::builtins::method(recv, m, args, kwargs),
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

/// `a < b` in Python.
pub fn less(a: &Value, b: &Value) -> Result<bool, String> {
    compare("<", a, b)
}

#[cfg(test)]
mod tests {
    use super::*;

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
