//! A minimal element tree of the document, each element's text a span of the file, and the numbers
//! of a text read in place.

use crate::mesh::{parse_f64_bytes, short_decimal, MeshError, MeshErrorKind};
use crate::text::line_of;
use quick_xml::events::Event;
use quick_xml::reader::Reader;
use std::path::Path;

/// A minimal element tree: enough of COLLADA for geometry and scene graphs.
///
/// The tree holds no copy of the text: an element's text is a span of the file's bytes, parsed where
/// it is used (a `<float_array>` or `<p>` is most of a file's size).
#[derive(Debug, Default)]
pub(super) struct El {
    pub(super) name: String,
    pub(super) attrs: Vec<(String, String)>,
    pub(super) children: Vec<El>,
    pub(super) text: Text,
    pub(super) line: usize,
}

/// An element's character data, whitespace-only pieces left out.
#[derive(Debug, Default)]
pub(super) enum Text {
    #[default]
    None,
    /// One piece: a byte range of the file.
    Span(usize, usize),
    /// Several pieces (text around a comment or child), joined as XML joins them.
    Joined(String),
}

impl El {
    /// The element's text (borrowed from the file unless it came in several pieces).
    pub(super) fn text<'a>(&'a self, bytes: &'a [u8]) -> std::borrow::Cow<'a, str> {
        match &self.text {
            Text::None => "".into(),
            Text::Span(a, b) => String::from_utf8_lossy(bytes.get(*a..*b).unwrap_or_default()),
            Text::Joined(s) => s.as_str().into(),
        }
    }
    /// The element's text as bytes, as stored: numbers are ASCII, so they need no UTF-8 decoding
    /// (which was a tenth of reading a large file; figures: docs/benchmarks.md, "Figures behind
    /// choices in the code").
    pub(super) fn raw_text<'a>(&'a self, bytes: &'a [u8]) -> &'a [u8] {
        match &self.text {
            Text::None => b"",
            Text::Span(a, b) => bytes.get(*a..*b).unwrap_or_default(),
            Text::Joined(s) => s.as_bytes(),
        }
    }
    pub(super) fn attr(&self, key: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }
    pub(super) fn child(&self, name: &str) -> Option<&El> {
        self.children.iter().find(|c| c.name == name)
    }
    pub(super) fn children_named<'a>(&'a self, name: &'a str) -> impl Iterator<Item = &'a El> + 'a {
        self.children.iter().filter(move |c| c.name == name)
    }
    /// Every element of the tree, in document order (iterative: deep files must not overflow the stack).
    pub(super) fn walk<'a>(&'a self, out: &mut Vec<&'a El>) {
        let mut stack = vec![self];
        while let Some(e) = stack.pop() {
            out.push(e);
            stack.extend(e.children.iter().rev());
        }
    }
}

/// Deepest element nesting accepted. The tree is dropped recursively (and real files nest a few dozen
/// levels), so a bound keeps a hostile file from overflowing a worker thread's stack.
const MAX_DEPTH: usize = 512;

fn local(name: &[u8]) -> String {
    let s = String::from_utf8_lossy(name);
    match s.rfind(':') {
        Some(i) => s[i + 1..].to_string(),
        None => s.into_owned(),
    }
}

fn element(e: &quick_xml::events::BytesStart<'_>, line: usize) -> El {
    let mut el = El {
        name: local(e.name().as_ref()),
        line,
        ..Default::default()
    };
    // Without the duplicate check, which compares each attribute with all before it (quadratic).
    for a in e.attributes().with_checks(false).flatten() {
        let v = a
            .unescape_value()
            .map(std::borrow::Cow::into_owned)
            .unwrap_or_default();
        el.attrs.push((local(a.key.as_ref()), v));
    }
    el
}

/// Reads the document into a tree of elements, with each element's text kept as a span of the file
/// where it can be; and the line of what follows the root element's end tag, if anything but
/// whitespace, comments and processing instructions does.
///
/// Such a tail is not read. A file saved over a longer one sometimes keeps the old file's end after
/// its own `</COLLADA>` (rtb-data 2.0.0's KUKA `lbr_iiwa_14_r820/visual/base_link2.dae`: a stray
/// `</p>` and more at line 495); assimp, and so `RViz`, Gazebo and pinocchio, read the document up to
/// that end tag and ignore the rest, and so does this reader (the caller says so in a warning).
pub(super) fn parse_tree(bytes: &[u8], path: &Path) -> Result<(El, Option<usize>), MeshError> {
    let mut reader = Reader::from_reader(bytes);
    reader.config_mut().trim_text(false);
    let mut stack: Vec<El> = vec![El {
        name: "#document".into(),
        ..Default::default()
    }];
    let mut lines = crate::text::LineCounter::new(bytes);
    let syntax = |pos: usize, msg: String| {
        MeshError::new(path, Some(line_of(bytes, pos)), MeshErrorKind::Syntax(msg))
    };
    loop {
        let pos = reader.buffer_position() as usize;
        if stack.len() == 1 && !stack[0].children.is_empty() {
            // The root element is closed: only what XML allows after it may follow.
            match reader.read_event() {
                Ok(Event::Eof) => break,
                Ok(Event::Comment(_) | Event::PI(_)) => continue,
                Ok(Event::Text(t)) if t.iter().all(u8::is_ascii_whitespace) => continue,
                _ => {
                    let rest = bytes.get(pos..).unwrap_or_default();
                    let skip = rest.iter().take_while(|b| b.is_ascii_whitespace()).count();
                    let tail = Some(line_of(bytes, pos + skip));
                    return Ok((stack.pop().unwrap_or_default(), tail));
                }
            }
        }
        let event = reader.read_event().map_err(|e| {
            syntax(
                reader.error_position() as usize,
                format!("malformed XML: {e}"),
            )
        })?;
        match event {
            Event::Start(e) => {
                if stack.len() > MAX_DEPTH {
                    return Err(syntax(
                        pos,
                        format!("elements nested deeper than {MAX_DEPTH} levels"),
                    ));
                }
                stack.push(element(&e, lines.at(pos)));
            }
            Event::Empty(e) => {
                let el = element(&e, lines.at(pos));
                if let Some(parent) = stack.last_mut() {
                    parent.children.push(el);
                }
            }
            Event::End(_) => {
                if stack.len() < 2 {
                    return Err(syntax(pos, "unexpected closing tag".into()));
                }
                let done = stack.pop().unwrap_or_default();
                if let Some(parent) = stack.last_mut() {
                    parent.children.push(done);
                }
            }
            Event::Text(t) => {
                if let Some(top) = stack.last_mut() {
                    add_text(top, t.as_ref(), pos, bytes);
                }
            }
            Event::Eof => break,
            _ => {}
        }
    }
    if stack.len() != 1 {
        return Err(MeshError::new(
            path,
            Some(line_of(bytes, bytes.len())),
            MeshErrorKind::Syntax("the XML ends before its elements are closed".into()),
        ));
    }
    Ok((stack.pop().unwrap_or_default(), None))
}

/// Adds a piece of text to `top`: a span of `bytes` while it is one piece borrowed from the file at `pos`,
/// joined text otherwise. Whitespace only matters between two pieces.
fn add_text(top: &mut El, piece: &[u8], pos: usize, bytes: &[u8]) {
    if piece.iter().all(u8::is_ascii_whitespace) {
        // Nothing to keep, unless it separates two pieces.
        if !matches!(top.text, Text::None) {
            top.text = Text::Joined(format!("{} ", top.text(bytes)));
        }
        return;
    }
    // The event borrows the file's bytes from `pos` on; the span is checked anyway.
    let span = (pos, pos + piece.len());
    let borrowed = bytes.get(span.0..span.1) == Some(piece);
    top.text = match std::mem::take(&mut top.text) {
        Text::None if borrowed => Text::Span(span.0, span.1),
        Text::None => Text::Joined(String::from_utf8_lossy(piece).into_owned()),
        Text::Span(a, b) => {
            let mut s = String::from_utf8_lossy(&bytes[a..b]).into_owned();
            s.push_str(&String::from_utf8_lossy(piece));
            Text::Joined(s)
        }
        Text::Joined(mut s) => {
            s.push_str(&String::from_utf8_lossy(piece));
            Text::Joined(s)
        }
    };
}

/// The numbers of an element's text, one at a time (a `<p>` of millions of indices is never a list).
///
/// Words are runs of bytes between ASCII whitespace (what `split_ascii_whitespace` gave on the
/// decoded text: an invalid byte is never whitespace, and its word is no number either way); a
/// short decimal is scanned where it stands, anything else is cut out and parsed by `str::parse`
/// (figures against `from_utf8_lossy`, `split_ascii_whitespace` and `str::parse`:
/// docs/benchmarks.md, "Figures behind choices in the code").
pub(super) fn each_number<'a>(
    el: &'a El,
    text: &'a [u8],
    path: &'a Path,
) -> impl Iterator<Item = Result<f64, MeshError>> + 'a {
    Numbers { rest: text }.map(move |n| n.map_err(|w| not_a_number(el, w, path)))
}

pub(super) fn not_a_number(el: &El, word: &[u8], path: &Path) -> MeshError {
    MeshError::new(
        path,
        Some(el.line),
        MeshErrorKind::Syntax(format!(
            "`{}` is not a number in <{}>",
            String::from_utf8_lossy(word),
            el.name
        )),
    )
}

/// The words of a text as numbers, `Err` a word that is none (see [`each_number`]).
pub(super) struct Numbers<'a> {
    pub(super) rest: &'a [u8],
}

impl<'a> Numbers<'a> {
    /// The text from the next word on (leading whitespace skipped).
    #[inline]
    fn word_start(&self) -> &'a [u8] {
        let mut r = self.rest;
        while let [b, tail @ ..] = r {
            if !b.is_ascii_whitespace() {
                break;
            }
            r = tail;
        }
        r
    }

    /// Takes the first `n` bytes of `r` (from [`Self::word_start`]) as a word if the word ends there:
    /// at the end of the text, or at whitespace, which is passed over with it.
    #[inline]
    fn take_word(&mut self, r: &'a [u8], n: usize) -> bool {
        match r.get(n) {
            None => self.rest = &[],
            Some(b) if b.is_ascii_whitespace() => self.rest = &r[n + 1..],
            Some(_) => return false,
        }
        true
    }

    /// Passes over the next word as [`Iterator::next`] would, without converting it when it is plain
    /// digits (a number, whatever its value); any other word is parsed, so a word that is no number
    /// is the same error. The index lists of `<p>` hold a normal and a texture coordinate index for
    /// every vertex index, and only the vertex's is used.
    #[inline]
    pub(super) fn pass_word(&mut self) -> Option<Result<(), &'a [u8]>> {
        let r = self.word_start();
        let digits = r.iter().take_while(|b| b.is_ascii_digit()).count();
        if digits > 0 && self.take_word(r, digits) {
            return Some(Ok(()));
        }
        self.rest = r;
        self.next().map(|n| n.map(|_| ()))
    }
}

impl<'a> Iterator for Numbers<'a> {
    type Item = Result<f64, &'a [u8]>;

    #[inline]
    fn next(&mut self) -> Option<Self::Item> {
        let r = self.word_start();
        if r.is_empty() {
            self.rest = r;
            return None;
        }
        if let Some((x, n)) = short_decimal(r) {
            if self.take_word(r, n) {
                return Some(Ok(x));
            }
        }
        let len = r
            .iter()
            .position(u8::is_ascii_whitespace)
            .unwrap_or(r.len());
        let (w, after) = r.split_at(len);
        self.rest = after;
        Some(parse_f64_bytes(w).ok_or(w))
    }
}

pub(super) fn numbers(el: &El, bytes: &[u8], path: &Path) -> Result<Vec<f64>, MeshError> {
    each_number(el, el.raw_text(bytes), path).collect()
}
