//! The byte-level readers of the ASCII STL fast path ([`super::ChunkParse`]): eight bytes loaded at
//! a time, the newline and keyword tests on them, the hash of a vertex's text, and the decimal
//! reader of its coordinates.

use crate::mesh::{exponent_suffix, parse_f64_bytes, short_decimal, EXACT_POWERS_OF_TEN};

const ONES: u64 = 0x0101_0101_0101_0101;
pub(super) const HIGHS: u64 = 0x8080_8080_8080_8080;
pub(super) const SPACES: u64 = 0x2020_2020_2020_2020;
const NEWLINES: u64 = 0x0a0a_0a0a_0a0a_0a0a;

/// The eight bytes of `text` from `at` (little-endian: the first byte lowest), zeros past its end.
#[inline(always)]
pub(super) fn load(text: &[u8], at: usize) -> u64 {
    // `get(at..)` then the first eight: two comparisons, where `get(at..at + 8)` also tests
    // `at + 8` for overflow (840.6 M against 838.3 M instructions on the 101.6 MB torus).
    if let Some(&b) = text.get(at..).and_then(|b| b.first_chunk::<8>()) {
        u64::from_le_bytes(b)
    } else {
        let mut w = [0u8; 8];
        let tail = text.get(at..).unwrap_or_default();
        w[..tail.len()].copy_from_slice(tail);
        u64::from_le_bytes(w)
    }
}

/// The sixteen bytes of `text` from `at` as two words ([`load`] of `at` and of `at + 8`), with one
/// bounds test when they are all in `text`: the whole lines compared at each line start of the
/// fast path and the two words of a `%e` number (the 101.6 MB torus of `validation/threads.sh`:
/// 781.7 M instructions against 767.2 M).
#[inline(always)]
pub(super) fn load2(text: &[u8], at: usize) -> (u64, u64) {
    if let Some(&b) = text.get(at..).and_then(|b| b.first_chunk::<16>()) {
        let x = u128::from_le_bytes(b);
        (x as u64, (x >> 64) as u64)
    } else {
        (load(text, at), load(text, at + 8))
    }
}

/// The bit of the first zero byte of `x` and above it (0 when none): exact for the first one.
#[inline(always)]
fn zero_bytes(x: u64) -> u64 {
    x.wrapping_sub(ONES) & !x & HIGHS
}

/// Whether the word at `at` (whose first eight bytes are `w`) is the keyword `k` (lowercase letters,
/// 5 to 8 of them) in any case, followed by ASCII whitespace. A letter `b` is `k`'s in either
/// case exactly when `b | 0x20` is.
#[inline(always)]
pub(super) fn is_word(text: &[u8], at: usize, w: u64, k: &[u8]) -> bool {
    let n = k.len();
    let mask = if n >= 8 { u64::MAX } else { (1 << (8 * n)) - 1 };
    let mut pattern = [0u8; 8];
    pattern[..n].copy_from_slice(k);
    (w | SPACES) & mask == u64::from_le_bytes(pattern)
        && text.get(at + n).is_some_and(u8::is_ascii_whitespace)
}

/// The three coordinates of the vertex line whose text after `vertex` starts at `from` (and ends
/// at a `\n`), when each is a decimal [`exponent_form`] or [`decimal`] reads or else a word
/// [`parse_f64_bytes`] reads to a finite value (−0.0 folded into 0.0): what
/// [`super::AsciiWords::vertex`] gives then; `None` for anything else, which it decides.
#[inline]
pub(super) fn coordinates(text: &[u8], from: usize) -> Option<[f64; 3]> {
    exponent_triple(text, from).or_else(|| any_coordinates(text, from))
}

/// [`coordinates`] when each of the three numbers is one blank and an [`exponent_form`] (what
/// C's `"vertex %e %e %e"` writes): the same value, read without the loop over blanks and the
/// other readers; `None` for any other text, which [`any_coordinates`] then reads (the 101.6 MB
/// torus of `validation/threads.sh`, one thread: 747.1 M instructions with the loop alone,
/// 737.4 M with this first).
#[inline(always)]
fn exponent_triple(text: &[u8], from: usize) -> Option<[f64; 3]> {
    // Read in the next 64 bytes, at least (the text is at most 42 bytes, and the last number's
    // words end 16 bytes after its start): a length the compiler knows, so no bounds test (the
    // 101.6 MB torus of `validation/threads.sh`: 729.1 M instructions in `text`, 721.6 M in this).
    let text = text.get(from..)?.first_chunk::<64>()?;
    if text[0] != b' ' {
        return None;
    }
    // The first two followed by a blank: the next one's.
    let (x, at) = exponent_form(text, 1, true)?;
    let (y, at) = exponent_form(text, at + 1, true)?;
    let (z, _) = exponent_form(text, at + 1, false)?;
    Some([x + 0.0, y + 0.0, z + 0.0])
}

/// [`coordinates`] of any text: blanks skipped, each number read by the first reader that takes it.
#[inline(never)]
fn any_coordinates(text: &[u8], mut from: usize) -> Option<[f64; 3]> {
    let mut p = [0.0; 3];
    for c in &mut p {
        while let Some(b' ' | b'\t' | b'\r' | b'\x0c') = text.get(from) {
            from += 1;
        }
        let x = if let Some((x, end)) = exponent_form(text, from, false) {
            from = end;
            x
        } else {
            let rest = text.get(from..)?;
            // What the eight-byte and short readers do not take (`8.572527e-17`): the word, as
            // the general path parses it; not finite, the general path gives the error.
            let (x, n) = if let Some(d) = decimal(rest) {
                d
            } else {
                let n = rest.iter().position(u8::is_ascii_whitespace)?;
                let x = parse_f64_bytes(&rest[..n]).filter(|x| x.is_finite())?;
                (x, n)
            };
            from += n;
            if !text.get(from)?.is_ascii_whitespace() {
                return None;
            }
            x
        };
        *c = x + 0.0;
    }
    Some(p)
}

/// C's `%e` (`-d.dddddde+dd`: one digit, the point, six digits, an exponent of a sign and two
/// digits) at `text[at..]` followed by ASCII whitespace, the form most exporters write, checked
/// and read in two eight-byte words: [`decimal`]'s value and where the word ends when it takes
/// the word, `None` otherwise. The value is m·10^e with m < 10^7 and |e| ≤ 22, rounded once, as
/// in [`decimal`]. It is a fixed shape, so none of [`decimal`]'s digit counting: the coordinates
/// of the distinct vertex texts of the 101.6 MB torus of `validation/threads.sh` (callgrind, one
/// thread) take 117.1 M instructions with it first, 169.5 M with [`decimal`] alone.
/// With `blank_after`, only a blank may follow it.
#[inline(always)]
fn exponent_form(text: &[u8], at: usize, blank_after: bool) -> Option<(f64, usize)> {
    let negative = text.get(at) == Some(&b'-');
    let i = at + usize::from(negative);
    let (a, b) = load2(text, i);
    // The point, then eight digits with a `0` in its place.
    let digits = (a & !0xff00) | 0x3000;
    let all_digits = (digits.wrapping_add(0x4646_4646_4646_4646) | digits.wrapping_sub(0x3030_3030_3030_3030)) & HIGHS == 0;
    // `e` or `E`, a sign and two digits, in one word: `x`'s bytes are 0, then 0 for `+` or 6 for
    // `-` (bits 1 and 2 equal, where `)` and `/` give 2 and 4), then each digit's value, at most 9
    // (a high nibble of 0, and no high bit when 0x76 is added). Tested byte by byte (and any
    // blank after the first two numbers of [`exponent_triple`], where one must be a blank), the
    // 101.6 MB torus of `validation/threads.sh` took 737.4 M instructions against 729.1 M.
    let x = (b as u32 | 0x20) ^ 0x3030_2b65;
    let bad = (x & 0xf0f0_f9ff) | (x.wrapping_add(0x7676_0000) & 0x8080_0000) | (((x >> 9) ^ (x >> 10)) & 1);
    let after = (b >> 32) as u8;
    if !(all_digits
        && (a >> 8) as u8 == b'.'
        && bad == 0
        && if blank_after { after == b' ' } else { after.is_ascii_whitespace() })
    {
        return None;
    }
    // The digit before the point moved up over it: `0d dddddd`, seven digits.
    let mantissa = digits_value((digits & !0xffff) | ((digits & 0xff) << 8), 8);
    let e = ((x >> 16) & 0xff) as i32 * 10 + (x >> 24) as i32;
    let exponent = if x & 0x0600 != 0 { -e } else { e } - 6;
    // By the exponent itself, no absolute value (a negative index wraps past the table): the
    // 101.6 MB torus of `validation/threads.sh`, 721.6 M instructions by |exponent|, 719.6 M so.
    let power = *SIGNED_POWERS_OF_TEN.get((exponent + 22) as usize)?;
    let x = mantissa as f64;
    let x = if exponent < 0 { x / power } else { x * power };
    Some((if negative { -x } else { x }, i + 12))
}

/// 10^|k| at `k + 22` for k in −22..=22 ([`EXACT_POWERS_OF_TEN`] both ways).
const SIGNED_POWERS_OF_TEN: [f64; 45] = {
    let mut t = [0.0; 45];
    let mut i = 0;
    while i < 45 {
        t[i] = EXACT_POWERS_OF_TEN[i.abs_diff(22)];
        i += 1;
    }
    t
};

/// [`short_decimal`], with the digits before and after the point read in one eight-byte step when
/// they fit in eight bytes with it (`-1.234567e+00`, `0.125`, `42`); longer numbers, and anything it
/// does not take, go to [`short_decimal`]. The value is m·10^e with m < 10^8 and |e| ≤ 22, rounded
/// once, so it is `short_decimal`'s to the bit.
#[inline]
fn decimal(w: &[u8]) -> Option<(f64, usize)> {
    let (negative, mut i) = match w.first() {
        Some(b'-') => (true, 1),
        Some(b'+') => (false, 1),
        _ => (false, 0),
    };
    let v = load(w, i);
    let not_digits = not_digit_bytes(v);
    let whole = not_digits.trailing_zeros() as usize / 8;
    let (mantissa, fraction) = if whole < 7 && (v >> (8 * whole)) as u8 == b'.' {
        // The digits after the point: up to the first non-digit after it.
        let end = (not_digits & !(0xff << (8 * whole))).trailing_zeros() as usize / 8;
        if end == 1 || (end == 8 && w.get(i + 8).is_some_and(u8::is_ascii_digit)) {
            return short_decimal(w);
        }
        // The point dropped: the whole digits moved up one byte over it, a zero digit ahead.
        let low = v & ((1 << (8 * whole)) - 1);
        let digits = (v & !((1 << (8 * (whole + 1))) - 1)) | (low << 8);
        i += end;
        (digits_value(digits, end), end - whole - 1)
    } else {
        if whole == 8 || whole == 0 || (v >> (8 * whole)) as u8 == b'.' {
            return short_decimal(w);
        }
        i += whole;
        (digits_value(v, whole), 0)
    };
    let Some((e, i)) = exponent_suffix(w, i, 3) else {
        return short_decimal(w);
    };
    let exponent = e - fraction as i32;
    // By the signed exponent, as in [`exponent_form`] (at most three digits: no overflow).
    let Some(&power) = SIGNED_POWERS_OF_TEN.get((exponent + 22) as usize) else {
        return short_decimal(w);
    };
    // Exact: m < 2^53.
    let x = mantissa as i64 as f64;
    let x = if exponent < 0 { x / power } else { x * power };
    Some((if negative { -x } else { x }, i))
}

/// The bytes of `v` that are not ASCII digits, nonzero (only the first one is exact: a byte is a
/// digit when its high nibble is 3 and stays 3 when 6 is added, and a carry out of a byte reaches
/// only the bytes after it, past a non-digit).
#[inline(always)]
fn not_digit_bytes(v: u64) -> u64 {
    const HIGH_NIBBLES: u64 = 0xf0f0_f0f0_f0f0_f0f0;
    let x = (v & HIGH_NIBBLES) | ((v.wrapping_add(0x0606_0606_0606_0606) & HIGH_NIBBLES) >> 4);
    x ^ 0x3333_3333_3333_3333
}

/// The value of the first `n` (up to 8) bytes of `v`, decimal digits: the digits moved up to
/// the top bytes (zeros ahead of them), then combined in pairs, fours and eights (SWAR, as
/// `fast_float` parses eight digits).
#[inline(always)]
fn digits_value(v: u64, n: usize) -> u64 {
    if n == 0 {
        return 0;
    }
    let d = (v & 0x0f0f_0f0f_0f0f_0f0f) << (8 * (8 - n));
    let d = d.wrapping_mul(10).wrapping_add(d >> 8);
    let d = ((d & 0x00ff_00ff_00ff_00ff).wrapping_mul((100 << 16) + 1)) >> 16;
    ((d & 0x0000_ffff_0000_ffff).wrapping_mul((10_000 << 32) + 1)) >> 32
}

/// At most 16 bytes of a line (a whole line, its `\n` included, or its start), as two words to
/// compare the text with (what is past its end masked off), or none (no text matches it).
#[derive(Clone, Copy)]
pub(super) struct FixedLine {
    words: [u64; 2],
    masks: [u64; 2],
    len: usize,
}

impl FixedLine {
    pub(super) const NONE: FixedLine = FixedLine {
        words: [1, 0],
        masks: [0, 0],
        len: 0,
    };

    /// The line `text[start..end]` when it ends with its `\n` and is at most 16 bytes long; else
    /// none.
    #[inline]
    pub(super) fn line(text: &[u8], start: usize, end: usize) -> FixedLine {
        if end == start || text[end - 1] != b'\n' {
            return FixedLine::NONE;
        }
        FixedLine::of(text, start, end)
    }

    /// The bytes `text[start..end]` when there are 1 to 16 of them; else none.
    #[inline]
    pub(super) fn of(text: &[u8], start: usize, end: usize) -> FixedLine {
        let n = end - start;
        if n == 0 || n > 16 {
            return FixedLine::NONE;
        }
        let mask = |k: usize| if k >= 8 { u64::MAX } else { (1u64 << (8 * k)) - 1 };
        let masks = [mask(n), mask(n.saturating_sub(8))];
        FixedLine {
            words: [
                load(text, start) & masks[0],
                load(text, start + 8) & masks[1],
            ],
            masks,
            len: n,
        }
    }

    /// The line's length (0 for none).
    #[inline(always)]
    pub(super) fn len(&self) -> usize {
        self.len
    }

    /// Whether the text at `at` begins with this line. The bytes compared need no or into the
    /// UTF-8 accumulator: they are the line's, or-ed into it when it was first taken.
    #[inline(always)]
    pub(super) fn at(&self, text: &[u8], at: usize) -> bool {
        let (a, b) = load2(text, at);
        a & self.masks[0] == self.words[0] && b & self.masks[1] == self.words[1]
    }
}

/// The bit of the first `\n` byte of `w` and above it, when the bytes before it are ASCII; a byte
/// before it that is not ASCII may be flagged instead (the first flagged byte is a `\n` or not
/// ASCII). One operation fewer than [`zero_bytes`], which is exact.
#[inline(always)]
fn newline_or_high(w: u64) -> u64 {
    (w ^ NEWLINES).wrapping_sub(ONES) & HIGHS
}

/// The first `\n` at or after `from`, the words read or-ed into `bytes` (sixteen bytes a step).
/// Past a byte that is not ASCII (or-ed into `bytes` with its word: the chunk is then checked
/// whole) the rest is found by `memchr`.
#[inline]
pub(super) fn newline(text: &[u8], mut from: usize, bytes: &mut u64) -> Option<usize> {
    while from + 16 <= text.len() {
        let (a, b) = (load(text, from), load(text, from + 8));
        *bytes |= a | b;
        let (za, zb) = (newline_or_high(a), newline_or_high(b));
        if za | zb != 0 {
            let at = if za != 0 {
                from + za.trailing_zeros() as usize / 8
            } else {
                from + 8 + zb.trailing_zeros() as usize / 8
            };
            if text.get(at) == Some(&b'\n') {
                return Some(at);
            }
            return memchr::memchr(b'\n', &text[at..]).map(|i| at + i);
        }
        from += 16;
    }
    while from + 8 <= text.len() {
        let w = load(text, from);
        *bytes |= w;
        let z = zero_bytes(w ^ NEWLINES);
        if z != 0 {
            return Some(from + z.trailing_zeros() as usize / 8);
        }
        from += 8;
    }
    *bytes |= load(text, from);
    memchr::memchr(b'\n', &text[from..]).map(|i| from + i)
}

/// `from + len` when it is the first `\n` at or after `from` ([`newline`]'s answer) and the bytes
/// before it are ASCII, found by checking that one is there and none comes before it: at least
/// eight bytes, read once; `None` otherwise (a byte that is not ASCII included: the caller's
/// [`newline`] then reads the line and ors its words for the UTF-8 check). Being ASCII, the
/// bytes of an answer need no or into the UTF-8 accumulator.
#[inline]
pub(super) fn newline_at(text: &[u8], from: usize, len: usize) -> Option<usize> {
    let end = from + len;
    if len < 8 || text.get(end) != Some(&b'\n') {
        return None;
    }
    let line = text.get(from..end)?;
    let last = u64::from_le_bytes(*line.last_chunk::<8>()?);
    let flags = whole_words(line, newline_or_byte_high) | newline_or_byte_high(last);
    (flags & HIGHS == 0).then_some(end)
}

/// The first `\n` at or after `from` and the [`line_hash`] of the text before it (the words read
/// or-ed into `bytes`); `None` when no `\n` comes before the last eight bytes of `text`, or a byte
/// that is not ASCII comes before it (the caller takes the general path).
#[inline]
pub(super) fn text_to_newline(text: &[u8], from: usize, bytes: &mut u64) -> Option<(usize, u64)> {
    let mut at = from;
    while at + 8 <= text.len() {
        let w = load(text, at);
        *bytes |= w;
        let z = newline_or_high(w);
        if z != 0 {
            let end = at + z.trailing_zeros() as usize / 8;
            // A byte that is not ASCII may be flagged first: the general path decides that line.
            if text.get(end) != Some(&b'\n') {
                return None;
            }
            return Some((end, line_hash(&text[from..end])));
        }
        at += 8;
    }
    None
}

/// A top bit set in each byte of `w` that is a `\n` or not ASCII, or (after the first such byte)
/// whatever the borrow makes of the bytes after it: none when `w` has no `\n` and is ASCII. One
/// word holds both tests, so that a line's words need no separate or for the UTF-8 check when
/// this finds nothing (the whole-process instructions of the 101.6 MB torus of
/// `validation/threads.sh`: 838.3 M with the separate or, 822.4 M with this).
#[inline(always)]
fn newline_or_byte_high(w: u64) -> u64 {
    (w ^ NEWLINES).wrapping_sub(ONES) | w
}

/// `f` folded over the whole eight-byte words of `s` from `init` (its tail left out): the first 48
/// bytes in straight-line code (a vertex text or a `facet` line's rest is 39 to 55 bytes), then a
/// word at a time. A loop over all of them was vectorised with a setup longer than the loop (the
/// or of [`newline_or_byte_high`]: 794.8 M instructions against 781.7 M on the 101.6 MB torus of
/// `validation/threads.sh`), and unrolled four times over every length it took its trip counts'
/// arithmetic on every call (the hash of [`line_hash`]: 809.5 M against 794.8 M). With 32 bytes
/// in straight-line code, a text or rest of 40 bytes or more still paid that arithmetic for its
/// fifth and sixth words: the second torus of docs/benchmarks.md (minus signs, every facet's
/// normal) took 744.9 M instructions against 724.1 M with 48, the first torus 719.6 M against
/// 714.3 M.
#[inline(always)]
fn fold_words<T>(s: &[u8], init: T, f: impl Fn(T, u64) -> T) -> T {
    let mut acc = init;
    let mut rest = s;
    if let Some((first, after)) = s.split_first_chunk::<32>() {
        for c in first.chunks_exact(8) {
            let mut w = [0u8; 8];
            w.copy_from_slice(c);
            acc = f(acc, u64::from_le_bytes(w));
        }
        rest = after;
        // Two more words in straight-line code too: the loop below is unrolled.
        if let Some((w, after)) = rest.split_first_chunk::<8>() {
            acc = f(acc, u64::from_le_bytes(*w));
            rest = after;
            if let Some((w, after)) = rest.split_first_chunk::<8>() {
                acc = f(acc, u64::from_le_bytes(*w));
                rest = after;
            }
        }
    }
    while let Some((w, after)) = rest.split_first_chunk::<8>() {
        acc = f(acc, u64::from_le_bytes(*w));
        rest = after;
    }
    acc
}

/// The or of `flag` of the whole eight-byte words of `s` (its tail left out).
#[inline(always)]
fn whole_words(s: &[u8], flag: impl Fn(u64) -> u64) -> u64 {
    fold_words(s, 0, |flags, w| flags | flag(w))
}

/// Whether `key` holds no `\n` and is ASCII (then its bytes need no or into the UTF-8
/// accumulator; otherwise the caller's [`text_to_newline`] reads and ors them).
#[inline]
pub(super) fn plain_text(key: &[u8]) -> bool {
    let w = tail_word(key);
    // The zero bytes past the tail are not flagged, and a borrow runs past a flagged byte only.
    let flags = whole_words(key, newline_or_byte_high) | newline_or_byte_high(w);
    flags & HIGHS == 0
}

/// A hash of a line's bytes, eight at a time, every bit mixed into the top (the slot) and the
/// bottom (the tag).
pub(super) fn line_hash(b: &[u8]) -> u64 {
    // The whole words before the last byte (a text of three `%e` numbers is 39 to 42 bytes), then
    // the last eight bytes as they stand, over the last of those words or not: every byte is in a
    // word, and the length is folded in. The tail as a word of its own (shifted down, zeros above
    // it: a branch, a shift and a word more at a multiple of eight) took more: the second torus of
    // docs/benchmarks.md, one thread, 724.1 M instructions against 714.7 M so (the first torus
    // 714.3 M against 704.7 M).
    if let Some(&last) = b.last_chunk::<8>() {
        let h = fold_words(&b[..b.len() - 1], HASH_SEED, hash_word);
        return hash_finish(hash_word(h, u64::from_le_bytes(last)), b.len());
    }
    hash_finish(hash_word(HASH_SEED, tail_word(b)), b.len())
}

/// The last `b.len() % 8` bytes of `b` as a word, zeros above them: the last eight bytes loaded and
/// shifted down when there are eight (no copy of a length known only at run time).
#[inline(always)]
fn tail_word(b: &[u8]) -> u64 {
    let r = b.len() % 8;
    if r == 0 {
        return 0;
    }
    if let Some(&last) = b.last_chunk::<8>() {
        return u64::from_le_bytes(last) >> (8 * (8 - r));
    }
    let mut w = [0u8; 8];
    for (i, &c) in b.iter().enumerate().take(8) {
        w[i] = c;
    }
    u64::from_le_bytes(w)
}

const HASH_K: u64 = 0x9e37_79b9_7f4a_7c15;
const HASH_SEED: u64 = 0x2545_f491_4f6c_dd1d;

#[inline(always)]
fn hash_word(h: u64, w: u64) -> u64 {
    (h.rotate_left(23) ^ w).wrapping_mul(HASH_K)
}

/// The length folded in, one more product (whose top bits, the slot, depend on every bit), and its
/// top half folded onto the bottom (the tag). murmur3's finaliser (two products) took 8.6 M more
/// instructions on the 101.6 MB torus of `validation/threads.sh`.
#[inline(always)]
fn hash_finish(h: u64, len: usize) -> u64 {
    let h = (h ^ len as u64).wrapping_mul(0xff51_afd7_ed55_8ccd);
    h ^ (h >> 32)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A text read to its newline hashes as the same text hashed whole (the lookup of a text as
    /// long as the last one relies on it), at every length and alignment, and `plain_text` finds
    /// a newline or a byte that is not ASCII anywhere in it.
    #[test]
    fn text_hashes_agree() {
        for len in 0..64 {
            for skip in 0..9 {
                let key: Vec<u8> = (0..len).map(|i| b'0' + (i * 7 % 10) as u8).collect();
                let mut text = vec![b' '; skip];
                text.extend_from_slice(&key);
                text.extend_from_slice(b"\n        ");
                let mut bytes = 0;
                let read = text_to_newline(&text, skip, &mut bytes);
                assert_eq!(read, Some((skip + len, line_hash(&key))), "{len} {skip}");
                assert!(plain_text(&key), "{len}");
                for at in 0..len {
                    for b in [b'\n', 0x80, 0xc3, 0x8a, 0xff] {
                        let mut k = key.clone();
                        k[at] = b;
                        assert!(!plain_text(&k), "{len} {at} {b}");
                    }
                }
            }
        }
    }

    /// `newline_at` gives `newline`'s answer wherever it gives one, and gives it for every ASCII
    /// line of eight bytes or more at the length asked; it answers only for an ASCII line (every
    /// length, start, position of the `\n` and of a byte that is not ASCII).
    #[test]
    fn newline_at_is_newline() {
        for from in 0..3usize {
            for nl in from..68 {
                for high in [None, Some(from), Some(from + 5), Some(from + 9), Some(from + 37), Some(from + 45), Some(nl.saturating_sub(1))] {
                    for byte in [0xc3, 0x8a, 0xff] {
                        let mut text = vec![b'7'; 76];
                        text[nl] = b'\n';
                        if let Some(h) = high.filter(|&h| h != nl && h >= from) {
                            text[h] = byte;
                        }
                        let first = newline(&text, from, &mut 0);
                        for len in 0..72 {
                            let ascii = text[from..(from + len).min(76)].is_ascii();
                            match newline_at(&text, from, len) {
                                Some(end) => {
                                    assert_eq!(Some(end), first, "{from} {nl} {len}");
                                    assert!(ascii, "{from} {nl} {len}");
                                }
                                None => assert!(len < 8 || first != Some(from + len) || !ascii, "{from} {nl} {len}"),
                            }
                        }
                    }
                }
            }
        }
    }

    /// The three-`%e` reader gives what the general one does, to the bit, and leaves the rest
    /// to it.
    #[test]
    fn exponent_triple_is_any_coordinates() {
        let texts: [&[u8]; 10] = [
            b" 3.400000e-01 2.000000e-01 -2.000000e-01\n",
            b" -0.000000e+00 1.000000E+22 9.999999e-22\n",
            b" 3.400000e-01 2.000000e-01 2.000000e-01 \n",
            b" 3.400000e-01  2.000000e-01 2.000000e-01\n",
            b"\t3.400000e-01 2.000000e-01 2.000000e-01\n",
            b" 3.400000e-01 2.000000e-01 2.000000e-23\n",
            b" 3.400000e-01 2.000000e-01 2.5\n",
            b" 3.400000e-01 2.000000e-01 2.000000e-01",
            b" 8.572527e-17 1.000000e+00 1.000000e+0\n",
            b" 1.000000e+00 1.000000e+00 1.000000e+00\r\n",
        ];
        let padded = texts.map(|t| [t, &[b' '; 64][..]].concat());
        for t in texts.iter().copied().chain(padded.iter().map(|t| &t[..])) {
            let fast = exponent_triple(t, 0);
            let any = any_coordinates(t, 0);
            if let Some(p) = fast {
                assert_eq!(any.map(|q| q.map(f64::to_bits)), Some(p.map(f64::to_bits)), "{t:?}");
            }
            assert_eq!(coordinates(t, 0).map(|q| q.map(f64::to_bits)), any.map(|q| q.map(f64::to_bits)));
        }
        // Every %e shape of one value, signs and exponents included.
        for e in -25i32..=25 {
            for (m, s) in [(1234567, ""), (9000001, "-"), (0, "-")] {
                let n = format!("{s}{}.{:06}e{}{:02}", m / 1_000_000, m % 1_000_000, if e < 0 { '-' } else { '+' }, e.abs());
                let t = format!(" {n} {n} {n}\n{:64}", "");
                let fast = exponent_triple(t.as_bytes(), 0);
                let any = any_coordinates(t.as_bytes(), 0);
                assert_eq!(fast.is_some(), (-22..=22).contains(&(e - 6)), "{t}");
                if let Some(p) = fast {
                    assert_eq!(any.map(|q| q.map(f64::to_bits)), Some(p.map(f64::to_bits)), "{t}");
                }
            }
        }
    }

    /// The `%e` reader gives [`decimal`]'s value and length, and `str::parse`'s value, bit for bit,
    /// wherever it takes a word: C's `%e` of values of every sign over exponents beyond its range,
    /// followed by what may follow a word, and the same words with any one byte replaced by a
    /// digit, a letter, a sign, a point or a blank (it takes none that `decimal` would read
    /// otherwise).
    #[test]
    fn exponent_form_is_decimal() {
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut taken = 0;
        for k in 0..4000 {
            seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
            let m = (seed >> 11) as f64 / (1u64 << 53) as f64 * 10.0;
            let e = k % 61 - 30;
            let v = if k % 3 == 0 { -m } else { m } * 10f64.powi(e);
            let r = format!("{:.6e}", if k % 97 == 0 { 0.0 } else { v });
            let (mantissa, exp) = r.split_once('e').unwrap_or((&r, "0"));
            let exp: i32 = exp.parse().unwrap_or(0);
            let c = format!("{mantissa}{}{}{:02}", if k % 5 == 0 { 'E' } else { 'e' }, if exp < 0 { '-' } else { '+' }, exp.abs());
            for end in ["", " ", "\n", "\t", "\r", "x", "1", " 2"] {
                let w = format!("{c}{end}");
                taken += usize::from(agrees(w.as_bytes()));
                for at in 0..w.len() {
                    for b in *b"05e+-.Ex \n)/,:" {
                        let mut v = w.clone().into_bytes();
                        v[at] = b;
                        agrees(&v);
                    }
                }
            }
        }
        assert!(taken > 10_000, "{taken}");
    }

    /// Whether `exponent_form` takes `w` (checking that it then agrees with `decimal` and
    /// `str::parse`).
    fn agrees(w: &[u8]) -> bool {
        let Some((x, n)) = exponent_form(w, 0, false) else {
            return false;
        };
        let d = decimal(w);
        assert_eq!(Some((x.to_bits(), n)), d.map(|(x, n)| (x.to_bits(), n)), "{:?}", String::from_utf8_lossy(w));
        let parsed = std::str::from_utf8(&w[..n]).ok().and_then(|s| s.parse::<f64>().ok());
        assert_eq!(parsed.map(f64::to_bits), Some(x.to_bits()));
        true
    }

    /// The eight-at-a-time decimal reader gives `short_decimal`'s value and length, bit for bit, on
    /// every shape of number around its limits (digit runs of 0 to 9 before and after the point,
    /// exponents of 0 to 4 digits, signs, cases, what follows), and `str::parse`'s where it takes one.
    #[test]
    fn decimal_is_short_decimal() {
        let runs = ["", "0", "7", "10", "123", "9999", "12345", "999999", "1234567", "09876543", "123456789", "1234567890123"];
        let exps = ["", "e", "E+", "e-", "e0", "e+00", "e-01", "E07", "e-22", "e+22", "e23", "e-23", "e-307", "e0001", "e12345"];
        let mut n = 0;
        for sign in ["", "-", "+"] {
            for whole in runs {
                for (point, fraction) in [("", ""), (".", "")].into_iter().chain(runs.iter().map(|f| (".", *f))) {
                    for e in exps {
                        for end in ["", " ", "\n", "x", " 1"] {
                            let w = format!("{sign}{whole}{point}{fraction}{e}{end}");
                            let (a, b) = (decimal(w.as_bytes()), short_decimal(w.as_bytes()));
                            assert_eq!(a.map(|(x, n)| (x.to_bits(), n)), b.map(|(x, n)| (x.to_bits(), n)), "{w:?}");
                            if let Some((x, len)) = a {
                                assert_eq!(w[..len].parse::<f64>().map(f64::to_bits), Ok(x.to_bits()), "{w:?}");
                                n += 1;
                            }
                        }
                    }
                }
            }
        }
        assert!(n > 10_000, "{n}");
    }
}
