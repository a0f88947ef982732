//! The streaming readers against the whole-text reference reader they replaced.

use super::ascii::Ascii;
use super::*;
use crate::mass::Polygons;
use crate::mesh::parse_f64;
use crate::mesh::weld::VertexTable;

/// The ASCII reader as it was before it streamed, kept to check the streaming one against it.
/// Parses ASCII STL; errors carry the line.
fn ascii_reference(bytes: &[u8], path: &Path) -> Result<RawMesh, MeshError> {
    let text = std::str::from_utf8(bytes).map_err(|e| {
        MeshError::new(
            path,
            None,
            MeshErrorKind::Syntax(format!(
                "ASCII STL is not valid UTF-8 at byte {}",
                e.valid_up_to()
            )),
        )
    })?;
    let mut vertices = VertexTable::with_capacity(bytes.len() / 512 + 16);
    let mut faces = Polygons::new();
    let mut current: Vec<u32> = Vec::new();
    let mut in_loop = false;
    for (lineno, line) in text.lines().enumerate() {
        let lineno = lineno + 1;
        let mut words = line.split_ascii_whitespace();
        let Some(word) = words.next() else { continue };
        match Keyword::of(word.as_bytes()) {
            Keyword::Vertex => {
                if !in_loop {
                    return Err(MeshError::new(
                        path,
                        Some(lineno),
                        MeshErrorKind::Syntax("`vertex` outside `outer loop`".into()),
                    ));
                }
                let p = ascii_vertex(words, lineno, path)?;
                current.push(vertices.insert(p));
            }
            Keyword::Outer => {
                in_loop = true;
                current.clear();
            }
            Keyword::EndLoop => {
                in_loop = false;
                if current.len() < 3 {
                    return Err(MeshError::new(
                        path,
                        Some(lineno),
                        MeshErrorKind::Syntax(format!("a facet with {} vertices", current.len())),
                    ));
                }
                faces.push(&current);
            }
            Keyword::Ignored => {}
            Keyword::Other => {
                return Err(MeshError::new(
                    path,
                    Some(lineno),
                    MeshErrorKind::Syntax(format!("unexpected `{word}` in ASCII STL")),
                ));
            }
        }
    }
    if in_loop {
        return Err(MeshError::new(
            path,
            Some(text.lines().count()),
            MeshErrorKind::Truncated("ASCII STL ends inside a facet".into()),
        ));
    }
    Ok(RawMesh {
        vertices: vertices.into_vertices(),
        faces,
        notes: Vec::new(),
        warnings: Vec::new(),
        welded: true,
    })
}

/// The three coordinates after an ASCII STL `vertex` (for [`ascii_reference`]).
fn ascii_vertex<'a>(
    mut words: impl Iterator<Item = &'a str>,
    lineno: usize,
    path: &Path,
) -> Result<[f64; 3], MeshError> {
    let mut p = [0.0; 3];
    for c in &mut p {
        let w = words.next().ok_or_else(|| {
            MeshError::new(
                path,
                Some(lineno),
                MeshErrorKind::Syntax("`vertex` needs three coordinates".into()),
            )
        })?;
        *c = parse_f64(w).ok_or_else(|| {
            MeshError::new(
                path,
                Some(lineno),
                MeshErrorKind::Syntax(format!("`{w}` is not a number")),
            )
        })?;
        if !c.is_finite() {
            return Err(MeshError::new(path, Some(lineno), MeshErrorKind::NotFinite));
        }
        // −0.0 folds into 0.0, so that both weld (`RawMesh::welded`).
        *c += 0.0;
    }
    Ok(p)
}

/// A closed mesh of quads and triangles on a sphere-like grid, with coordinates of every sign
/// (−0.0 included) and magnitudes from 1e-7 to 1e5.
fn mesh() -> (Vec<[f64; 3]>, Vec<Vec<u32>>) {
    let (n, m) = (9u32, 7u32);
    let mut v = vec![[0.0, 0.0, 1.0], [-0.0, 0.0, -1.0]];
    for j in 1..m {
        for i in 0..n {
            let (a, b) = (
                std::f64::consts::TAU * f64::from(i) / f64::from(n),
                std::f64::consts::PI * f64::from(j) / f64::from(m),
            );
            let r = [1e-7, 1.0, 3.5, 1e5][(i % 4) as usize];
            v.push([r * b.sin() * a.cos(), r * b.sin() * a.sin(), b.cos()]);
        }
    }
    let at = |i: u32, j: u32| 2 + (j - 1) * n + i % n;
    let mut f = Vec::new();
    for i in 0..n {
        f.push(vec![0, at(i, 1), at(i + 1, 1)]);
        f.push(vec![1, at(i + 1, m - 1), at(i, m - 1)]);
        for j in 1..m - 1 {
            if (i + j) % 3 == 0 {
                f.push(vec![at(i, j), at(i, j + 1), at(i + 1, j + 1), at(i + 1, j)]);
            } else {
                f.push(vec![at(i, j), at(i, j + 1), at(i + 1, j + 1)]);
                f.push(vec![at(i, j), at(i + 1, j + 1), at(i + 1, j)]);
            }
        }
    }
    (v, f)
}

/// How a writer spells things: the number format, and the whitespace around lines and words.
struct Style {
    number: fn(f64) -> String,
    indent: &'static str,
    gap: &'static str,
    eol: &'static str,
    solid: &'static str,
    end: &'static str,
}

fn write(style: &Style, v: &[[f64; 3]], f: &[Vec<u32>]) -> Vec<u8> {
    let Style {
        indent: ind,
        gap: g,
        eol,
        ..
    } = style;
    let mut s = format!("{}{eol}", style.solid);
    for face in f {
        let _ = write!(
            s,
            "{ind}facet{g}normal{g}0{g}0{g}1{eol}{ind}{ind}outer{g}loop{eol}"
        );
        for &i in face {
            let p = v[i as usize].map(style.number);
            let _ = write!(
                s,
                "{ind}{ind}{ind}vertex{g}{}{g}{}{g}{}{eol}",
                p[0], p[1], p[2]
            );
        }
        let _ = write!(s, "{ind}{ind}endloop{eol}{ind}endfacet{eol}");
    }
    s += style.end;
    s.into_bytes()
}

fn styles() -> Vec<Style> {
    vec![
        Style {
            number: |x| format!("{x}"),
            indent: "  ",
            gap: " ",
            eol: "\n",
            solid: "solid fixture",
            end: "endsolid fixture\n",
        },
        Style {
            number: |x| format!("{x:.6e}"),
            indent: "\t",
            gap: "  ",
            eol: "\r\n",
            solid: "solid Part 1 (exported) ÄÖ",
            end: "endsolid\r\n",
        },
        Style {
            // C's %E: an uppercase exponent with a sign and two digits.
            number: |x| {
                let t = format!("{x:.8E}");
                let (m, e) = t.split_once('E').unwrap_or((&t, "0"));
                let e: i32 = e.parse().unwrap_or(0);
                format!("{m}E{}{:02}", if e < 0 { '-' } else { '+' }, e.abs())
            },
            indent: "",
            gap: " \t ",
            eol: " \n\n",
            solid: "  \n solid",
            end: "endsolid  name with spaces",
        },
        Style {
            number: |x| format!("{x:+.17}"),
            indent: "    ",
            gap: "\x0c ",
            eol: "\r\n \r\n",
            solid: "solid",
            end: "",
        },
    ]
}

pub(super) fn same(a: &Result<RawMesh, MeshError>, b: &Result<RawMesh, MeshError>, what: &str) {
    match (a, b) {
        (Ok(a), Ok(b)) => {
            let bits = |m: &RawMesh| -> Vec<[u64; 3]> {
                m.vertices.iter().map(|p| p.map(f64::to_bits)).collect()
            };
            assert_eq!(bits(a), bits(b), "{what}: vertices");
            assert_eq!(a.faces.indices, b.faces.indices, "{what}: corners");
            assert_eq!(a.faces.starts, b.faces.starts, "{what}: faces");
            assert_eq!(
                (&a.notes, &a.warnings, a.welded),
                (&b.notes, &b.warnings, b.welded),
                "{what}"
            );
        }
        (Err(a), Err(b)) => assert_eq!(format!("{a:?}"), format!("{b:?}"), "{what}"),
        (a, b) => panic!(
            "{what}: {:?} against {:?}",
            a.as_ref().err(),
            b.as_ref().err()
        ),
    }
}

/// A pool of one thread, where the streamed reader reads its pieces in turn into one buffer.
fn one_thread() -> &'static rayon::ThreadPool {
    static POOL: std::sync::OnceLock<rayon::ThreadPool> = std::sync::OnceLock::new();
    POOL.get_or_init(|| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .expect("a pool of one thread")
    })
}

/// Every way in: in memory (one chunk, and tiny chunks), streamed in tiny pieces and chunks (lines
/// longer than a piece, chunk borders everywhere), and through `read_split` as a file is read.
fn check(bytes: &[u8], what: &str) {
    let path = Path::new("t.stl");
    let reference = ascii_reference(bytes, path);
    same(&reference, &ascii(bytes, path), what);
    for (piece, chunk) in [(7, 1), (64, 40), (300, 100), (1 << 20, 1000)] {
        let mut tiny = Ascii::new(path, chunk);
        tiny.feed(bytes);
        same(
            &reference,
            &tiny.finish(),
            &format!("{what}, chunks of {chunk}"),
        );
        let mut tiny = Ascii::new(path, chunk);
        one_thread().install(|| tiny.feed(bytes));
        same(
            &reference,
            &tiny.finish(),
            &format!("{what}, one thread, chunks of {chunk}"),
        );
        let head = bytes[..bytes.len().min(5)].to_vec();
        let rest = &bytes[bytes.len().min(5)..];
        let streamed = ascii_stream(head.clone(), rest, bytes.len() as u64, path, piece, chunk);
        same(
            &reference,
            &streamed,
            &format!("{what}, pieces of {piece}, chunks of {chunk}"),
        );
        let streamed = one_thread().install(|| ascii_stream(head, rest, bytes.len() as u64, path, piece, chunk));
        same(
            &reference,
            &streamed,
            &format!("{what}, one thread, pieces of {piece}, chunks of {chunk}"),
        );
    }
    if looks_ascii(bytes) && is_text(&bytes[..bytes.len().min(4096)]) {
        let read = read_split(bytes, bytes.len() as u64, path, CHUNK, None);
        same(&reference, &read, &format!("{what}, read"));
    }
}

/// The streaming reader gives the whole-text reader's vertices and faces bit for bit, on files
/// written in several styles (exponents, CRLF, tabs and form feeds, blank lines, `solid` names,
/// no final newline, quads), and on text spanning many chunks.
#[test]
fn streamed_ascii_is_the_whole_text_parse() {
    let (v, f) = mesh();
    for (k, style) in styles().iter().enumerate() {
        let bytes = write(style, &v, &f);
        check(&bytes, &format!("style {k}"));
        assert!(ascii(&bytes, Path::new("t")).is_ok_and(|m| m.faces.len() == f.len()));
    }
    // Large enough for several default chunks, written as a common exporter writes.
    let mut big_v = Vec::new();
    let mut big_f = Vec::new();
    for copy in 0..400u32 {
        let base = big_v.len() as u32;
        big_v.extend(v.iter().map(|p| [p[0] + f64::from(copy % 3), p[1], p[2]]));
        big_f.extend(f.iter().map(|face| face.iter().map(|i| i + base).collect()));
    }
    let bytes = write(&styles()[1], &big_v, &big_f);
    assert!(bytes.len() > 3 * ASCII_CHUNK, "{}", bytes.len());
    check(&bytes, "big");
    let m = ascii(&bytes, Path::new("t")).expect("parses");
    // Copies 0 and 3 coincide: their corners weld across chunks.
    assert_eq!(m.vertices.len(), 3 * v.len());
}

/// Files the reader accepts although they are odd, and files it refuses: the same faces, or the
/// same error (line, message), as the whole-text reader, however the text is cut.
#[test]
fn streamed_ascii_errors_and_oddities_are_the_whole_text_parse() {
    let facet = "facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n";
    let cases: Vec<(String, &str)> = vec![
            (format!("solid a\n{facet}{facet}endsolid a\n"), "two facets"),
            (String::new() + "solid", "no facets"),
            ("solid x\n".to_string(), "no facets, newline"),
            (
                format!("solid a\nfacet\nouter loop\nvertex 0 0 0\nfacet normal 1 2 3\nvertex 1 0 0\nvertex 0 1 0\nendloop\n{facet}"),
                "`facet` inside a loop",
            ),
            (format!("solid a\n{facet}endloop\nendloop\n{facet}"), "endloop repeated"),
            (format!("solid a\n{facet}vertex 1 2 3 4 extra\n"), "vertex outside a loop"),
            (format!("solid a\n{facet}outer\nvertex 1 2\n"), "two coordinates"),
            (format!("solid a\n{facet}outer\nvertex 1 2 x3\n"), "not a number"),
            (format!("solid a\n{facet}outer\nvertex 1 2 1e999\n"), "not finite"),
            (format!("solid a\n{facet}outer\nvertex 1 2 3\nendloop\n"), "two vertices"),
            (format!("solid a\n{facet}bogus line\n{facet}"), "unexpected word"),
            (format!("solid a\n{facet}outer loop\nvertex 1 2 3\n"), "ends in a facet"),
            (format!("solid a\n{facet}outer loop\nvertex 1 2 3"), "ends in a facet, no newline"),
            (
                format!("solid a\n{facet}outer loop\nvertex .5 5. -0 +1e+2\nvertex 0x1 0 0\n"),
                "odd numbers",
            ),
            (
                format!("solid a\n{facet}outer\nvertex 1 1 1\nvertex 0 1 1\nvertex 1 0 1\nvertex 0.5 0.5 0.5\nendloop\n"),
                "a polygon",
            ),
        ];
    for (text, what) in &cases {
        check(text.as_bytes(), what);
    }
    // Not UTF-8: that error wins over a syntax error before it, as the whole text was checked first.
    let mut bad = format!("solid a\n{facet}bogus\n{facet}").into_bytes();
    bad.extend_from_slice(b"vertex \xff\n");
    check(&bad, "syntax error, then not UTF-8");
    let mut bad = format!("solid a\n{facet}").into_bytes();
    bad.extend_from_slice(b"outer loop\nvertex 1 \xc3\n");
    bad.extend_from_slice(facet.repeat(40).as_bytes());
    check(&bad, "not UTF-8");
}

/// The per-line fast path of the chunk parser against the whole-text reader, on what it must take
/// exactly as the general path does or hand back to it: keywords in any case and followed by any
/// blank, `facet normal` lines whose numbers are never read (garbage included: accepted, as the
/// whole-text reader has always accepted them), coordinates in every decimal form (exponents,
/// signs, a point first or last, runs of digits longer than eight), words that only begin like a
/// keyword, and bytes that are not ASCII inside lines the fast path skips.
#[test]
fn streamed_ascii_fast_path_is_the_whole_text_parse() {
    let corners = [
        "0 0 0",
        "1e0 0 0",
        "0 1E+00 0",
        "0 0 .1e1",
        "1. 1 1",
        "+1.5e-3 -0.0 -0",
        "12345678.5 0.12345678901 1",
        "123456789012345678901 1 1",
        "-1.000000e+00 2.500000E-01 3.125000e+001",
        "1.2999373516471264 0.012762515138294503 0",
        "8.572527e-17 -1e-300 4.9e-324",
        "1e23 -1.5E+40 0.1e-22",
    ];
    let mut facets = String::new();
    for (k, c) in corners.iter().enumerate() {
        let (a, b) = (corners[(k + 1) % corners.len()], corners[(k + 2) % corners.len()]);
        let _ = write!(
            facets,
            "facet normal 0 0 1\nouter loop\nvertex {c}\nvertex {a}\nvertex {b}\nendloop\nendfacet\n"
        );
    }
    let plain = format!("solid s\n{facets}endsolid s\n");
    let shouted = plain
        .replace("facet", "FACET")
        .replace("normal", "NORMAL")
        .replace("outer loop", "Outer Loop")
        .replace("vertex", "VeRtEx")
        .replace("endloop", "ENDLOOP")
        .replace("solid", "SOLID");
    let blanks = plain
        .replace("vertex ", "vertex\t")
        .replace("endloop\n", "endloop\r\n")
        .replace("outer ", "outer\x0c")
        .replace("\nfacet", "\n \t\r facet");
    let garbage = plain.replace("normal 0 0 1", "normal nan x ∞ 1e999 junk");
    let non_ascii = plain.replace("endfacet\n", "endfacet ünïcödé\n");
    for (text, what) in [
        (&plain, "plain"),
        (&shouted, "upper and mixed case"),
        (&blanks, "tabs, CR, form feeds"),
        (&garbage, "facet normal garbage"),
        (&non_ascii, "non-ASCII after a keyword"),
    ] {
        check(text.as_bytes(), what);
    }
    let parse = |t: &str| ascii(t.as_bytes(), Path::new("t"));
    let reference = parse(&plain).expect("parses");
    for text in [&shouted, &blanks, &garbage, &non_ascii] {
        same(&Ok(reference.clone()), &parse(text), "the same mesh as plain");
    }
    // Words that only begin like a keyword are errors, on their line.
    for (from, to, line) in [
        ("vertex 0 0 0", "vertexx 0 0 0", 4),
        ("endloop\n", "endloops\n", 7),
        ("facet normal", "facets normal", 2),
        ("solid s\n", "solid2 s\n", 1),
    ] {
        let text = plain.replacen(from, to, 1);
        check(text.as_bytes(), to);
        let e = parse(&text).expect_err(to);
        assert_eq!(e.line, Some(line), "{to}: {e}");
    }
    // A byte that is not UTF-8 in a line the fast path does not read to the end.
    let mut bad = plain.clone().into_bytes();
    let at = plain.find("normal 0 0 1").expect("a facet") + 10;
    bad[at] = 0xff;
    check(&bad, "not UTF-8 in a facet normal");
    let e = ascii(&bad, Path::new("t")).expect_err("not UTF-8");
    assert!(e.to_string().contains(&format!("not valid UTF-8 at byte {at}")), "{e}");
}

/// An exporter's facet `k` with the given `outer`, `vertex` (up to its coordinates), `endloop` and
/// `endfacet` lines, and `corners` corners.
fn fixed_facet(k: usize, lines: [&str; 4], corners: usize) -> String {
    let [outer, vertex, endloop, endfacet] = lines;
    let mut s = format!("  facet normal 0 0 1\n{outer}");
    for c in 0..corners {
        let _ = writeln!(s, "{vertex}{}.5 {} {}", k + c, c * 2, k % 7);
    }
    s + endloop + endfacet
}

/// The lines of [`fixed_facet`] as exporters write them.
const EXPORTER: [&str; 4] = ["    outer loop\n", "      vertex ", "    endloop\n", "  endfacet\n"];

/// Thirty facets of [`EXPORTER`] lines.
fn exporter_facets() -> String {
    (0..30).map(|k| fixed_facet(k, EXPORTER, 3)).collect()
}

/// The lines after a `facet` line and after a facet's last corner, compared whole with the last
/// `outer`, `endloop` and `endfacet` lines taken, and `vertex` lines recognised by the start of
/// the last one: the same faces or errors (and lines) as the whole-text reader when they repeat
/// byte for byte, when they differ in blanks, case or what follows the keyword, when they are
/// longer than the 16 bytes compared, when a facet has too few corners for its `endloop`, when a
/// line after a corner is an error, and at the end of the text without a newline.
#[test]
fn streamed_ascii_fixed_lines_are_the_whole_text_parse() {
    let [o, _, l, f] = EXPORTER;
    let plain = exporter_facets();
    let mut cases: Vec<(String, String)> = vec![(format!("solid t\n{plain}endsolid t\n"), "plain".into())];
    let mut odd = String::from("solid t\n");
    for k in 0..40 {
        let (oo, ll, ff) = match k % 8 {
            1 => ("   outer loop\n", "   endloop\n", " endfacet\n"),
            2 => ("    OUTER LOOP\n", "    EndLoop\n", "  endFacet\n"),
            3 => ("    outer loop\r\n", "    endloop\r\n", "  endfacet\r\n"),
            4 => ("        outer loop\n", "        endloop\n", "          endfacet\n"),
            5 => ("    outer loops\n", "\tendloop x\n", "\tendfacet\t\n"),
            6 => ("    outer loop é\n", "    endloop é\n", "  endfacet ü\n"),
            _ => (o, l, f),
        };
        let vv = match k % 6 {
            1 => "     vertex  ",
            2 => "      VERTEX ",
            3 => "\t\tvertex\t",
            4 => "vertex ",
            5 => "              vertex ",
            _ => "      vertex ",
        };
        let one = fixed_facet(k, [oo, vv, ll, ff], 3 + usize::from(k % 5 == 4));
        odd += &match k % 7 {
            3 => one.replace("  facet normal", "\tFacet\tnormal"),
            5 => one.replace("  facet normal", "facet normal"),
            _ => one,
        };
        odd += &fixed_facet(k + 50, [oo, vv, ll, ff], 3);
    }
    cases.push((odd + "endsolid t\n", "blanks, case, long lines, non-ASCII".into()));
    for (n, what) in [(2, "two corners"), (1, "one corner"), (0, "no corners")] {
        let text = format!("solid t\n{plain}{}{plain}", fixed_facet(99, EXPORTER, n));
        cases.push((text, what.into()));
    }
    for (line, bad) in [
        (o, "    outerx loop\n"),
        (l, "    endloops\n"),
        (f, "  endfacets\n"),
        ("  facet normal", "  facets normal"),
    ] {
        // The second one, after one taken.
        let mut text = format!("solid t\n{plain}");
        let at = text.match_indices(line).nth(1).map_or(0, |(i, _)| i);
        text.replace_range(at..at + line.len(), bad);
        cases.push((text + &plain, bad.into()));
    }
    for bad in ["vertex 1 2\n", "vertexx 1 2 3\n", "vertex\n", "vertex 1 2 3 4\n"] {
        let open = fixed_facet(7, [o, EXPORTER[1], "", ""], 2);
        cases.push((format!("solid t\n{plain}{open}      {bad}{l}{f}{plain}"), bad.into()));
    }
    // Vertex texts as long as the one before: seen, not seen, holding a newline or bytes that are
    // not ASCII, or ending in one.
    for corners in [
        "1 2 3\n      vertex 1 2 3\n      vertex 4 5 6\n",
        "1 2 3\n      vertex 4 5 6\n      vertex 1 2 3\n",
        "1 2 3\n      vertex 1\n2 3\n      vertex 4 5 6\n",
        "1 2 3\n      vertex 1 2\n3\n      vertex 4 5 6\n",
        "1 2 3\n      vertex 1 é 3\n      vertex 4 5 6\n",
        "1 2 3\n      vertex 1 2 3 é\n      vertex 1 2 3 é\n      vertex 4 5 6\n",
        "1 2 3\n      vertex 1 2 3\r\n      vertex 4 5 6\n",
        "1 2 3\n      vertex 1 2 3 \n      vertex 1 2\t3\n",
        "1 2 3 4 5 6\n      vertex 1 2 3\n     \n      vertex 4 5 6\n      bogus\n",
    ] {
        let facet = format!("  facet normal 0 0 1\n{o}      vertex {corners}{l}{f}");
        cases.push((format!("solid t\n{plain}{facet}{facet}{plain}"), corners.into()));
    }
    let cut = format!("solid t\n{plain}");
    for end in [1, 2, 3, 5, 12, 13] {
        cases.push((cut[..cut.len() - end].to_string(), format!("cut {end} bytes before the end")));
    }
    let outer = format!("solid t\n{plain}  facet normal 0 0 1\n    outer loop");
    cases.push((outer, "outer without a newline".into()));
    for (text, what) in &cases {
        check(text.as_bytes(), what);
    }
}

/// Bytes that are not ASCII before the newline of a line scanned eight or sixteen bytes at a time
/// (at every offset in the word), and bytes that are not UTF-8 repeated in a line compared whole:
/// the whole-text reader's faces or error.
#[test]
fn streamed_ascii_fast_lines_not_ascii_are_the_whole_text_parse() {
    let plain = exporter_facets();
    for pad in 0..20 {
        let blanks = " ".repeat(pad);
        let normal = plain.replacen("normal 0 0 1\n", &format!("normal 0 0 1{blanks}é\n"), 3);
        let corner = normal.replacen(" 0\n", &format!(" 0{blanks} ü\n"), 2);
        check(format!("solid t\n{corner}endsolid t\n").as_bytes(), &format!("not ASCII after {pad} blanks"));
    }
    let mut bad = b"solid t\n".to_vec();
    for k in 0..20 {
        let [o, v, _, f] = EXPORTER;
        let t = fixed_facet(k, [o, v, "    endloop \u{1}\n", f], 3);
        bad.extend(t.bytes().map(|b| if b == 1 { 0xff } else { b }));
    }
    check(&bad, "not UTF-8 in repeated endloop lines");
    let e = ascii(&bad, Path::new("t")).expect_err("not UTF-8");
    assert!(e.to_string().contains("not valid UTF-8"), "{e}");
}

/// A source that gives `bytes` and then fails, as a file on a failing disk or a network share
/// that drops does.
struct FailingAfter<'a> {
    bytes: &'a [u8],
}

impl std::io::Read for FailingAfter<'_> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        if self.bytes.is_empty() {
            return Err(std::io::Error::other("the disk went away"));
        }
        let n = buf.len().min(self.bytes.len());
        buf[..n].copy_from_slice(&self.bytes[..n]);
        self.bytes = &self.bytes[n..];
        Ok(n)
    }
}

/// The next piece is read while the one before is parsed: a read that fails is still reported as
/// the read error (not as the text cut short), and text that is not UTF-8 before it still wins, as
/// when the pieces were read one after the other.
#[test]
fn streamed_ascii_read_error_while_parsing() {
    let facet = "facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n";
    let text = format!("solid a\n{}", facet.repeat(50));
    let path = Path::new("t.stl");
    for (piece, chunk, threads) in [(300, 100, 0), (1000, 200, 0), (300, 100, 1), (1000, 200, 1)] {
        let stream = |head: &[u8], source| {
            let len = text.len() as u64;
            let read = || ascii_stream(head.to_vec(), source, len, path, piece, chunk);
            if threads == 1 { one_thread().install(read) } else { read() }
        };
        let read = stream(&text.as_bytes()[..5], FailingAfter { bytes: &text.as_bytes()[5..] });
        let err = read.expect_err("the read fails");
        assert!(matches!(err.kind, MeshErrorKind::Io(_)), "{err:?}");
        let mut bad = text.clone().into_bytes();
        bad[40] = 0xff;
        let read = stream(&bad[..5], FailingAfter { bytes: &bad[5..] });
        let err = read.expect_err("not UTF-8");
        assert!(
            format!("{err}").contains("not valid UTF-8 at byte 40"),
            "{err}"
        );
    }
}
