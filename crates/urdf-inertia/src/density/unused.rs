//! The density-map rules that match nothing in a run, each with a did-you-mean when a name is one
//! edit away.

use super::DensityMap;
use std::fmt::Write as _;
use std::path::Path;

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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::density::Glob;

    #[test]
    fn rules_that_match_nothing_are_named_with_a_near_name() {
        type Row<'a> = (&'a str, &'a str, usize, Option<(String, String)>);
        let text = "default = 1000\n[links]\n\"*_link\" = 1.0\nbase_lnk = 2.0\n\"Wrist\" = 3.0\n\"arm_*\" = 4.0\n[meshes]\n\"*batery*\" = 5.0\n\"*motor*\" = 6.0\n\"meshes/x/*.stl\" = 7.0\n";
        let m = DensityMap::parse(text, Path::new("d.toml")).unwrap();
        let links = ["base_link", "wrist", "arm_link"];
        let uris = [
            "package://r/meshes/big_battery.stl",
            "package://r/meshes/motor.stl",
        ];
        let unused = m.unused_rules(&links, &uris);
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
}
