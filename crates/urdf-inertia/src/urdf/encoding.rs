//! The text a URDF file holds: UTF-8 (with or without a byte-order mark), UTF-16 (with a byte-order
//! mark, or sniffed from `<?xml` as XML 1.0 appendix F describes), or an ASCII-compatible encoding named
//! by the XML declaration (`encoding="ISO-8859-1"`, `windows-1252`, …, decoded with `encoding_rs`).
//!
//! The scan works on the decoded UTF-8 text. Writing back re-encodes the spliced text in the file's own
//! encoding ([`SourceEncoding::encode`]); only files whose decoding is lossless (it re-encodes to the very
//! same bytes, checked when reading) are written, so every byte outside the spliced `<inertial>` stays
//! as it was.

use encoding_rs::Encoding;

/// The encoding a URDF was read in, to write it back the same way.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SourceEncoding {
    /// UTF-8; a byte-order mark, if any, stays in the text.
    #[default]
    Utf8,
    /// UTF-16, little- or big-endian, and whether the file starts with a byte-order mark.
    Utf16 { big_endian: bool, bom: bool },
    /// An ASCII-compatible encoding named by the XML declaration; `lossless` when decoding and encoding
    /// again gives the file's own bytes.
    Declared {
        encoding: &'static Encoding,
        lossless: bool,
    },
}

impl SourceEncoding {
    /// The name to show in messages.
    pub fn name(&self) -> &'static str {
        match self {
            SourceEncoding::Utf8 => "UTF-8",
            SourceEncoding::Utf16 {
                big_endian: false, ..
            } => "UTF-16LE",
            SourceEncoding::Utf16 {
                big_endian: true, ..
            } => "UTF-16BE",
            SourceEncoding::Declared { encoding, .. } => encoding.name(),
        }
    }

    /// The bytes of `text` in this encoding, or why the file cannot be written back in it.
    pub fn encode(&self, text: &str) -> Result<Vec<u8>, String> {
        match *self {
            SourceEncoding::Utf8 => Ok(text.as_bytes().to_vec()),
            SourceEncoding::Utf16 { big_endian, bom } => {
                let mut out = Vec::with_capacity(2 * text.len() + 2);
                let units = bom
                    .then_some(0xfeff_u16)
                    .into_iter()
                    .chain(text.encode_utf16());
                for u in units {
                    out.extend_from_slice(&if big_endian {
                        u.to_be_bytes()
                    } else {
                        u.to_le_bytes()
                    });
                }
                Ok(out)
            }
            SourceEncoding::Declared { encoding, lossless } => {
                if !lossless {
                    return Err(format!(
                        "the file's {} text does not read back byte for byte, so it is not written (convert it to UTF-8, e.g. `iconv -f {} -t UTF-8`, and fix its XML declaration)",
                        encoding.name(),
                        encoding.name()
                    ));
                }
                let (bytes, _, unmappable) = encoding.encode(text);
                if unmappable {
                    return Err(format!(
                        "the new text cannot be written in {}",
                        encoding.name()
                    ));
                }
                Ok(bytes.into_owned())
            }
        }
    }
}

/// Why a URDF's bytes are not text: where (the first bad byte) and what to do.
#[derive(Debug, Clone, PartialEq)]
pub struct DecodeError {
    /// Offset of the first bad byte in the file.
    pub offset: usize,
    /// Line and column (1-based, in bytes) of that offset.
    pub line: usize,
    pub column: usize,
    pub message: String,
}

impl DecodeError {
    fn at(bytes: &[u8], offset: usize, message: String) -> Self {
        let before = &bytes[..offset.min(bytes.len())];
        let line_start = before
            .iter()
            .rposition(|&b| b == b'\n')
            .map_or(0, |i| i + 1);
        DecodeError {
            offset,
            line: 1 + crate::text::count_newlines(before),
            column: 1 + before.len() - line_start,
            message,
        }
    }
}

/// The `encoding` attribute of an XML declaration at the very start of ASCII-compatible bytes.
fn declared_encoding(bytes: &[u8]) -> Option<&[u8]> {
    let head = bytes.strip_prefix(b"\xef\xbb\xbf").unwrap_or(bytes);
    if !head.starts_with(b"<?xml") {
        return None;
    }
    let end = head.windows(2).take(512).position(|w| w == b"?>")?;
    let decl = &head[..end];
    let at = decl.windows(8).position(|w| w == b"encoding")?;
    let rest = &decl[at + 8..];
    let rest = &rest[rest.iter().position(|b| !b.is_ascii_whitespace())?..];
    let rest = rest.strip_prefix(b"=")?;
    let rest = &rest[rest.iter().position(|b| !b.is_ascii_whitespace())?..];
    let quote = *rest.first()?;
    if quote != b'"' && quote != b'\'' {
        return None;
    }
    let value = &rest[1..];
    Some(&value[..value.iter().position(|&b| b == quote)?])
}

/// Decodes a URDF file's bytes to UTF-8 text.
pub fn decode(bytes: Vec<u8>) -> Result<(String, SourceEncoding), DecodeError> {
    if let Some(form) = utf32_form(&bytes) {
        return Err(DecodeError::at(
            &bytes,
            0,
            format!("the file is UTF-32 ({form}), which urdf-inertia does not read; save it as UTF-8 (e.g. `iconv -f UTF-32 -t UTF-8`)"),
        ));
    }
    if let Some((big_endian, bom)) = utf16_form(&bytes) {
        return decode_utf16(&bytes, big_endian, bom);
    }
    match declared_encoder(&bytes)? {
        None => decode_utf8(bytes),
        Some(encoding) => decode_declared(&bytes, encoding),
    }
}

/// The UTF-32 form of the bytes, if they are UTF-32: a byte-order mark, or a markup start or
/// whitespace as one 32-bit unit (XML 1.0 appendix F). Checked before UTF-16: `FF FE 00 00` is the
/// UTF-32LE mark.
fn utf32_form(bytes: &[u8]) -> Option<&'static str> {
    let markup = |b: u8| b == b'<' || b.is_ascii_whitespace();
    match bytes.get(..4)? {
        [0, 0, 0xfe, 0xff] => Some("big-endian, with a byte-order mark"),
        [0xff, 0xfe, 0, 0] => Some("little-endian, with a byte-order mark"),
        &[0, 0, 0, b] if markup(b) => Some("big-endian"),
        &[b, 0, 0, 0] if markup(b) => Some("little-endian"),
        _ => None,
    }
}

/// `(big_endian, bom)` if the bytes are UTF-16: a byte-order mark, or markup (`<`, whitespace)
/// followed by another ASCII character as 16-bit units (XML 1.0 appendix F; a file without an XML
/// declaration starts `<robot`).
fn utf16_form(bytes: &[u8]) -> Option<(bool, bool)> {
    let markup = |b: u8| b == b'<' || b.is_ascii_whitespace();
    match bytes.get(..4) {
        Some([0xff, 0xfe, ..]) => Some((false, true)),
        Some([0xfe, 0xff, ..]) => Some((true, true)),
        Some(&[a, 0, b, 0]) if markup(a) && b != 0 && b.is_ascii() => Some((false, false)),
        Some(&[0, a, 0, b]) if markup(a) && b != 0 && b.is_ascii() => Some((true, false)),
        _ => None,
    }
}

/// Decodes UTF-16 bytes (after the byte-order mark if `bom`); errors point at the bad unit.
fn decode_utf16(
    bytes: &[u8],
    big_endian: bool,
    bom: bool,
) -> Result<(String, SourceEncoding), DecodeError> {
    let body = &bytes[if bom { 2 } else { 0 }..];
    if body.len() % 2 != 0 {
        return Err(DecodeError::at(
            bytes,
            bytes.len() - 1,
            "the UTF-16 file has an odd number of bytes (truncated?)".into(),
        ));
    }
    let units = body.chunks_exact(2).map(|c| {
        if big_endian {
            u16::from_be_bytes([c[0], c[1]])
        } else {
            u16::from_le_bytes([c[0], c[1]])
        }
    });
    let mut text = String::with_capacity(body.len() / 2);
    for (k, c) in char::decode_utf16(units).enumerate() {
        match c {
            Ok(c) => text.push(c),
            Err(_) => {
                return Err(DecodeError::at(
                    bytes,
                    if bom { 2 } else { 0 } + 2 * k,
                    "not valid UTF-16 (an unpaired surrogate)".into(),
                ))
            }
        }
    }
    Ok((text, SourceEncoding::Utf16 { big_endian, bom }))
}

/// The encoding the XML declaration names, if it is not UTF-8 (nor a stale UTF-16 label); an
/// unknown name is an error.
fn declared_encoder(bytes: &[u8]) -> Result<Option<&'static Encoding>, DecodeError> {
    let Some(l) = declared_encoding(bytes) else {
        return Ok(None);
    };
    match Encoding::for_label(l) {
        // A UTF-16 label on bytes that are not UTF-16 is a stale declaration: read them as UTF-8.
        Some(e) if e == encoding_rs::UTF_8 || e == encoding_rs::UTF_16LE || e == encoding_rs::UTF_16BE => Ok(None),
        Some(e) => Ok(Some(e)),
        None => Err(DecodeError::at(
            bytes,
            0,
            format!(
                "the XML declaration names the encoding `{}`, which urdf-inertia does not know; convert the file to UTF-8",
                String::from_utf8_lossy(l)
            ),
        )),
    }
}

/// UTF-8 bytes as they are; an error suggests declaring Latin-1.
fn decode_utf8(bytes: Vec<u8>) -> Result<(String, SourceEncoding), DecodeError> {
    String::from_utf8(bytes)
        .map(|t| (t, SourceEncoding::Utf8))
        .map_err(|e| {
            let offset = e.utf8_error().valid_up_to();
            DecodeError::at(
                e.as_bytes(),
                offset,
                format!("not valid UTF-8 (byte 0x{:02x}), and the XML declaration names no other encoding; if the file is Latin-1, declare it (<?xml version=\"1.0\" encoding=\"ISO-8859-1\"?>) or convert it to UTF-8", e.as_bytes().get(offset).copied().unwrap_or(0)),
            )
        })
}

/// Bytes in a declared legacy encoding; notes whether writing the text back gives the same bytes.
fn decode_declared(
    bytes: &[u8],
    encoding: &'static Encoding,
) -> Result<(String, SourceEncoding), DecodeError> {
    let (text, malformed) = encoding.decode_without_bom_handling(bytes);
    if malformed {
        return Err(DecodeError::at(
            bytes,
            0,
            format!(
                "not valid {} text, although the XML declaration says so",
                encoding.name()
            ),
        ));
    }
    let text = text.into_owned();
    let (again, _, unmappable) = encoding.encode(&text);
    let lossless = !unmappable && again.as_ref() == bytes;
    Ok((text, SourceEncoding::Declared { encoding, lossless }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn latin1_and_utf16_decode_and_encode_back_to_the_same_bytes() {
        let latin1 =
            b"<?xml version=\"1.0\" encoding=\"ISO-8859-1\"?>\n<robot name=\"r\xe9\"/>\n".to_vec();
        let (text, enc) = decode(latin1.clone()).expect("latin-1");
        assert!(text.contains("name=\"r\u{e9}\""), "{text}");
        assert_eq!(enc.encode(&text).expect("encode"), latin1);

        let utf16: Vec<u8> = [0xfeff_u16]
            .into_iter()
            .chain(
                "<?xml version=\"1.0\" encoding=\"UTF-16\"?><robot name=\"\u{e9}\"/>"
                    .encode_utf16(),
            )
            .flat_map(u16::to_le_bytes)
            .collect();
        let (text, enc) = decode(utf16.clone()).expect("utf-16");
        assert!(
            text.starts_with("<?xml") && text.contains('\u{e9}'),
            "{text}"
        );
        assert_eq!(
            enc,
            SourceEncoding::Utf16 {
                big_endian: false,
                bom: true
            }
        );
        assert_eq!(enc.encode(&text).expect("encode"), utf16);
    }

    #[test]
    fn undeclared_latin1_names_the_byte_and_the_fix() {
        let e = decode(b"<robot name=\"r\xe9\"/>".to_vec()).unwrap_err();
        assert_eq!((e.offset, e.line, e.column), (14, 1, 15));
        assert!(e.message.contains("ISO-8859-1"), "{}", e.message);
        let e = decode(b"<?xml version='1.0' encoding='klingon'?><robot/>".to_vec()).unwrap_err();
        assert!(e.message.contains("`klingon`"), "{}", e.message);
    }

    #[test]
    fn truncated_and_odd_inputs_never_panic() {
        let utf16: Vec<u8> = [0xfeff_u16]
            .into_iter()
            .chain("<?xml version='1.0'?><robot name='\u{e9}\u{1F916}'/>".encode_utf16())
            .flat_map(u16::to_be_bytes)
            .collect();
        let latin1 = b"<?xml version='1.0' encoding='latin1'?><robot name='\xe9'/>".to_vec();
        for bytes in [utf16, latin1] {
            for n in 0..=bytes.len() {
                if let Ok((text, enc)) = decode(bytes[..n].to_vec()) {
                    let _ = enc.encode(&text);
                }
                let _ = declared_encoding(&bytes[..n]);
            }
        }
        // A lone surrogate is an error naming its offset, not a panic or a replacement.
        let e = decode(vec![0xff, 0xfe, b'<', 0, 0x00, 0xd8, b'>', 0]).unwrap_err();
        assert_eq!(e.offset, 4);
    }
}
