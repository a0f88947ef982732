//! Text helpers shared by the readers, the splice and the commands: line numbers for byte offsets, and
//! the one number formatter every output uses (URDF, tables, JSON).
//!
//! Numbers are written as a person would: `13.11`, not `13.109999999999998`. A computed value is only
//! known to within its error estimate, so any decimal within that distance of it is an equally honest
//! answer; the formatter writes the shortest one. The distance is absolute, `relative error × scale`,
//! where the scale is the size of what the number belongs to (the tensor's largest entry for products of
//! inertia, the link's size for the centre of mass), so a product of inertia of 1e-19 beside moments of
//! 1e-2 is written as `0`.
//!
//! ```
//! use urdf_inertia::text::{shortest, shortest_within, significant};
//! assert_eq!(shortest(13.109999999999998), "13.109999999999998");
//! assert_eq!(shortest_within(13.109999999999998, 13.11 * 8.9e-16), "13.11");
//! assert_eq!(shortest_within(-3.0e-19, 0.026 * 8.9e-16), "0");
//! assert_eq!(significant(8.4412, 4), "8.441");
//! assert_eq!(shortest(-0.0), "0");
//! ```

/// The most that rounding may move a written value, relative: the error estimate says which digits are
/// round-off noise, but a model error (caps, a hull) bounds how far the solid can be from the truth, not
/// how the solid's own numbers should be written. They keep six digits at least, so a second `fill`
/// and `check` see the solid that was computed.
pub const MAX_ROUNDING: f64 = 1e-6;

/// The relative tolerance the formatter rounds within for a value whose relative error estimate is
/// `error`: at least the f64 round-off floor, at most [`MAX_ROUNDING`] (also for an unbounded or NaN
/// estimate).
pub fn rounding_tolerance(error: f64) -> f64 {
    const FLOOR: f64 = crate::geometry::ROUND_OFF_FLOOR;
    if error.is_nan() {
        MAX_ROUNDING
    } else {
        error.clamp(FLOOR, MAX_ROUNDING)
    }
}

/// Line numbers (1-based) for byte positions, counted in one pass when positions increase (elements come
/// in document order); an earlier position is counted from the start.
#[derive(Debug)]
pub(crate) struct LineCounter<'a> {
    bytes: &'a [u8],
    pos: usize,
    line: usize,
}

impl<'a> LineCounter<'a> {
    pub(crate) fn new(bytes: &'a [u8]) -> Self {
        LineCounter {
            bytes,
            pos: 0,
            line: 1,
        }
    }

    /// The line of byte offset `pos`.
    pub(crate) fn at(&mut self, pos: usize) -> usize {
        let pos = pos.min(self.bytes.len());
        if pos < self.pos {
            return line_of(self.bytes, pos);
        }
        self.line += count_newlines(&self.bytes[self.pos..pos]);
        self.pos = pos;
        self.line
    }
}

/// The line (1-based) of byte offset `pos`.
pub(crate) fn line_of(bytes: &[u8], pos: usize) -> usize {
    1 + count_newlines(&bytes[..pos.min(bytes.len())])
}

/// How many `\n` bytes `bytes` holds.
pub(crate) fn count_newlines(bytes: &[u8]) -> usize {
    // memchr's counter: a byte-wise sum took 2.5 instructions a byte (130 M of a 28.8 MB DAE's 2 G).
    memchr::memchr_iter(b'\n', bytes).count()
}

/// How many digits the URDF and JSON numbers get.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Digits {
    /// The shortest decimal within the value's own error estimate (see the module docs).
    #[default]
    Auto,
    /// The shortest text that reads back as the same f64 (every bit kept).
    Full,
    /// This many significant digits (3 to 17); a rounded tensor is re-checked for validity.
    Fixed(u32),
}

impl std::str::FromStr for Digits {
    type Err = String;

    /// `auto`, `full`, or a number of significant digits from 3 to 17.
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "auto" => Ok(Digits::Auto),
            "full" => Ok(Digits::Full),
            _ => match s.parse::<u32>() {
                Ok(n) if (3..=17).contains(&n) => Ok(Digits::Fixed(n)),
                _ => Err(format!(
                    "`{s}`: expected `auto`, `full` or a number of significant digits from 3 to 17"
                )),
            },
        }
    }
}

/// `s` with its control characters written as escapes (`\n`, `\r`, `\t`, `\x1b`, `\u{85}`), for every
/// text message that shows something an input file or a user controls: a link name holding a newline
/// could otherwise forge a CI annotation line, and an ESC rewrite the terminal. Borrowed unchanged when
/// there is nothing to escape (the usual case).
pub fn escape_control(s: &str) -> std::borrow::Cow<'_, str> {
    if !s.chars().any(char::is_control) {
        return s.into();
    }
    let mut out = String::with_capacity(s.len() + 8);
    for c in s.chars() {
        match c {
            '\n' => out.push_str("\\n"),
            '\r' => out.push_str("\\r"),
            '\t' => out.push_str("\\t"),
            c if (c as u32) < 0x80 && c.is_control() => {
                let _ = std::fmt::Write::write_fmt(&mut out, format_args!("\\x{:02x}", c as u32));
            }
            c if c.is_control() => {
                let _ = std::fmt::Write::write_fmt(&mut out, format_args!("\\u{{{:x}}}", c as u32));
            }
            c => out.push(c),
        }
    }
    out.into()
}

/// The shortest text that reads back as the same f64: plain notation for ordinary magnitudes,
/// scientific for very small or large ones; `-0` is written `0`.
pub fn shortest(x: f64) -> String {
    if x == 0.0 {
        return "0".into();
    }
    let a = x.abs();
    if (1e-4..1e9).contains(&a) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// `x` rounded to `digits` significant digits (at least 1), as an f64.
pub fn round_significant(x: f64, digits: u32) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return if x == 0.0 { 0.0 } else { x };
    }
    let precision = usize::try_from(digits.max(1) - 1).unwrap_or(0);
    format!("{x:.precision$e}").parse().unwrap_or(x)
}

/// `x` with `digits` significant digits, written shortest (`1.50000e0` is `1.5`).
pub fn significant(x: f64, digits: u32) -> String {
    shortest(round_significant(x, digits))
}

/// The decimal with the fewest significant digits within `delta` (absolute) of `x`, as an f64: `0` when
/// `|x| ≤ delta`, `x` itself when `delta` is not a positive finite number.
pub fn within(x: f64, delta: f64) -> f64 {
    if !(x.is_finite() && delta > 0.0 && delta.is_finite()) {
        return if x == 0.0 { 0.0 } else { x };
    }
    if x.abs() <= delta {
        return 0.0;
    }
    // Rounding to p significant digits gives the nearest p-digit decimal, so the first p that lands
    // within delta gives the shortest decimal there is. The p-digit roundings are cut from the
    // shortest round-trip digits (see [`ShortestDigits`]) instead of formatting x 17 times: the
    // fill's writing was 3% of filling example-robot-data, nearly all of it here.
    let digits = ShortestDigits::of(x);
    (1..digits.len())
        .map(|p| {
            digits
                .rounded(p)
                .unwrap_or_else(|| round_significant(x, p as u32))
        })
        .find(|y| (y - x).abs() <= delta)
        .unwrap_or(x)
}

/// The shortest decimal digits that read back as `x` (Rust's `{:e}`: the shortest, and of those the
/// nearest to x). Rounding them to fewer digits gives the nearest p-digit decimal to x itself, except
/// at a tie (the digits cut off are exactly `5`): a rounding boundary strictly between x and these
/// digits would be a shorter, or as short and nearer, decimal that reads back as x. And at p = their
/// length they are x's own nearest p-digit decimal, which reads back as x, so no longer p is tried.
struct ShortestDigits {
    negative: bool,
    digits: Vec<u8>,
    exponent: i32,
}

impl ShortestDigits {
    fn of(x: f64) -> Self {
        let text = format!("{:e}", x.abs());
        let (mantissa, exponent) = text.split_once('e').unwrap_or((&text, "0"));
        ShortestDigits {
            negative: x < 0.0,
            digits: mantissa.bytes().filter(u8::is_ascii_digit).collect(),
            exponent: exponent.parse().unwrap_or(0),
        }
    }

    fn len(&self) -> usize {
        self.digits.len()
    }

    /// The digits rounded to `p` (fewer than all) as an f64; `None` at a tie.
    fn rounded(&self, p: usize) -> Option<f64> {
        let (kept, cut) = self.digits.split_at(p);
        if cut == b"5" {
            return None;
        }
        let mut kept = kept.to_vec();
        let mut exponent = self.exponent;
        if cut[0] >= b'5' {
            // Round up, carrying through nines.
            if let Some(i) = kept.iter().rposition(|&d| d != b'9') {
                kept[i] += 1;
                kept[i + 1..].fill(b'0');
            } else {
                kept.fill(b'0');
                kept[0] = b'1';
                exponent += 1;
            }
        }
        let mut text = String::with_capacity(p + 8);
        if self.negative {
            text.push('-');
        }
        text.push(char::from(kept[0]));
        text.push('.');
        text.extend(kept[1..].iter().map(|&d| char::from(d)));
        text.push('0');
        text.push('e');
        text.push_str(&exponent.to_string());
        text.parse().ok()
    }
}

/// [`within`], written with [`shortest`].
pub fn shortest_within(x: f64, delta: f64) -> String {
    shortest(within(x, delta))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// [`within`] as it was: each p formatted from x itself.
    fn within_reference(x: f64, delta: f64) -> f64 {
        if !(x.is_finite() && delta > 0.0 && delta.is_finite()) {
            return if x == 0.0 { 0.0 } else { x };
        }
        if x.abs() <= delta {
            return 0.0;
        }
        (1..=17)
            .map(|p| round_significant(x, p))
            .find(|y| (y - x).abs() <= delta)
            .unwrap_or(x)
    }

    /// The digits cut from the shortest round-trip text give what formatting x to p digits gives, to
    /// the bit: random f64 of every magnitude, decimals with few digits and their neighbours, ties
    /// (0.125, 2.5, 9.5, 0.45…), nines that carry (9.96, 0.0999…), against tolerances from 1e-17 of
    /// the value to 10 times it.
    #[test]
    fn within_is_the_formatting_scan() {
        let mut rng = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || crate::xorshift(&mut rng);
        let mut xs: Vec<f64> = vec![
            0.125,
            2.5,
            9.5,
            0.45,
            9.96,
            0.0999,
            0.09999999999999999,
            13.109999999999998,
            0.0007999999999999999,
            1.0,
            999.5,
            1e-300,
            5e-324,
            1.7976931348623157e308,
            0.3,
        ];
        for _ in 0..20_000 {
            let x = f64::from_bits(next());
            if x.is_finite() {
                xs.push(x);
            }
            // A short decimal, and its neighbours.
            let d = (next() % 100_000) as f64 / 10f64.powi((next() % 12) as i32);
            xs.extend([d, d.next_up(), d.next_down(), -d]);
        }
        let rels = [
            1e-17,
            4.0 * f64::EPSILON,
            1e-12,
            1e-6,
            1e-3,
            0.05,
            0.5,
            10.0,
        ];
        for &x in &xs {
            for r in rels {
                let delta = x.abs() * r;
                let (got, want) = (within(x, delta), within_reference(x, delta));
                assert_eq!(
                    got.to_bits(),
                    want.to_bits(),
                    "x = {x:e}, delta = {delta:e}"
                );
            }
        }
    }

    #[test]
    fn numbers_drop_round_off_and_nothing_else() {
        // Each noisy value is within 4 ulps of the decimal a person would write.
        let e = 4.0 * f64::EPSILON;
        assert_eq!(shortest_within(13.109999999999998, 13.11 * e), "13.11");
        assert_eq!(shortest_within(0.0007999999999999999, 0.0008 * e), "0.0008");
        assert_eq!(shortest_within(3.4560000000000004, 3.456 * e), "3.456");
        // A real f32 coordinate is not noise: its digits stay.
        assert_eq!(
            shortest_within(0.019999999552965164, 0.02 * e),
            "0.01999999955296516"
        );
        // Below the scale's round-off: zero, and never "-0".
        assert_eq!(shortest_within(-1.9e-18, 0.3 * e), "0");
        assert_eq!(shortest_within(-0.0, 0.0), "0");
        assert_eq!(shortest_within(0.1 + 0.2, 0.0), "0.30000000000000004");
        assert_eq!(shortest(1.5e-9), "1.5e-9");
        assert_eq!(significant(0.123456789, 4), "0.1235");
        assert_eq!(significant(8.4412, 4), "8.441");
        assert_eq!("full".parse(), Ok(Digits::Full));
        assert_eq!("6".parse(), Ok(Digits::Fixed(6)));
        assert!("2".parse::<Digits>().is_err());
    }

    #[test]
    fn control_characters_are_escaped() {
        assert_eq!(escape_control("forearm"), "forearm");
        assert_eq!(
            escape_control("a\n::error::x\u{1b}[2J\t\r\u{7f}\u{85}é"),
            "a\\n::error::x\\x1b[2J\\t\\r\\x7f\\u{85}é"
        );
    }

    #[test]
    fn counts_forward_and_back() {
        let text = b"a\nb\nc\n";
        let mut l = LineCounter::new(text);
        assert_eq!(l.at(0), 1);
        assert_eq!(l.at(2), 2);
        assert_eq!(l.at(5), 3);
        assert_eq!(l.at(1), 1);
    }
}
