//! Glob patterns compiled once, and a section's rules compiled into glob sets so that a lookup costs
//! one pass over the name whatever the number of rules.

use super::Spec;

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
    pub(super) rules: Vec<Rule>,
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
    pub(super) fn mark_matches(&self, uri: &str, name: &str, used: &mut [bool]) {
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
    pub(super) fn best(&self, uri: &str, name: &str) -> Option<(&str, Spec)> {
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
pub(super) fn parse_glob(pattern: &str) -> Result<globset::Glob, String> {
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
