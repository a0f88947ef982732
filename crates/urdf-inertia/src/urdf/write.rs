//! Writing `<inertial>` back: splice new text into the original bytes; everything else stays identical.

use super::scan::{InertialSpan, Link, Robot};
use crate::geometry::ROUND_OFF_FLOOR;
use crate::mass::{matrix_rpy, validity, MassProperties};
use crate::text::{self, Digits};

/// How numbers and frames are written.
#[derive(Debug, Clone, Copy, Default)]
#[non_exhaustive]
pub struct WriteOptions {
    /// How many digits (default: the shortest decimal within each value's error estimate).
    pub digits: Digits,
    /// Write the principal frame (`rpy` of the principal axes, diagonal tensor).
    pub principal: bool,
}

/// One link's new `<inertial>`: the mass properties in link coordinates and how well they are known.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct LinkUpdate {
    /// Index into `Robot::links`.
    pub index: usize,
    pub props: MassProperties,
    /// Relative error bound of the values (volume and inertia), at least the round-off floor.
    pub error: f64,
    /// Relative precision of the input's coordinates (2⁻²⁴ for f32 mesh data, else 0): numbers are
    /// written within it as well as within `error`, so the input's own noise is not written.
    pub input_precision: f64,
    /// The link's size (m): the scale of its centre of mass.
    pub size: f64,
}

impl From<(usize, MassProperties)> for LinkUpdate {
    /// Values known to round-off, the centre of mass on the scale of its own coordinates.
    fn from((index, props): (usize, MassProperties)) -> Self {
        LinkUpdate {
            index,
            props,
            error: ROUND_OFF_FLOOR,
            input_precision: 0.0,
            size: 0.0,
        }
    }
}

/// A link whose `<inertial>` cannot be written as asked.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct WriteError {
    /// Index into `Robot::links`.
    pub index: usize,
    pub message: String,
}

/// Most nudges of the diagonal `--digits N` tries before it gives up.
const MAX_NUDGES: usize = 16;

/// The numbers of one `<inertial>`, ready to write.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Written {
    com: [f64; 3],
    rpy: [f64; 3],
    mass: f64,
    tensor: [[f64; 3]; 3],
}

/// Whether a written tensor is valid with no tolerance at all: positive definite and the triangle
/// inequality holding exactly, as `MuJoCo` and Drake require (`check` allows a round-off tolerance for
/// existing values; what we write must not need it).
fn tensor_valid(tensor: &[[f64; 3]; 3]) -> bool {
    let mp = MassProperties {
        mass: 1.0,
        com: [0.0; 3],
        inertia: *tensor,
    };
    validity::check(&mp, 0.0).is_empty()
}

fn largest_entry(tensor: &[[f64; 3]; 3]) -> f64 {
    tensor.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// Rounds the tensor entries to `digits` significant digits, then nudges the diagonal minimally (relative
/// to the largest moment, in steps of the last written digit) until the rounded tensor is valid again
/// (judged as `check` judges it); an error when [`MAX_NUDGES`] steps do not suffice.
pub fn rounded_tensor(i: &[[f64; 3]; 3], digits: u32) -> Result<[[f64; 3]; 3], String> {
    round_and_nudge(i, digits, MAX_NUDGES)
}

fn round_and_nudge(
    i: &[[f64; 3]; 3],
    digits: u32,
    max_nudges: usize,
) -> Result<[[f64; 3]; 3], String> {
    let r = |x: f64| text::round_significant(x, digits);
    let mut out = i.map(|row| row.map(r));
    let step = largest_entry(i) * 10f64.powi(1 - i32::try_from(digits).unwrap_or(17));
    for _ in 0..max_nudges {
        if tensor_valid(&out) {
            return Ok(out);
        }
        // Raising every diagonal entry by one step restores positive definiteness and the triangle
        // inequality (I_a + step ≤ I_b + I_c + 2 step) while moving the tensor by one written digit.
        for k in 0..3 {
            out[k][k] = r(out[k][k] + step);
        }
    }
    if tensor_valid(&out) {
        Ok(out)
    } else {
        Err(format!(
            "with {digits} significant digits the inertia tensor is not valid (not positive definite or breaking the triangle inequality) even after {max_nudges} nudges of its diagonal; write more digits (--digits 17 or --digits full)"
        ))
    }
}

/// The tensor written as the shortest decimals within `error` (relative to its largest entry); when that
/// breaks validity (a plate on the triangle boundary with a loose error estimate), with a tighter
/// tolerance, down to every bit.
fn tidy_tensor(tensor: &[[f64; 3]; 3], error: f64) -> [[f64; 3]; 3] {
    let scale = largest_entry(tensor);
    let mut rel = error;
    while rel >= f64::EPSILON / 4.0 {
        let out = tensor.map(|row| row.map(|x| text::within(x, rel * scale)));
        if tensor_valid(&out) {
            return out;
        }
        rel /= 10.0;
    }
    tensor.map(|row| row.map(|x| text::within(x, 0.0)))
}

/// Whether a link's one existing `<inertial>` already says what `fill` would write (`--digits
/// auto`, link axes): each number, as urdfdom reads it, within the tolerance [`written`] rounds the
/// computed value within (so it is as honest a decimal as the one `fill` would choose), the origin
/// unrotated, and the tensor valid. Its bytes then stay as they are: a second `fill`, or one after
/// an upgrade that moved only digits below the estimate, leaves the file as it was.
fn agrees(update: &LinkUpdate, span: &InertialSpan, opts: &WriteOptions) -> bool {
    let v = &span.value;
    let (Some(mass), Some(i)) = (v.mass, v.inertia) else {
        return false;
    };
    if opts.digits != Digits::Auto || opts.principal || span.problem.is_some() {
        return false;
    }
    let mp = &update.props;
    let (error, length) = tolerance(update);
    let scale = largest_entry(&mp.inertia);
    let tensor = [[i[0], i[1], i[2]], [i[1], i[3], i[4]], [i[2], i[4], i[5]]];
    let near = |a: f64, b: f64, delta: f64| (a - b).abs() <= delta;
    v.origin.rpy == [0.0; 3]
        && near(mass, mp.mass, error * mp.mass)
        && (0..3).all(|k| near(v.origin.xyz[k], mp.com[k], error * length))
        && (0..3).all(|r| (0..3).all(|c| near(tensor[r][c], mp.inertia[r][c], error * scale)))
        && tensor_valid(&tensor)
}

/// The relative tolerance `update`'s numbers are written within, and the length its centre of mass
/// is known relative to: the link's size or its own coordinates, whichever is larger.
fn tolerance(update: &LinkUpdate) -> (f64, f64) {
    let error = text::rounding_tolerance(update.error.max(update.input_precision));
    let length = update.props.com.iter().fold(update.size, |m, x| m.max(x.abs()));
    (error, length)
}

/// The values to write for `update`, rounded as `opts` says.
fn written(update: &LinkUpdate, opts: &WriteOptions) -> Result<Written, String> {
    let mp = &update.props;
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
    let (error, length) = tolerance(update);
    let floor = |x: f64, scale: f64| text::within(x, ROUND_OFF_FLOOR * scale);
    Ok(match opts.digits {
        Digits::Full => Written {
            com: mp.com.map(|x| text::within(x, 0.0)),
            rpy: rpy.map(|x| text::within(x, 0.0)),
            mass: mp.mass,
            tensor,
        },
        Digits::Auto => Written {
            com: mp.com.map(|x| text::within(x, error * length)),
            rpy: rpy.map(|x| text::within(x, error * std::f64::consts::PI)),
            mass: text::within(mp.mass, error * mp.mass),
            tensor: tidy_tensor(&tensor, error),
        },
        Digits::Fixed(d) => {
            let scale = largest_entry(&tensor);
            let cleaned = tensor.map(|row| row.map(|x| floor(x, scale)));
            Written {
                com: mp.com.map(|x| text::round_significant(floor(x, length), d)),
                rpy: rpy.map(|x| text::round_significant(floor(x, 1.0), d)),
                mass: text::round_significant(mp.mass, d),
                tensor: rounded_tensor(&cleaned, d)?,
            }
        }
    })
}

/// The mass properties as written (in link axes), for reports: rounded as `digits` says, or every bit
/// when `--digits N` cannot keep the tensor valid.
pub fn tidy(update: &LinkUpdate, digits: Digits) -> MassProperties {
    let opts = WriteOptions {
        digits,
        principal: false,
    };
    let w = written(update, &opts).or_else(|_| {
        written(
            update,
            &WriteOptions {
                digits: Digits::Full,
                principal: false,
            },
        )
    });
    match w {
        Ok(w) => MassProperties {
            mass: w.mass,
            com: w.com,
            inertia: w.tensor,
        },
        Err(_) => update.props,
    }
}

/// Principal moments as reports write them: within `error` of the largest, `-0` as `0`.
pub fn tidy_moments(moments: [f64; 3], error: f64, digits: Digits) -> [f64; 3] {
    let largest = moments.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    match digits {
        Digits::Full => moments.map(|x| text::within(x, 0.0)),
        Digits::Auto => moments.map(|x| text::within(x, text::rounding_tolerance(error) * largest)),
        Digits::Fixed(d) => moments.map(|x| text::round_significant(x, d)),
    }
}

/// How the file writes its `<inertial>` elements, followed by the ones written: the end of an empty
/// element (`/>` or ` />`), the order of `<origin>`'s and `<inertia>`'s attributes.
#[derive(Debug, Clone, PartialEq)]
pub struct InertialStyle {
    close: &'static str,
    rpy_first: bool,
    /// Indices into ixx, ixy, ixz, iyy, iyz, izz, in the file's order.
    order: [usize; 6],
}

impl Default for InertialStyle {
    fn default() -> Self {
        InertialStyle {
            close: "/>",
            rpy_first: false,
            order: [0, 1, 2, 3, 4, 5],
        }
    }
}

const INERTIA_KEYS: [&str; 6] = ["ixx", "ixy", "ixz", "iyy", "iyz", "izz"];

impl InertialStyle {
    /// The style of the robot's first existing `<inertial>` (each part read where it is written;
    /// the default where the file has none).
    pub fn of(robot: &Robot) -> Self {
        let mut style = InertialStyle::default();
        let Some(span) = robot.links.iter().find_map(|l| l.inertial.as_ref()) else {
            return style;
        };
        let body = robot.text.get(span.start..span.end).unwrap_or("");
        // The position of attribute `key` in `tag`, as a whole name followed by `=`.
        let attr = |tag: &str, key: &str| {
            tag.match_indices(key).map(|(i, _)| i).find(|&i| {
                tag[..i].ends_with(char::is_whitespace)
                    && tag[i + key.len()..].trim_start().starts_with('=')
            })
        };
        let tag = |name: &str| {
            let start = body.find(&format!("<{name}"))?;
            let rest = &body[start..];
            Some(&rest[..=rest.find('>')?])
        };
        if let Some(t) = tag("inertia ") {
            if let Some(before) = t.strip_suffix("/>") {
                style.close = if before.ends_with(char::is_whitespace) {
                    " />"
                } else {
                    "/>"
                };
            }
            let at: Vec<Option<usize>> = INERTIA_KEYS.iter().map(|k| attr(t, k)).collect();
            if at.iter().all(Option::is_some) {
                let mut order = [0, 1, 2, 3, 4, 5];
                order.sort_by_key(|&k| at[k]);
                style.order = order;
            }
        }
        if let Some(t) = tag("origin ") {
            if let (Some(x), Some(r)) = (attr(t, "xyz"), attr(t, "rpy")) {
                style.rpy_first = r < x;
            }
        }
        style
    }
}

/// The text of an `<inertial>` element for `update`, indented for its place, in `style`.
pub fn inertial_text(
    update: &LinkUpdate,
    opts: &WriteOptions,
    indent: &str,
    unit: &str,
    nl: &str,
    style: &InertialStyle,
) -> Result<String, String> {
    let w = written(update, opts)?;
    let n = |x: f64| text::shortest(x);
    let t = &w.tensor;
    let inner = format!("{indent}{unit}");
    let xyz = format!("xyz=\"{} {} {}\"", n(w.com[0]), n(w.com[1]), n(w.com[2]));
    let rpy = format!("rpy=\"{} {} {}\"", n(w.rpy[0]), n(w.rpy[1]), n(w.rpy[2]));
    let origin = if style.rpy_first {
        format!("{rpy} {xyz}")
    } else {
        format!("{xyz} {rpy}")
    };
    let values = [t[0][0], t[0][1], t[0][2], t[1][1], t[1][2], t[2][2]];
    let inertia: Vec<String> = style
        .order
        .iter()
        .map(|&k| format!("{}=\"{}\"", INERTIA_KEYS[k], n(values[k])))
        .collect();
    let close = style.close;
    Ok(format!(
        "<inertial>{nl}{inner}<origin {origin}{close}{nl}{inner}<mass value=\"{}\"{close}{nl}{inner}<inertia {}{close}{nl}{indent}</inertial>",
        n(w.mass),
        inertia.join(" "),
    ))
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
///
/// An error lists every link whose values cannot be written as asked (`--digits N` too few to keep
/// the tensor valid).
pub fn splice(
    robot: &Robot,
    updates: &[LinkUpdate],
    opts: &WriteOptions,
) -> Result<String, Vec<WriteError>> {
    let mut edits: Vec<(usize, usize, String)> = Vec::new();
    let mut errors = Vec::new();
    let style = InertialStyle::of(robot);
    for update in updates {
        match link_edits(robot, update, opts, &style) {
            Ok(e) => edits.extend(e),
            Err(message) => errors.push(WriteError {
                index: update.index,
                message,
            }),
        }
    }
    if !errors.is_empty() {
        return Err(errors);
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
    Ok(out)
}

/// The edits (byte range, new text) that give one link its new `<inertial>`.
fn link_edits(
    robot: &Robot,
    update: &LinkUpdate,
    opts: &WriteOptions,
    style: &InertialStyle,
) -> Result<Vec<(usize, usize, String)>, String> {
    let link = &robot.links[update.index];
    let unit = indent_unit(link);
    let child_indent = link
        .child_indent
        .clone()
        .unwrap_or_else(|| format!("{}{unit}", link.indent));
    let Some(span) = &link.inertial else {
        // Insert as the link's first child, on its own line after the start tag.
        let text = inertial_text(update, opts, &child_indent, &unit, robot.newline, style)?;
        return Ok(vec![(
            link.open_end,
            link.open_end,
            format!("{}{child_indent}{text}", robot.newline),
        )]);
    };
    if link.extra_inertials.is_empty() && agrees(update, span, opts) {
        return Ok(Vec::new());
    }
    // Replace the element itself; its leading indentation stays where it is.
    let own_indent = robot.text[..span.start].rsplit('\n').next().unwrap_or("");
    let indent = if own_indent.chars().all(|c| c == ' ' || c == '\t') {
        own_indent
    } else {
        &child_indent
    };
    let text = inertial_text(update, opts, indent, &unit, robot.newline, style)?;
    let mut edits = vec![(span.start, span.end, text)];
    for extra in &link.extra_inertials {
        let (start, end) = removal_span(&robot.text, extra.start, extra.end);
        edits.push((start, end, String::new()));
    }
    Ok(edits)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn valid(t: &[[f64; 3]; 3]) -> bool {
        tensor_valid(t)
    }

    #[test]
    fn digits_and_nudging() {
        // Valid (1.0054 ≤ 1.0045 + 0.001), but 3 digits give 1.01 > 1.00 + 0.001.
        let t = [[1.0045, 0.0, 0.0], [0.0, 1.0054, 0.0], [0.0, 0.0, 0.001]];
        let plain = t.map(|r| r.map(|x| text::round_significant(x, 3)));
        assert!(!valid(&plain));
        let r = rounded_tensor(&t, 3).expect("nudged");
        assert!(valid(&r), "{r:?}");
    }

    #[test]
    fn too_few_digits_is_an_error_not_an_invalid_tensor() {
        // The tensor of `digits_and_nudging`, allowed no nudge: reported, never written invalid.
        let t = [[1.0045, 0.0, 0.0], [0.0, 1.0054, 0.0], [0.0, 0.0, 0.001]];
        let e = round_and_nudge(&t, 3, 0).expect_err("invalid after rounding");
        assert!(e.contains("--digits"), "{e}");
        assert!(round_and_nudge(&t, 3, 1).is_ok());
    }

    #[test]
    fn auto_digits_keep_plates_valid() {
        // A thin plate: Izz exceeds Ixx + Iyy by nothing but the thickness term (1e-10 relative),
        // a loose error estimate (1e-3) must not round it across the boundary.
        let (a, b, c) = (1.0f64, 1.0f64, 1e-5f64);
        let t = [
            [(b * b + c * c) / 12.0, 0.0, 0.0],
            [0.0, (a * a + c * c) / 12.0, 0.0],
            [0.0, 0.0, (a * a + b * b) / 12.0],
        ];
        let r = tidy_tensor(&t, 1e-3);
        assert!(valid(&r), "{r:?}");
    }

    #[test]
    fn a_new_inertial_follows_the_files_style() {
        let text = "<robot name=\"r\">\n  <link name=\"a\">\n    <inertial>\n      <origin rpy=\"0 0 0\" xyz=\"0 0 0\" />\n      <mass value=\"1\" />\n      <inertia ixx=\"1\" iyy=\"1\" izz=\"1\" ixy=\"0\" ixz=\"0\" iyz=\"0\" />\n    </inertial>\n  </link>\n  <link name=\"b\">\n    <collision><geometry><box size=\"1 1 1\"/></geometry></collision>\n  </link>\n</robot>\n";
        let robot = crate::urdf::scan(text.to_string(), std::path::Path::new("r.urdf")).unwrap();
        let style = InertialStyle::of(&robot);
        assert_eq!(
            style,
            InertialStyle {
                close: " />",
                rpy_first: true,
                order: [0, 3, 5, 1, 2, 4],
            }
        );
        let mp = MassProperties {
            mass: 2.0,
            com: [0.5, 0.0, 0.0],
            inertia: [[3.0, 0.0, 0.0], [0.0, 4.0, 0.0], [0.0, 0.0, 5.0]],
        };
        let out = splice(
            &robot,
            &[LinkUpdate::from((1, mp))],
            &WriteOptions::default(),
        )
        .unwrap();
        assert!(
            out.contains("<origin rpy=\"0 0 0\" xyz=\"0.5 0 0\" />\n      <mass value=\"2\" />\n      <inertia ixx=\"3\" iyy=\"4\" izz=\"5\" ixy=\"0\" ixz=\"0\" iyz=\"0\" />"),
            "{out}"
        );
        // A file without inertials gets the usual order and `/>`.
        let bare = crate::urdf::scan(
            text.replace("<inertial>", "<!--")
                .replace("</inertial>", "-->"),
            std::path::Path::new("r.urdf"),
        )
        .unwrap();
        assert_eq!(InertialStyle::of(&bare), InertialStyle::default());
    }
}
