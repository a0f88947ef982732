//! The density map: which density (or mass) each part and link gets.
//!
//! ```toml
//! default = 1000.0                  # kg/m³ for parts nothing else matches (optional)
//! total_mass = 12.5                 # optional: scale densities so the filled links sum to this mass
//! [materials]                       # optional names, added to the built-in table
//! my_alloy = 2810.0
//! [links]                           # link name or glob
//! base_link = "aluminum"            # a material name
//! "*_finger*" = { mass = 0.05 }     # the link's total mass; its parts share one density
//! "wrist_*" = { density = 1200.0 }
//! [meshes]                          # mesh file name or glob, per part
//! "*battery*" = { density = 2500.0 }
//! ```
//!
//! The most specific rule wins: for a part, a `[meshes]` entry matching its mesh file (by file name, or
//! by the whole URI when the pattern has a `/`); else the link's rule: an exact `[links]` name, then the
//! longest matching glob (ties: the one written first), then `default`. A value is a density (number or
//! `{ density = … }`), a material (`"steel"` or `{ material = "steel" }`) or, for links and meshes, a
//! mass (`{ mass = … }`: the link's total, or the part's own).

use serde::Deserialize;
use std::collections::BTreeMap;
use std::fmt;
use std::fmt::Write as _;
use std::ops::Range;
use std::path::{Path, PathBuf};
use toml::Spanned;

mod glob;
mod unused;

use glob::parse_glob;
pub use glob::{Glob, Rule, RuleSet};
#[cfg(any(test, feature = "internals"))]
pub use glob::MAX_GLOB_LEN;
pub use unused::near_miss;
#[cfg(any(test, feature = "internals"))]
pub use unused::UnusedRule;

/// Built-in materials, kg/m³ (typical values; put your own in `[materials]`).
pub const MATERIALS: &[(&str, f64)] = &[
    ("aluminum", 2700.0),
    ("aluminium", 2700.0),
    ("steel", 7850.0),
    ("stainless_steel", 8000.0),
    ("titanium", 4430.0),
    ("copper", 8960.0),
    ("brass", 8500.0),
    ("magnesium", 1740.0),
    ("carbon_fiber", 1600.0),
    ("pla", 1240.0),
    ("abs", 1040.0),
    ("petg", 1270.0),
    ("nylon", 1150.0),
    ("polycarbonate", 1200.0),
    ("acrylic", 1180.0),
    ("pom", 1410.0),
    ("delrin", 1410.0),
    ("rubber", 1100.0),
    ("silicone", 1100.0),
    ("wood", 700.0),
    ("water", 1000.0),
];

/// What a rule gives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Spec {
    /// kg/m³.
    Density(f64),
    /// kg: a link's total mass (links) or a part's own mass (meshes).
    Mass(f64),
}

/// A density map error, with the line of the TOML it concerns.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct MapError {
    pub path: PathBuf,
    pub line: Option<usize>,
    /// 1-based column (characters) of a TOML syntax error.
    pub column: Option<usize>,
    pub message: String,
    /// The offending line with a caret under the column, and a hint, as compilers show them (TOML
    /// syntax errors).
    pub snippet: Option<String>,
}

impl fmt::Display for MapError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.path.display())?;
        if let Some(l) = self.line {
            write!(f, ":{l}")?;
            if let Some(c) = self.column {
                write!(f, ":{c}")?;
            }
        }
        write!(f, ": {}", self.message)?;
        if let Some(s) = &self.snippet {
            write!(f, "\n{s}")?;
        }
        Ok(())
    }
}

/// A TOML syntax error at byte `at` of `text`: its line, column, the line with a caret, and a hint
/// for the likeliest slip, an unquoted glob key (`*_link = …` must be `"*_link" = …`).
fn syntax_error(text: &str, at: usize, path: &Path, message: &str) -> MapError {
    let at = at.min(text.len());
    let start = text[..at].rfind('\n').map_or(0, |i| i + 1);
    let end = text[start..].find('\n').map_or(text.len(), |i| start + i);
    let line_text = text[start..end].trim_end_matches('\r');
    let line = text[..start].matches('\n').count() + 1;
    let column = text[start..at].chars().count() + 1;
    let shown = crate::text::escape_control(line_text);
    let gutter = " ".repeat(line.to_string().len());
    let mut snippet = format!(
        "{gutter} |\n{line} | {shown}\n{gutter} | {}^",
        " ".repeat(column - 1)
    );
    let key = line_text.split('=').next().unwrap_or("").trim();
    let quoted = key.starts_with('"') || key.starts_with('\'');
    if line_text.contains('=') && !quoted && key.contains(['*', '?', '[', ']', '{', '}', '!']) {
        let _ = write!(
            snippet,
            "\n{gutter} = hint: a key with glob characters must be quoted: \"{}\" = …",
            crate::text::escape_control(key)
        );
    }
    MapError {
        path: path.into(),
        line: Some(line),
        column: Some(column),
        message: message.trim_end().to_string(),
        snippet: Some(snippet),
    }
}

impl std::error::Error for MapError {}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMap {
    default: Option<Spanned<toml::Value>>,
    total_mass: Option<Spanned<f64>>,
    #[serde(default)]
    materials: BTreeMap<String, Spanned<toml::Value>>,
    /// Entries with their spans: the span gives each rule's line and its place in the file, however it
    /// was written (`[links] "a" = …` or dotted `links."a" = …`).
    #[serde(default)]
    links: BTreeMap<String, Spanned<toml::Value>>,
    #[serde(default)]
    meshes: BTreeMap<String, Spanned<toml::Value>>,
}

/// A validated density map.
#[derive(Debug, Clone, Default, PartialEq)]
#[non_exhaustive]
pub struct DensityMap {
    pub default: Option<f64>,
    pub total_mass: Option<f64>,
    /// The `[links]` rules, matched against link names.
    pub links: RuleSet,
    /// The `[meshes]` rules, matched against a part's mesh URI (patterns with a `/`) or file name.
    pub meshes: RuleSet,
}

impl DensityMap {
    /// One density for everything (`--density`).
    pub fn uniform(density: f64) -> Self {
        DensityMap {
            default: Some(density),
            ..Default::default()
        }
    }

    /// Reads and validates a density map file no larger than `max_file_size` bytes.
    pub fn load(path: &Path, max_file_size: u64) -> Result<Self, MapError> {
        let cannot = |e: String| MapError {
            path: path.into(),
            line: None,
            column: None,
            message: format!("cannot read the density map: {e}"),
            snippet: None,
        };
        let bytes =
            crate::input::read_file(path, max_file_size).map_err(|e| cannot(e.to_string()))?;
        let text = String::from_utf8(bytes)
            .map_err(|e| cannot(format!("not UTF-8 (byte {})", e.utf8_error().valid_up_to())))?;
        Self::parse(&text, path)
    }

    /// Parses and validates density map text.
    pub fn parse(text: &str, path: &Path) -> Result<Self, MapError> {
        // Line starts, once: each lookup is a binary search (a map with thousands of rules stays linear).
        let line_starts: Vec<usize> = std::iter::once(0)
            .chain(text.match_indices('\n').map(|(i, _)| i + 1))
            .collect();
        let line_of = |span: Range<usize>| {
            Some(line_starts.partition_point(|&s| s <= span.start.min(text.len())))
        };
        let err = |span: Option<Range<usize>>, message: String| MapError {
            path: path.into(),
            line: span.and_then(line_of),
            column: None,
            message,
            snippet: None,
        };
        let raw: RawMap = toml::from_str(text).map_err(|e| match e.span() {
            Some(span) => syntax_error(text, span.start, path, e.message()),
            None => err(None, e.message().to_string()),
        })?;

        let materials = material_table(&raw.materials).map_err(|(span, m)| err(Some(span), m))?;
        let default = match &raw.default {
            None => None,
            Some(v) => match spec(&materials, v.get_ref(), false, "default")
                .map_err(|m| err(Some(v.span()), m))?
            {
                Spec::Density(d) => Some(d),
                Spec::Mass(_) => None,
            },
        };
        if let Some(t) = &raw.total_mass {
            check_positive(*t.get_ref(), "total_mass").map_err(|m| err(Some(t.span()), m))?;
        }
        let line = |span: Range<usize>| line_of(span).unwrap_or(0);
        let links = rules(&materials, "links", &raw.links, &err, &line)?;
        let meshes = rules(&materials, "meshes", &raw.meshes, &err, &line)?;
        Ok(DensityMap {
            default,
            total_mass: raw.total_mass.map(|t| *t.get_ref()),
            links,
            meshes,
        })
    }

    /// The rule for a link: exact name, then the longest matching glob, then `None` (the default applies).
    pub fn link_rule(&self, link: &str) -> Option<(&str, Spec)> {
        self.links.best(link, link)
    }

    /// The rule for a part's mesh, if any: `uri` is the URDF's filename attribute. A pattern with a `/`
    /// is matched against the whole URI, any other against the file name.
    pub fn mesh_rule(&self, uri: &str) -> Option<(&str, Spec)> {
        let file = uri.rsplit('/').next().unwrap_or(uri);
        self.meshes.best(uri, file)
    }
}

/// The built-in materials with the map's `[materials]` added (names compare case-insensitively). An
/// error carries the span of the entry it concerns.
fn material_table(
    table: &BTreeMap<String, Spanned<toml::Value>>,
) -> Result<BTreeMap<String, f64>, (Range<usize>, String)> {
    let mut materials: BTreeMap<String, f64> =
        MATERIALS.iter().map(|(k, v)| (k.to_string(), *v)).collect();
    for (name, v) in table {
        let d = v
            .get_ref()
            .as_float()
            .or_else(|| v.get_ref().as_integer().map(|i| i as f64))
            .ok_or_else(|| {
                (
                    v.span(),
                    format!("material `{name}` must be a density in kg/m³"),
                )
            })?;
        check_positive(d, &format!("material `{name}`")).map_err(|m| (v.span(), m))?;
        materials.insert(name.to_ascii_lowercase(), d);
    }
    Ok(materials)
}

/// A material by name, as a density; an unknown name lists the built-in ones.
fn material(materials: &BTreeMap<String, f64>, name: &str, what: &str) -> Result<Spec, String> {
    materials
        .get(&name.to_ascii_lowercase())
        .map(|d| Spec::Density(*d))
        .ok_or_else(|| {
            format!(
                "{what}: unknown material `{name}`; add it under [materials] (built in: {})",
                MATERIALS.iter().map(|m| m.0).collect::<Vec<_>>().join(", ")
            )
        })
}

/// One rule's value: a density, a material name or a one-key table (`mass` only where `allow_mass`).
/// `what` names the rule in messages.
fn spec(
    materials: &BTreeMap<String, f64>,
    v: &toml::Value,
    allow_mass: bool,
    what: &str,
) -> Result<Spec, String> {
    match v {
        toml::Value::Float(d) => check_positive(*d, what).map(|()| Spec::Density(*d)),
        toml::Value::Integer(i) => {
            check_positive(*i as f64, what).map(|()| Spec::Density(*i as f64))
        }
        toml::Value::String(s) => material(materials, s, what),
        toml::Value::Table(t) => table_spec(materials, t, allow_mass, what),
        _ => Err(format!(
            "{what}: expected a density, a material name or a table"
        )),
    }
}

/// A rule written as a table: exactly one of `density`, `mass` (where allowed) or `material`.
fn table_spec(
    materials: &BTreeMap<String, f64>,
    t: &toml::Table,
    allow_mass: bool,
    what: &str,
) -> Result<Spec, String> {
    if t.len() != 1 {
        return Err(format!(
            "{what}: give exactly one of density, mass or material"
        ));
    }
    let (k, val) = t
        .iter()
        .next()
        .ok_or_else(|| format!("{what}: empty table"))?;
    let num = || {
        val.as_float()
            .or_else(|| val.as_integer().map(|i| i as f64))
            .ok_or_else(|| format!("{what}: `{k}` must be a number"))
    };
    match k.as_str() {
        "density" => {
            let d = num()?;
            check_positive(d, what).map(|()| Spec::Density(d))
        }
        "mass" if allow_mass => {
            let m = num()?;
            check_positive(m, what).map(|()| Spec::Mass(m))
        }
        "material" => material(
            materials,
            val.as_str()
                .ok_or_else(|| format!("{what}: material must be a name"))?,
            what,
        ),
        other => Err(format!(
            "{what}: unknown key `{other}` (expected density, mass or material)"
        )),
    }
}

/// The rules of `[section]` in file order (for tie-breaking), compiled once; each error on its entry's
/// line.
fn rules(
    materials: &BTreeMap<String, f64>,
    section: &str,
    table: &BTreeMap<String, Spanned<toml::Value>>,
    err: &impl Fn(Option<Range<usize>>, String) -> MapError,
    line: &impl Fn(Range<usize>) -> usize,
) -> Result<RuleSet, MapError> {
    let mut entries: Vec<(&String, &Spanned<toml::Value>)> = table.iter().collect();
    entries.sort_by_key(|(_, v)| v.span().start);
    let rules = entries
        .into_iter()
        .map(|(k, v)| {
            parse_glob(k).map_err(|m| err(Some(v.span()), format!("[{section}] {m}")))?;
            spec(materials, v.get_ref(), true, &format!("[{section}] `{k}`"))
                .map(|spec| Rule {
                    pattern: k.clone(),
                    spec,
                    line: line(v.span()),
                })
                .map_err(|m| err(Some(v.span()), m))
        })
        .collect::<Result<Vec<_>, _>>()?;
    RuleSet::new(rules, section == "meshes").map_err(|m| err(None, format!("[{section}] {m}")))
}

fn check_positive(x: f64, what: &str) -> Result<(), String> {
    if x > 0.0 && x.is_finite() {
        Ok(())
    } else {
        Err(format!("{what}: {x} must be a positive number"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const MAP: &str = r#"
default = 1000.0
total_mass = 12.5
[materials]
my_alloy = 2810.0
[links]
base_link = "aluminum"
"*_finger*" = { mass = 0.05 }
"wrist_*" = { density = 1200.0 }
"wrist_roll*" = "my_alloy"
"*" = "pla"
[meshes]
"*battery*" = { density = 2500.0 }
"#;

    #[test]
    fn most_specific_rule_wins() {
        let m = DensityMap::parse(MAP, Path::new("d.toml")).expect("parse");
        assert_eq!(m.default, Some(1000.0));
        assert_eq!(m.total_mass, Some(12.5));
        assert_eq!(
            m.link_rule("base_link"),
            Some(("base_link", Spec::Density(2700.0)))
        );
        assert_eq!(
            m.link_rule("left_finger_1"),
            Some(("*_finger*", Spec::Mass(0.05)))
        );
        assert_eq!(
            m.link_rule("wrist_pitch"),
            Some(("wrist_*", Spec::Density(1200.0)))
        );
        // Longer glob beats shorter.
        assert_eq!(
            m.link_rule("wrist_roll_link"),
            Some(("wrist_roll*", Spec::Density(2810.0)))
        );
        assert_eq!(m.link_rule("elbow"), Some(("*", Spec::Density(1240.0))));
        assert_eq!(m.mesh_rule("package://r/meshes/Battery_pack.stl"), None);
        assert_eq!(
            m.mesh_rule("package://r/meshes/big_battery.stl"),
            Some(("*battery*", Spec::Density(2500.0)))
        );
    }

    #[test]
    fn errors_name_the_line() {
        let e = DensityMap::parse("[links]\nbase = \"unobtainium\"\n", Path::new("d.toml"))
            .unwrap_err();
        assert_eq!(e.line, Some(2), "{e}");
        assert!(e.message.contains("unknown material `unobtainium`"), "{e}");
        let e = DensityMap::parse("default = 1000\ncolour = 3\n", Path::new("d.toml")).unwrap_err();
        assert_eq!(e.line, Some(2), "{e}");
        assert!(e.message.contains("colour"), "{e}");
        let e = DensityMap::parse("default = -5.0\n", Path::new("d.toml")).unwrap_err();
        assert!(e.message.contains("positive"), "{e}");
        let e = DensityMap::parse(
            "[links]\n\"a*\" = { mass = 1, density = 2 }\n",
            Path::new("d.toml"),
        )
        .unwrap_err();
        assert_eq!(e.line, Some(2), "{e}");
        let e = DensityMap::parse("[meshes]\n\"a\" = { weight = 1 }\n", Path::new("d.toml"))
            .unwrap_err();
        assert!(e.message.contains("unknown key `weight`"), "{e}");
    }

    #[test]
    fn globs() {
        let glob_match = |p: &str, name: &str| Glob::new(p).expect("valid").is_match(name);
        assert!(glob_match("*_finger*", "l_finger_tip"));
        assert!(glob_match("a?c", "abc"));
        assert!(!glob_match("a?c", "ac"));
        assert!(glob_match("*", ""));
        assert!(!glob_match("wrist_*", "base"));
        // The full syntax: classes, alternatives.
        assert!(glob_match("link_[0-9]", "link_7"));
        assert!(!glob_match("link_[!0-9]", "link_7"));
        assert!(glob_match("{left,right}_finger", "right_finger"));
        let e = DensityMap::parse("[links]\n\"a[\" = 1000\n", Path::new("d.toml")).unwrap_err();
        assert_eq!(e.line, Some(2), "{e}");
        assert!(e.message.contains("not a valid glob"), "{e}");
    }

    #[test]
    fn toml_errors_show_the_line_the_column_and_a_hint_for_glob_keys() {
        let text = "default = 1000\n[links]\nbase_link = 2700\n*_finger = 1200\n";
        let e = DensityMap::parse(text, Path::new("d.toml")).unwrap_err();
        assert_eq!((e.line, e.column), (Some(4), Some(1)), "{e}");
        let shown = e.to_string();
        assert!(shown.starts_with("d.toml:4:1: "), "{shown}");
        assert!(
            shown.ends_with("\n  |\n4 | *_finger = 1200\n  | ^\n  = hint: a key with glob characters must be quoted: \"*_finger\" = …"),
            "{shown}"
        );
        // Another slip: no hint, but the line and the caret under the column.
        let e = DensityMap::parse("default = 1000\n[links]\na = 12 00\n", Path::new("d.toml"))
            .unwrap_err();
        assert_eq!(e.line, Some(3), "{e}");
        let shown = e.to_string();
        assert!(shown.contains("\n3 | a = 12 00\n"), "{shown}");
        assert!(!shown.contains("hint"), "{shown}");
    }
}
