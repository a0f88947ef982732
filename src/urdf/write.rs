//! Writing `<inertial>` back: splice new text into the original bytes; everything else stays identical.

use super::scan::{Link, Robot};
use crate::mass::{matrix_rpy, MassProperties};

/// How numbers and frames are written.
#[derive(Debug, Clone, Copy, Default)]
pub struct WriteOptions {
    /// Significant digits; `None` writes the shortest text that reads back as the same f64.
    pub digits: Option<u32>,
    /// Write the principal frame (`rpy` of the principal axes, diagonal tensor).
    pub principal: bool,
}

/// Formats a number: shortest round-trip text, or `digits` significant digits.
pub fn number(x: f64, digits: Option<u32>) -> String {
    let x = if x == 0.0 { 0.0 } else { x }; // no "-0"
    match digits {
        None => crate::cli::shortest(x),
        Some(d) => {
            if x == 0.0 {
                return "0".into();
            }
            let s = format!("{:.*e}", (d.max(1) - 1) as usize, x);
            // Parse back and print shortest, so 1.50000e0 becomes 1.5.
            let y: f64 = s.parse().unwrap_or(x);
            crate::cli::shortest(y)
        }
    }
}

/// Rounds the tensor entries to `digits` significant digits, then nudges the diagonal minimally (relative
/// to the largest moment, in steps of the last written digit) until the rounded tensor is valid again.
pub fn rounded_tensor(i: &[[f64; 3]; 3], digits: u32) -> [[f64; 3]; 3] {
    let r = |x: f64| number(x, Some(digits)).parse::<f64>().unwrap_or(x);
    let mut out = i.map(|row| row.map(r));
    let largest = i.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    let step = largest * 10f64.powi(1 - digits as i32);
    for _ in 0..16 {
        let mp = MassProperties {
            mass: 1.0,
            com: [0.0; 3],
            inertia: out,
        };
        let bad = crate::mass::validity::check(&mp, 0.0);
        if bad.is_empty() {
            break;
        }
        // Raising every diagonal entry by one step restores positive definiteness and the triangle
        // inequality (I_a + step ≤ I_b + I_c + 2 step) while moving the tensor by one written digit.
        for k in 0..3 {
            out[k][k] = r(out[k][k] + step);
        }
    }
    out
}

/// The text of an `<inertial>` element for `mp` (in link coordinates), indented for its place.
pub fn inertial_text(
    mp: &MassProperties,
    opts: &WriteOptions,
    indent: &str,
    unit: &str,
    nl: &str,
) -> String {
    let n = |x: f64| number(x, opts.digits);
    let (rpy, tensor) = if opts.principal {
        let p = mp.principal();
        let d = [
            [p.moments[0], 0.0, 0.0],
            [0.0, p.moments[1], 0.0],
            [0.0, 0.0, p.moments[2]],
        ];
        (matrix_rpy(&p.axes), d)
    } else {
        ([0.0; 3], mp.inertia)
    };
    let tensor = match opts.digits {
        Some(d) => rounded_tensor(&tensor, d),
        None => tensor,
    };
    let inner = format!("{indent}{unit}");
    format!(
        "<inertial>{nl}{inner}<origin xyz=\"{} {} {}\" rpy=\"{} {} {}\"/>{nl}{inner}<mass value=\"{}\"/>{nl}{inner}<inertia ixx=\"{}\" ixy=\"{}\" ixz=\"{}\" iyy=\"{}\" iyz=\"{}\" izz=\"{}\"/>{nl}{indent}</inertial>",
        n(mp.com[0]),
        n(mp.com[1]),
        n(mp.com[2]),
        n(rpy[0]),
        n(rpy[1]),
        n(rpy[2]),
        n(mp.mass),
        n(tensor[0][0]),
        n(tensor[0][1]),
        n(tensor[0][2]),
        n(tensor[1][1]),
        n(tensor[1][2]),
        n(tensor[2][2]),
    )
}

/// The indentation unit of a link: the difference between its children's indent and its own, or two
/// spaces (a tab where the file indents with tabs).
fn indent_unit(link: &Link) -> String {
    match &link.child_indent {
        Some(c) if c.len() > link.indent.len() && c.starts_with(&link.indent) => {
            c[link.indent.len()..].to_string()
        }
        _ => {
            if link.indent.contains('\t') {
                "\t".into()
            } else {
                "  ".into()
            }
        }
    }
}

/// The span that removes the element `start..end`: its whole line(s) when nothing else is on them
/// (the indentation before it and the line break after it go too), else the element alone.
fn removal_span(text: &str, start: usize, end: usize) -> (usize, usize) {
    let line_start = text[..start].rfind('\n').map_or(0, |i| i + 1);
    let before = &text[line_start..start];
    let rest = &text[end..];
    let line_end = rest.find('\n').map_or(text.len(), |i| end + i + 1);
    let after = &text[end..line_end];
    let blank = |s: &str| {
        s.chars()
            .all(|c| c == ' ' || c == '\t' || c == '\r' || c == '\n')
    };
    if blank(before) && blank(after) {
        (line_start, line_end)
    } else {
        (start, end)
    }
}

/// The URDF text with the given links' `<inertial>` replaced or inserted; every other byte unchanged.
/// A link's further `<inertial>` elements (which urdfdom ignores) are removed, so exactly one remains.
pub fn splice(robot: &Robot, updates: &[(usize, MassProperties)], opts: &WriteOptions) -> String {
    let mut edits: Vec<(usize, usize, String)> = Vec::new();
    for (li, mp) in updates {
        let link = &robot.links[*li];
        let unit = indent_unit(link);
        let child_indent = link
            .child_indent
            .clone()
            .unwrap_or_else(|| format!("{}{unit}", link.indent));
        let text = inertial_text(mp, opts, &child_indent, &unit, robot.newline);
        match &link.inertial {
            Some(span) => {
                // Replace the element itself; its leading indentation stays where it is.
                let own_indent = robot.text[..span.start].rsplit('\n').next().unwrap_or("");
                let text = if own_indent.chars().all(|c| c == ' ' || c == '\t')
                    && own_indent != child_indent
                {
                    inertial_text(mp, opts, own_indent, &unit, robot.newline)
                } else {
                    text
                };
                edits.push((span.start, span.end, text));
                for extra in &link.extra_inertials {
                    let (start, end) = removal_span(&robot.text, extra.start, extra.end);
                    edits.push((start, end, String::new()));
                }
            }
            None => {
                // Insert as the link's first child, on its own line after the start tag.
                edits.push((
                    link.open_end,
                    link.open_end,
                    format!("{}{child_indent}{text}", robot.newline),
                ));
            }
        }
    }
    edits.sort_by_key(|e| e.0);
    let mut out = String::with_capacity(robot.text.len() + 256 * edits.len());
    let mut at = 0;
    for (start, end, text) in edits {
        // Edits never overlap (elements are disjoint); clamping keeps slicing safe regardless.
        let start = start.max(at);
        let end = end.max(start);
        out.push_str(&robot.text[at..start]);
        out.push_str(&text);
        at = end;
    }
    out.push_str(&robot.text[at..]);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn digits_and_nudging() {
        assert_eq!(number(0.123456789, Some(4)), "0.1235");
        assert_eq!(number(1.5e-9, None), "1.5e-9");
        assert_eq!(number(-0.0, None), "0");
        // Valid (1.0054 ≤ 1.0045 + 0.001), but 3 digits give 1.01 > 1.00 + 0.001.
        let t = [[1.0045, 0.0, 0.0], [0.0, 1.0054, 0.0], [0.0, 0.0, 0.001]];
        let plain = t.map(|r| r.map(|x| number(x, Some(3)).parse::<f64>().unwrap()));
        assert!(!crate::mass::validity::check(
            &MassProperties {
                mass: 1.0,
                com: [0.0; 3],
                inertia: plain
            },
            0.0
        )
        .is_empty());
        let r = rounded_tensor(&t, 3);
        let mp = MassProperties {
            mass: 1.0,
            com: [0.0; 3],
            inertia: r,
        };
        assert!(crate::mass::validity::check(&mp, 0.0).is_empty(), "{r:?}");
    }
}
