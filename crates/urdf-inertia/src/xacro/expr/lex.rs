//! Tokens: numbers, strings, names and operators, with Python's literal rules.

#[derive(Debug, Clone, PartialEq)]
pub(super) enum Tok {
    Int(i64),
    Float(f64),
    Str(String),
    Name(String),
    Op(&'static str),
}

pub(super) const OPS: [&str; 27] = [
    "**", "//", "==", "!=", "<=", ">=", "<>", "<", ">", "+", "-", "*", "/", "%", "(", ")", "[",
    "]", "{", "}", ",", ":", ".", "~", "&", "|", "^",
];

pub(super) fn lex(src: &str) -> Result<Vec<Tok>, String> {
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

/// [`lex`], with each lone `=` (not part of `==`, `<=`, `>=`, `!=`) as an `=` token.
pub(super) fn lex_with_assign(src: &str) -> Result<Vec<Tok>, String> {
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
