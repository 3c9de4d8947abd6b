//! The layout keeps data flowing one way: no import cycle between the top-level modules of
//! `src/`, nor between sibling files of one directory (a child using its parent `mod.rs` is
//! not a cycle: the parent declares it). Dependencies are read from the source text
//! (`crate::a::b` paths, `super::` paths, `crate::{a, b}` groups, `crate::Error`/`Result`),
//! outside `#[cfg(test)]` code.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

type Module = Vec<String>;

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("readable src/") {
        let path = entry.expect("entry").path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// `src/a/b.rs` → `[a, b]`; `src/a/mod.rs` → `[a]`; `src/lib.rs` → `[]`.
fn module_of(src: &Path, file: &Path) -> Module {
    let rel = file
        .strip_prefix(src)
        .expect("under src/")
        .with_extension("");
    let mut parts: Module = rel
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect();
    if matches!(
        parts.last().map(String::as_str),
        Some("mod" | "lib" | "main")
    ) {
        parts.pop();
    }
    parts
}

/// The source without `#[cfg(test)]` items (from the first one on: test modules come last)
/// and without `//` comments.
fn code(text: &str) -> String {
    let text = text.split("#[cfg(test)]").next().unwrap_or("");
    text.lines()
        .map(|l| l.split("//").next().unwrap_or(""))
        .collect::<Vec<_>>()
        .join("\n")
}

/// The identifier path `a::b::c` at the start of `s`.
fn ident_path(s: &str) -> Vec<String> {
    let mut parts = Vec::new();
    let mut cur = s;
    loop {
        let n = cur
            .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
            .unwrap_or(cur.len());
        if n == 0 {
            break;
        }
        parts.push(cur[..n].to_string());
        match cur[n..].strip_prefix("::") {
            Some(next) => cur = next,
            None => break,
        }
    }
    parts
}

/// Identifier paths following `prefix` (e.g. `crate::`) in `text`.
fn paths_after<'a>(text: &'a str, prefix: &'a str) -> impl Iterator<Item = Vec<String>> + 'a {
    text.match_indices(prefix)
        .map(move |(i, _)| ident_path(&text[i + prefix.len()..]))
}

/// The longest prefix of `path` (after `base`) that names a module.
fn resolve(modules: &BTreeSet<Module>, base: &[String], path: &[String]) -> Option<Module> {
    (0..=path.len()).rev().find_map(|k| {
        let mut m: Module = base.to_vec();
        m.extend_from_slice(&path[..k]);
        modules.contains(&m).then_some(m)
    })
}

fn dependencies(src: &Path) -> BTreeMap<Module, BTreeSet<Module>> {
    let mut files = Vec::new();
    rust_files(src, &mut files);
    let modules: BTreeSet<Module> = files.iter().map(|f| module_of(src, f)).collect();
    let mut deps = BTreeMap::new();
    for f in &files {
        let m = module_of(src, f);
        let text = code(&std::fs::read_to_string(f).expect("readable"));
        let mut d = BTreeSet::new();
        for p in paths_after(&text, "crate::") {
            if matches!(p.first().map(String::as_str), Some("Error" | "Result")) {
                d.insert(vec!["error".to_string()]);
            } else if let Some(r) = resolve(&modules, &[], &p) {
                d.insert(r);
            }
        }
        for (i, _) in text.match_indices("crate::{") {
            let group = &text[i + "crate::{".len()..];
            let group = &group[..group.find('}').unwrap_or(0)];
            for item in group.split(',') {
                let p: Vec<String> = item.trim().split("::").map(str::to_string).collect();
                if let Some(r) = resolve(&modules, &[], &p) {
                    d.insert(r);
                }
            }
        }
        for (i, _) in text.match_indices("super::") {
            // Count the chain of `super::` ending here, once, at its first link.
            if text[..i].ends_with("super::") {
                continue;
            }
            let mut up = 0;
            let mut rest = &text[i..];
            while let Some(r) = rest.strip_prefix("super::") {
                up += 1;
                rest = r;
            }
            if up > m.len() {
                continue;
            }
            let base = &m[..m.len() - up];
            if let Some(r) = resolve(&modules, base, &ident_path(rest)) {
                d.insert(r);
            }
        }
        d.remove(&m);
        deps.insert(m, d);
    }
    deps
}

/// Strongly connected components with more than one node of `graph`.
fn cycles(graph: &BTreeMap<Module, BTreeSet<Module>>) -> Vec<Vec<Module>> {
    // Kosaraju: order by finish time, then components of the transpose.
    let nodes: Vec<&Module> = graph.keys().collect();
    let mut seen = BTreeSet::new();
    let mut order = Vec::new();
    fn visit<'a>(
        n: &'a Module,
        g: &'a BTreeMap<Module, BTreeSet<Module>>,
        seen: &mut BTreeSet<&'a Module>,
        order: &mut Vec<&'a Module>,
    ) {
        if !seen.insert(n) {
            return;
        }
        for m in g.get(n).into_iter().flatten() {
            visit(m, g, seen, order);
        }
        order.push(n);
    }
    for n in &nodes {
        visit(n, graph, &mut seen, &mut order);
    }
    let mut transpose: BTreeMap<&Module, Vec<&Module>> = BTreeMap::new();
    for (a, bs) in graph {
        for b in bs {
            transpose.entry(b).or_default().push(a);
        }
    }
    let mut assigned = BTreeSet::new();
    let mut out = Vec::new();
    for n in order.into_iter().rev() {
        if assigned.contains(n) {
            continue;
        }
        let mut comp = Vec::new();
        let mut stack = vec![n];
        while let Some(x) = stack.pop() {
            if !assigned.insert(x) {
                continue;
            }
            comp.push(x.clone());
            stack.extend(transpose.get(x).into_iter().flatten());
        }
        if comp.len() > 1 {
            comp.sort();
            out.push(comp);
        }
    }
    out
}

/// The graph between the modules at `depth` below the same parent: top-level modules
/// (depth 1), or the files of each directory (depth 2, 3, ...). Edges to an ancestor are
/// dropped (a child using its parent).
fn level_graph(
    deps: &BTreeMap<Module, BTreeSet<Module>>,
    depth: usize,
) -> BTreeMap<Module, BTreeSet<Module>> {
    let cut = |m: &Module| m[..m.len().min(depth)].to_vec();
    let mut g: BTreeMap<Module, BTreeSet<Module>> = BTreeMap::new();
    for (a, bs) in deps {
        if a.len() < depth {
            continue;
        }
        let a = cut(a);
        for b in bs {
            let b = cut(b);
            let ancestor = b.len() <= a.len() && a[..b.len()] == b[..];
            let siblings = depth == 1 || (b.len() == depth && a[..depth - 1] == b[..depth - 1]);
            if a != b && !ancestor && siblings {
                g.entry(a.clone()).or_default().insert(b);
            }
        }
        g.entry(a).or_default();
    }
    g
}

#[test]
fn no_import_cycle_in_src() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let deps = dependencies(&src);
    assert!(
        deps.len() > 50 && deps.values().map(BTreeSet::len).sum::<usize>() > 100,
        "the scan found the modules and their uses"
    );
    let mut found = Vec::new();
    for depth in 1..=3 {
        for c in cycles(&level_graph(&deps, depth)) {
            let names: Vec<String> = c.iter().map(|m| m.join("::")).collect();
            found.push(names.join(" ↔ "));
        }
    }
    assert!(found.is_empty(), "import cycles: {found:#?}");
}

/// The scan itself finds a planted cycle (so the test above can fail).
#[test]
fn a_planted_cycle_is_found() {
    let dir = std::env::temp_dir().join(format!("conemesh-arch-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("b")).expect("temp dir");
    std::fs::write(dir.join("lib.rs"), "pub mod a;\npub mod b;\n").expect("write");
    std::fs::write(dir.join("a.rs"), "use crate::b::Thing;\n").expect("write");
    std::fs::write(dir.join("b/mod.rs"), "mod c;\npub use c::Thing;\n").expect("write");
    std::fs::write(dir.join("b/c.rs"), "use crate::a;\nuse super::d;\n").expect("write");
    std::fs::write(dir.join("b/d.rs"), "use super::c::Thing;\n").expect("write");
    let deps = dependencies(&dir);
    let top = cycles(&level_graph(&deps, 1));
    assert_eq!(top.len(), 1, "{deps:?}");
    let inner = cycles(&level_graph(&deps, 2));
    assert_eq!(inner.len(), 1, "c ↔ d: {inner:?}");
    let _ = std::fs::remove_dir_all(&dir);
}
