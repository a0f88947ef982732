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

/// One rule of a density map: its key as written and what it gives.
#[derive(Debug, Clone, PartialEq)]
pub struct Rule {
    pub pattern: String,
    pub spec: Spec,
    /// 1-based line of the rule in the map's text (0 when built without text).
    pub line: usize,
}

/// The rules of one section, compiled once: exact keys in a hash map, the globs in two
/// `globset::GlobSet`s (keys with a `/`, matched against a whole URI, and the others), so that a lookup
/// costs one pass over the name whatever the number of rules (a map of 300 rules over 300 links was
/// quadratic when each lookup compiled each pattern).
#[derive(Debug, Clone, Default)]
pub struct RuleSet {
    rules: Vec<Rule>,
    /// The first rule (file order) of each key.
    exact: std::collections::HashMap<String, usize>,
    whole: Matcher,
    name: Matcher,
}

/// A glob set and the index into [`RuleSet::rules`] of each of its patterns.
#[derive(Debug, Clone, Default)]
struct Matcher {
    set: globset::GlobSet,
    rule: Vec<usize>,
}

impl PartialEq for RuleSet {
    fn eq(&self, other: &Self) -> bool {
        self.rules == other.rules
    }
}

impl RuleSet {
    /// Compiles `rules` (file order). With `by_uri`, keys holding a `/` are matched against the whole
    /// URI and the others against the file name; without it every key is matched against the name.
    pub fn new(rules: Vec<Rule>, by_uri: bool) -> Result<Self, String> {
        let mut exact = std::collections::HashMap::new();
        let (mut whole, mut name) = (
            globset::GlobSetBuilder::new(),
            globset::GlobSetBuilder::new(),
        );
        let (mut whole_rule, mut name_rule) = (Vec::new(), Vec::new());
        for (i, r) in rules.iter().enumerate() {
            exact.entry(r.pattern.clone()).or_insert(i);
            let g = parse_glob(&r.pattern)?;
            if by_uri && r.pattern.contains('/') {
                whole.add(g);
                whole_rule.push(i);
            } else {
                name.add(g);
                name_rule.push(i);
            }
        }
        let build = |b: globset::GlobSetBuilder, rule: Vec<usize>| {
            b.build()
                .map(|set| Matcher { set, rule })
                .map_err(|e| format!("the patterns cannot be compiled together: {e}"))
        };
        Ok(RuleSet {
            rules,
            exact,
            whole: build(whole, whole_rule)?,
            name: build(name, name_rule)?,
        })
    }

    /// The rules in file order.
    pub fn rules(&self) -> &[Rule] {
        &self.rules
    }

    /// Marks in `used` every rule that matches `name` (and, for mesh rules, `uri`), whether or not
    /// it is the one that wins.
    fn mark_matches(&self, uri: &str, name: &str, used: &mut [bool]) {
        for k in [uri, name] {
            if let Some(&i) = self.exact.get(k) {
                let r = &self.rules[i].pattern;
                if r == name || (r.contains('/') && r == uri) {
                    used[i] = true;
                }
            }
        }
        for (m, target) in [(&self.whole, uri), (&self.name, name)] {
            for j in m.set.matches(target) {
                used[m.rule[j]] = true;
            }
        }
    }

    /// The rule for `name` (and, for mesh rules, its `uri`): an exact key first (the first written of
    /// the two kinds), then the longest matching glob (the first written on ties).
    fn best(&self, uri: &str, name: &str) -> Option<(&str, Spec)> {
        let exact = [uri, name]
            .iter()
            .filter_map(|k| self.exact.get(*k).copied())
            .filter(|&i| {
                let r = &self.rules[i].pattern;
                // A key with a `/` names a URI, one without a file name (for links both are the name).
                r == name || (r.contains('/') && r == uri)
            })
            .min();
        let hit = exact.or_else(|| {
            let len = |i: usize| self.rules[i].pattern.len();
            let mut best: Option<usize> = None;
            for (m, target) in [(&self.whole, uri), (&self.name, name)] {
                for j in m.set.matches(target) {
                    let i = m.rule[j];
                    if best.is_none_or(|b| len(i) > len(b) || (len(i) == len(b) && i < b)) {
                        best = Some(i);
                    }
                }
            }
            best
        });
        hit.map(|i| (self.rules[i].pattern.as_str(), self.rules[i].spec))
    }
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

/// A density-map rule that matched nothing in the robots of a run, and a near name, if one is.
#[derive(Debug, Clone, PartialEq)]
pub struct UnusedRule {
    /// `links` or `meshes`.
    pub section: &'static str,
    pub pattern: String,
    /// 1-based line in the map.
    pub line: usize,
    /// A corrected key and the name it would match (`"*battery*"`, `big_battery.stl`).
    pub suggestion: Option<(String, String)>,
}

impl UnusedRule {
    /// The warning (UI302), located on the rule's line of the map at `path`.
    pub fn diagnostic(&self, path: &Path) -> crate::diagnostic::Diagnostic {
        use crate::diagnostic::{Code, Diagnostic, Location};
        let what = if self.section == "links" {
            "link"
        } else {
            "collision mesh"
        };
        let mut message = format!(
            "[{}] rule \"{}\" matches no {what}: it is ignored",
            self.section,
            crate::text::escape_control(&self.pattern)
        );
        match &self.suggestion {
            Some((key, name)) if key == name => {
                let _ = write!(
                    message,
                    "; did you mean \"{}\"?",
                    crate::text::escape_control(key)
                );
            }
            Some((key, name)) => {
                let _ = write!(
                    message,
                    "; did you mean \"{}\" (it matches `{}`)?",
                    crate::text::escape_control(key),
                    crate::text::escape_control(name)
                );
            }
            None => {}
        }
        Diagnostic::new(Code::DensityRuleUnused, message).at(Location {
            file: Some(path.to_path_buf()),
            line: Some(self.line),
            ..Location::default()
        })
    }
}

impl DensityMap {
    /// The `[links]` and `[meshes]` rules that match none of `links` (link names) and none of
    /// `mesh_uris` (collision mesh filename attributes), over every robot of a run, each with a
    /// did-you-mean when a name is one edit (or a change of case) away. A rule that matches but never
    /// wins (a more specific one does) is not reported: it is not a typo.
    pub fn unused_rules(&self, links: &[&str], mesh_uris: &[&str]) -> Vec<UnusedRule> {
        let mut used_links = vec![false; self.links.rules.len()];
        for l in links {
            self.links.mark_matches(l, l, &mut used_links);
        }
        let mut used_meshes = vec![false; self.meshes.rules.len()];
        let file_names: Vec<&str> = mesh_uris
            .iter()
            .map(|u| u.rsplit('/').next().unwrap_or(u))
            .collect();
        for (u, f) in mesh_uris.iter().zip(&file_names) {
            self.meshes.mark_matches(u, f, &mut used_meshes);
        }
        let mut out = Vec::new();
        for (section, set, used, names) in [
            ("links", &self.links, used_links, links),
            ("meshes", &self.meshes, used_meshes, &file_names[..]),
        ] {
            for (r, _) in set.rules.iter().zip(used).filter(|(_, u)| !u) {
                let names: &[&str] = if section == "meshes" && r.pattern.contains('/') {
                    mesh_uris
                } else {
                    names
                };
                out.push(UnusedRule {
                    section,
                    pattern: r.pattern.clone(),
                    line: r.line,
                    suggestion: near_miss(&r.pattern, names),
                });
            }
        }
        out
    }
}

/// A key one edit (or a change of case) from matching one of `names`: the corrected key and the
/// name it matches. Keys with `[`, `{` or `\\` are not guessed at (only `*` and `?` are understood
/// here), nor keys or name lists too long to try every edit of.
pub fn near_miss(pattern: &str, names: &[&str]) -> Option<(String, String)> {
    let p: Vec<char> = pattern.chars().collect();
    if p.len() > 64 || names.len() > 20_000 || p.iter().any(|c| "[]{}\\".contains(*c)) {
        return None;
    }
    let hit = |q: &[char], fold: bool| {
        names.iter().find(|n| {
            let n: Vec<char> = n.chars().collect();
            wildcard(q, &n, fold)
        })
    };
    if let Some(n) = hit(&p, true) {
        let key = if p.contains(&'*') || p.contains(&'?') {
            pattern.to_string()
        } else {
            (*n).to_string()
        };
        // Only the case differs: a glob names the name it would match with the case corrected.
        return Some((
            if key == pattern {
                (*n).to_string()
            } else {
                key
            },
            (*n).to_string(),
        ));
    }
    let mut alphabet: Vec<char> = names.iter().flat_map(|n| n.chars()).collect();
    alphabet.sort_unstable();
    alphabet.dedup();
    let mut q = Vec::with_capacity(p.len() + 1);
    for i in 0..=p.len() {
        // Deletion of p[i].
        if i < p.len() {
            q.clear();
            q.extend_from_slice(&p[..i]);
            q.extend_from_slice(&p[i + 1..]);
            if !q.is_empty() {
                if let Some(n) = hit(&q, false) {
                    return Some((q.iter().collect(), (*n).to_string()));
                }
            }
        }
        for &c in &alphabet {
            // Insertion before p[i], then substitution of p[i].
            q.clear();
            q.extend_from_slice(&p[..i]);
            q.push(c);
            q.extend_from_slice(&p[i..]);
            if let Some(n) = hit(&q, false) {
                return Some((q.iter().collect(), (*n).to_string()));
            }
            if i < p.len() && p[i] != c {
                q.clear();
                q.extend_from_slice(&p[..i]);
                q.push(c);
                q.extend_from_slice(&p[i + 1..]);
                if let Some(n) = hit(&q, false) {
                    return Some((q.iter().collect(), (*n).to_string()));
                }
            }
        }
    }
    None
}

/// Whether `name` matches `pattern` with `*` (any run) and `?` (one character), optionally ignoring
/// ASCII case: the classic two-pointer match with one backtrack point, linear in practice.
fn wildcard(pattern: &[char], name: &[char], fold: bool) -> bool {
    let eq = |a: char, b: char| {
        if fold {
            a.eq_ignore_ascii_case(&b)
        } else {
            a == b
        }
    };
    let (mut p, mut n) = (0, 0);
    let mut star: Option<(usize, usize)> = None;
    while n < name.len() {
        if p < pattern.len()
            && (pattern[p] == '?' || (pattern[p] != '*' && eq(pattern[p], name[n])))
        {
            p += 1;
            n += 1;
        } else if p < pattern.len() && pattern[p] == '*' {
            star = Some((p, n));
            p += 1;
        } else if let Some((sp, sn)) = star {
            p = sp + 1;
            n = sn + 1;
            star = Some((sp, sn + 1));
        } else {
            return false;
        }
    }
    pattern[p..].iter().all(|&c| c == '*')
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
        toml::Value::Float(d) => check_positive(*d, what).map(|_| Spec::Density(*d)),
        toml::Value::Integer(i) => {
            check_positive(*i as f64, what).map(|_| Spec::Density(*i as f64))
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
            check_positive(d, what).map(|_| Spec::Density(d))
        }
        "mass" if allow_mass => {
            let m = num()?;
            check_positive(m, what).map(|_| Spec::Mass(m))
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

/// The longest glob pattern accepted, in bytes. globset compiles a pattern into a regular expression
/// and panics on one past its size limit (a 400 KB key did); no link or mesh name needs a pattern this
/// long.
pub const MAX_GLOB_LEN: usize = 4096;

/// A glob pattern compiled once (the `globset` crate): `*` and `?` (which also match `/`), `[abc]`,
/// `[!a-z]`, `{a,b}` and `**`, with its text for messages. Used by `--only`, `--skip` and the density
/// map's keys.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct Glob {
    glob: globset::Glob,
    matcher: globset::GlobMatcher,
}

impl Glob {
    /// Compiles `pattern`; an invalid or over-long pattern is an error saying why.
    pub fn new(pattern: &str) -> Result<Glob, crate::Error> {
        let glob = parse_glob(pattern).map_err(|message| crate::Error::Pattern {
            pattern: pattern.to_string(),
            message,
        })?;
        let matcher = glob.compile_matcher();
        Ok(Glob { glob, matcher })
    }

    /// The pattern as written.
    pub fn as_str(&self) -> &str {
        self.glob.glob()
    }

    pub fn is_match(&self, name: &str) -> bool {
        self.matcher.is_match(name)
    }
}

/// Parses a pattern without compiling its matcher (a glob set compiles its patterns together).
fn parse_glob(pattern: &str) -> Result<globset::Glob, String> {
    if pattern.len() > MAX_GLOB_LEN {
        let head: String = pattern.chars().take(40).collect();
        return Err(format!(
            "`{}…` ({} bytes) is longer than the {MAX_GLOB_LEN} bytes a glob may have",
            crate::text::escape_control(&head),
            pattern.len()
        ));
    }
    globset::GlobBuilder::new(pattern)
        .backslash_escape(true)
        .build()
        .map_err(|e| {
            format!(
                "`{}` is not a valid glob: {}",
                crate::text::escape_control(pattern),
                e.kind()
            )
        })
}

impl PartialEq for Glob {
    fn eq(&self, other: &Self) -> bool {
        self.as_str() == other.as_str()
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
    fn rules_that_match_nothing_are_named_with_a_near_name() {
        let text = "default = 1000\n[links]\n\"*_link\" = 1.0\nbase_lnk = 2.0\n\"Wrist\" = 3.0\n\"arm_*\" = 4.0\n[meshes]\n\"*batery*\" = 5.0\n\"*motor*\" = 6.0\n\"meshes/x/*.stl\" = 7.0\n";
        let m = DensityMap::parse(text, Path::new("d.toml")).unwrap();
        let links = ["base_link", "wrist", "arm_link"];
        let uris = [
            "package://r/meshes/big_battery.stl",
            "package://r/meshes/motor.stl",
        ];
        let unused = m.unused_rules(&links, &uris);
        type Row<'a> = (&'a str, &'a str, usize, Option<(String, String)>);
        let got: Vec<Row<'_>> = unused
            .iter()
            .map(|u| (u.section, u.pattern.as_str(), u.line, u.suggestion.clone()))
            .collect();
        let s = |a: &str, b: &str| Some((a.to_string(), b.to_string()));
        assert_eq!(
            got,
            vec![
                ("links", "base_lnk", 4, s("base_link", "base_link")),
                ("links", "Wrist", 5, s("wrist", "wrist")),
                ("meshes", "*batery*", 8, s("*battery*", "big_battery.stl")),
                ("meshes", "meshes/x/*.stl", 10, None),
            ]
        );
        let d = unused[2].diagnostic(Path::new("d.toml"));
        assert_eq!(
            d.render(),
            "warning[UI302]: d.toml:8: [meshes] rule \"*batery*\" matches no collision mesh: it is ignored; did you mean \"*battery*\" (it matches `big_battery.stl`)?"
        );
        // A rule that matches is not reported, even when a more specific one wins.
        assert!(m
            .unused_rules(
                &["base_lnk", "Wrist", "arm_link"],
                &["meshes/x/batery.stl", "m/motor.stl"]
            )
            .is_empty());
    }

    #[test]
    fn wildcard_matches_like_the_glob() {
        let w = |p: &str, n: &str| {
            let p: Vec<char> = p.chars().collect();
            let n: Vec<char> = n.chars().collect();
            wildcard(&p, &n, false)
        };
        for (p, n) in [
            ("*", ""),
            ("a*b", "ab"),
            ("a*b", "axxb"),
            ("*a*", "bab"),
            ("a?c", "abc"),
            ("**x", "yx"),
        ] {
            assert!(w(p, n), "{p} {n}");
            assert!(Glob::new(p).unwrap().is_match(n), "{p} {n}");
        }
        for (p, n) in [("a*b", "abc"), ("a?c", "ac"), ("*x", "xy")] {
            assert!(!w(p, n), "{p} {n}");
            assert!(!Glob::new(p).unwrap().is_match(n), "{p} {n}");
        }
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
