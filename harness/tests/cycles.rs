//! No import cycles between the modules of a crate: every `crate::…` and `super::…` path in
//! the code (not in comments, not in the inline `#[cfg(test)]` modules) of `core`, `simd`, `reference`
//! and `harness` is an arrow from its file's module to the longest module prefix it names;
//! the test fails on every strongly connected set of more than one module, naming it.

use std::collections::BTreeMap;
use std::path::Path;

/// Module path (`rsl::sat`) → source text of every `.rs` file under `src`.
fn modules(src: &Path) -> BTreeMap<String, String> {
    let mut out = BTreeMap::new();
    let mut stack = vec![src.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for e in std::fs::read_dir(&dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "rs") {
                let rel = p.strip_prefix(src).unwrap().with_extension("");
                let mut parts: Vec<String> = rel
                    .components()
                    .map(|c| c.as_os_str().to_string_lossy().into_owned())
                    .collect();
                if matches!(
                    parts.last().map(String::as_str),
                    Some("mod" | "lib" | "main")
                ) {
                    parts.pop();
                }
                out.insert(parts.join("::"), std::fs::read_to_string(&p).unwrap());
            }
        }
    }
    out
}

/// The code of a file without comments and without its trailing inline test module.
fn code(src: &str) -> String {
    let src = match src.find("#[cfg(test)]\nmod tests") {
        Some(i) => &src[..i],
        None => src,
    };
    src.lines()
        .map(|l| match l.find("//") {
            Some(i) => &l[..i],
            None => l,
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// Arrows `from → to` between modules of one crate.
fn arrows(mods: &BTreeMap<String, String>) -> BTreeMap<String, Vec<String>> {
    let mut out: BTreeMap<String, Vec<String>> = BTreeMap::new();
    for (m, text) in mods {
        let text = code(text);
        let here: Vec<&str> = if m.is_empty() {
            vec![]
        } else {
            m.split("::").collect()
        };
        let bytes = text.as_bytes();
        let mut targets = Vec::new();
        for (start, _) in text
            .match_indices("crate::")
            .chain(text.match_indices("super::"))
        {
            if start > 0 && (bytes[start - 1].is_ascii_alphanumeric() || bytes[start - 1] == b'_') {
                continue;
            }
            // The path: identifiers joined by `::` (a `{` group ends it).
            let rest = &text[start..];
            let end = rest
                .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == ':'))
                .unwrap_or(rest.len());
            let segs: Vec<&str> = rest[..end].split("::").filter(|s| !s.is_empty()).collect();
            let mut path: Vec<&str> = Vec::new();
            let mut it = segs.into_iter().peekable();
            match it.next() {
                Some("crate") => {}
                Some("super") => {
                    path.extend(here.iter().take(here.len().saturating_sub(1)));
                    while it.peek() == Some(&"super") {
                        it.next();
                        path.pop();
                    }
                }
                _ => continue,
            }
            path.extend(it);
            // Longest prefix that is a module of the crate.
            while !path.is_empty() && !mods.contains_key(&path.join("::")) {
                path.pop();
            }
            let to = path.join("::");
            // A module's arrows to itself or to its ancestors' declarations are not imports.
            if to != *m && !to.is_empty() && !m.starts_with(&format!("{to}::")) {
                targets.push(to);
            }
        }
        targets.sort();
        targets.dedup();
        out.insert(m.clone(), targets);
    }
    out
}

/// The strongly connected sets of more than one module (Tarjan).
fn cycles(g: &BTreeMap<String, Vec<String>>) -> Vec<Vec<String>> {
    struct T<'a> {
        g: &'a BTreeMap<String, Vec<String>>,
        index: BTreeMap<&'a str, usize>,
        low: BTreeMap<&'a str, usize>,
        stack: Vec<&'a str>,
        on: BTreeMap<&'a str, bool>,
        out: Vec<Vec<String>>,
    }
    fn visit<'a>(t: &mut T<'a>, v: &'a str) {
        let i = t.index.len();
        t.index.insert(v, i);
        t.low.insert(v, i);
        t.stack.push(v);
        t.on.insert(v, true);
        for w in t.g.get(v).into_iter().flatten() {
            let w = w.as_str();
            if !t.index.contains_key(w) {
                visit(t, w);
                let lw = t.low[w];
                let lv = t.low.get_mut(v).unwrap();
                *lv = (*lv).min(lw);
            } else if t.on.get(w).copied().unwrap_or(false) {
                let iw = t.index[w];
                let lv = t.low.get_mut(v).unwrap();
                *lv = (*lv).min(iw);
            }
        }
        if t.low[v] == t.index[v] {
            let mut set = Vec::new();
            while let Some(w) = t.stack.pop() {
                t.on.insert(w, false);
                set.push(w.to_string());
                if w == v {
                    break;
                }
            }
            if set.len() > 1 {
                set.sort();
                t.out.push(set);
            }
        }
    }
    let mut t = T {
        g,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on: BTreeMap::new(),
        out: Vec::new(),
    };
    for v in g.keys() {
        if !t.index.contains_key(v.as_str()) {
            visit(&mut t, v);
        }
    }
    t.out
}

fn check(krate: &str) -> Vec<String> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join(krate)
        .join("src");
    let g = arrows(&modules(&src));
    cycles(&g)
        .into_iter()
        .map(|c| format!("{krate}: {}", c.join(" ↔ ")))
        .collect()
}

#[test]
fn no_import_cycles_in_any_crate() {
    let found: Vec<String> = ["core", "simd", "reference", "harness"]
        .iter()
        .flat_map(|k| check(k))
        .collect();
    assert!(found.is_empty(), "import cycles:\n  {}", found.join("\n  "));
}

#[test]
fn the_cycle_check_sees_a_cycle() {
    let mods: BTreeMap<String, String> = [
        ("a".to_string(), "use crate::b::x;".to_string()),
        ("b".to_string(), "use super::a::y;".to_string()),
        (
            "c".to_string(),
            "use crate::a::z; // crate::c::w".to_string(),
        ),
    ]
    .into_iter()
    .collect();
    let c = cycles(&arrows(&mods));
    assert_eq!(c, vec![vec!["a".to_string(), "b".to_string()]]);
}
