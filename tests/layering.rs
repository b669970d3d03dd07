//! The crate graph carries the architecture (ARCHITECTURE.md): each crate's
//! normal dependencies on the workspace's crates (and on salsa) are exactly
//! the ones listed here, so the layering cannot erode without this test
//! failing. Dev-dependencies (tests, benchmarks) are free.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::process::Command;

/// Each library crate with the workspace crates it may depend on.
const ALLOWED: &[(&str, &[&str])] = &[
    ("btc-pddl", &[]),
    ("btc-ir", &["btc-pddl"]),
    ("btc-emit", &["btc-ir", "btc-pddl"]),
    (
        "btc-lang",
        &["btc-files", "btc-ir", "btc-pddl", "btc-script"],
    ),
    ("btc-planner", &["btc-pddl"]),
    ("btc-runtime", &["btc-ir", "btc-pddl", "btc-script"]),
    (
        "btc-agent",
        &[
            "btc-ir",
            "btc-lang",
            "btc-pddl",
            "btc-planner",
            "btc-runtime",
        ],
    ),
    (
        "btc-api",
        &[
            "btc-agent",
            "btc-emit",
            "btc-files",
            "btc-ir",
            "btc-lang",
            "btc-pddl",
            "btc-planner",
            "btc-runtime",
        ],
    ),
    // The package's `btc` command is the CLI's library.
    ("btc-python", &["btc", "btc-api"]),
    ("btc-capi", &["btc-api", "btc-pddl"]),
    ("btc-lsp", &["btc-files", "btc-ir", "btc-lang", "btc-pddl"]),
    ("btc-testkit", &[]),
    ("btc-files", &[]),
    ("btc-script", &[]),
];

/// Crates that may use the salsa database.
const SALSA: &[&str] = &["btc-lang"];

/// The workspace's packages, as `cargo metadata` says them.
fn metadata() -> serde_json::Value {
    let out = Command::new(env!("CARGO"))
        .args([
            "metadata",
            "--format-version",
            "1",
            "--no-deps",
            "--offline",
        ])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("cargo metadata runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

fn normal_deps() -> BTreeMap<String, BTreeSet<String>> {
    let meta = metadata();
    let mut graph = BTreeMap::new();
    for p in meta["packages"].as_array().unwrap() {
        let deps = p["dependencies"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|d| d["kind"].is_null())
            .map(|d| d["name"].as_str().unwrap().to_owned())
            .collect();
        graph.insert(p["name"].as_str().unwrap().to_owned(), deps);
    }
    graph
}

#[test]
fn each_crate_depends_only_on_the_layers_below_it() {
    let graph = normal_deps();
    for (krate, deps) in &graph {
        if krate == "btc" {
            continue; // the CLI sits on top of everything
        }
        let allowed = ALLOWED
            .iter()
            .find(|(k, _)| k == krate)
            .unwrap_or_else(|| panic!("{krate} is not in the layering table of tests/layering.rs"))
            .1;
        let ours: BTreeSet<&str> = deps
            .iter()
            .map(String::as_str)
            .filter(|d| *d == "btc" || d.starts_with("btc-"))
            .collect();
        let expected: BTreeSet<&str> = allowed.iter().copied().collect();
        assert_eq!(ours, expected, "{krate}'s dependencies on btc crates");
        assert_eq!(
            deps.contains("salsa"),
            SALSA.contains(&krate.as_str()),
            "{krate} and salsa"
        );
    }
    for (krate, _) in ALLOWED {
        assert!(
            graph.contains_key(*krate),
            "{krate} is not in the workspace"
        );
    }
}

/// A crate's source files as modules: each file's module path
/// (`rules/check/mod.rs` is `rules::check`), from the crate's root file.
fn module_files(root: &Path) -> BTreeMap<Vec<String>, PathBuf> {
    let dir = root.parent().expect("a crate root is in a folder");
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).expect("the source folder reads") {
            let p = e.expect("a folder entry").path();
            if p.is_dir() {
                stack.push(p);
                continue;
            }
            if p.extension().is_none_or(|x| x != "rs") {
                continue;
            }
            let rel = p.strip_prefix(dir).expect("inside the folder");
            let mut parts: Vec<String> = rel
                .with_extension("")
                .components()
                .map(|c| c.as_os_str().to_string_lossy().into_owned())
                .collect();
            if p == root {
                parts.clear();
            } else if parts.last().is_some_and(|l| l == "mod") {
                parts.pop();
            }
            out.insert(parts, p);
        }
    }
    out
}

/// The code of a file without comments, string literals and its test
/// module (`#[cfg(test)]` and what follows): what the file's own code
/// names.
fn code_of(text: &str) -> String {
    let text = text.split("#[cfg(test)]").next().unwrap_or("");
    let mut out = String::with_capacity(text.len());
    let b = text.as_bytes();
    let mut i = 0;
    while i < b.len() {
        if b[i..].starts_with(b"//") {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
        } else if b[i..].starts_with(b"/*") {
            i = text[i + 2..].find("*/").map_or(b.len(), |k| i + k + 4);
        } else if b[i] == b'"' {
            i += 1;
            while i < b.len() && b[i] != b'"' {
                i += if b[i] == b'\\' { 2 } else { 1 };
            }
            i += 1;
            out.push_str("\"\"");
        } else if b[i] == b'\'' && b.get(i + 2) == Some(&b'\'') {
            i += 3; // a character literal such as '{'
        } else {
            out.push(b[i] as char);
            i += 1;
        }
    }
    out
}

/// The paths a file's code starts with `crate::`, `super::` or `self::`,
/// `use` groups (`crate::a::{b, c::d}`) expanded.
fn paths_in(code: &str) -> Vec<Vec<String>> {
    let b = code.as_bytes();
    let word = |c: u8| c.is_ascii_alphanumeric() || c == b'_';
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let starts = ["crate::", "super::", "self::"]
            .iter()
            .any(|s| code[i..].starts_with(s));
        if starts && (i == 0 || !(word(b[i - 1]) || b[i - 1] == b'$' || b[i - 1] == b':')) {
            let mut prefix = Vec::new();
            i = read_path(code, i, &mut prefix, &mut out);
        } else {
            i += 1;
        }
    }
    out
}

/// Reads `a::b::{c, d::e}` at `i` (after the segments in `prefix`) into
/// `out`; returns the index after it.
fn read_path(
    code: &str,
    mut i: usize,
    prefix: &mut Vec<String>,
    out: &mut Vec<Vec<String>>,
) -> usize {
    let b = code.as_bytes();
    let word = |c: u8| c.is_ascii_alphanumeric() || c == b'_';
    let depth = prefix.len();
    loop {
        while i < b.len() && b[i].is_ascii_whitespace() {
            i += 1;
        }
        if i < b.len() && b[i] == b'{' {
            i += 1;
            loop {
                while i < b.len() && (b[i].is_ascii_whitespace() || b[i] == b',') {
                    i += 1;
                }
                if i >= b.len() || b[i] == b'}' {
                    i += 1;
                    break;
                }
                let before = i;
                i = read_path(code, i, prefix, out);
                if i == before {
                    i += 1;
                }
            }
            prefix.truncate(depth);
            return i;
        }
        let start = i;
        while i < b.len() && word(b[i]) {
            i += 1;
        }
        if i > start {
            prefix.push(code[start..i].to_owned());
        } else if i < b.len() && b[i] == b'*' {
            i += 1;
        }
        if code[i..].starts_with("::") {
            i += 2;
            continue;
        }
        out.push(prefix.clone());
        prefix.truncate(depth);
        return i;
    }
}

/// Where a path names a file: the deepest module file along it.
fn target_of(
    module: &[String],
    path: &[String],
    files: &BTreeMap<Vec<String>, PathBuf>,
) -> Option<Vec<String>> {
    let mut at: Vec<String> = Vec::new();
    let mut rest = path;
    match rest.first().map(String::as_str) {
        Some("crate") => rest = &rest[1..],
        Some("self" | "super") => {
            at = module.to_vec();
            while let Some(s) = rest.first().filter(|s| *s == "super" || *s == "self") {
                if s == "super" {
                    at.pop()?;
                }
                rest = &rest[1..];
            }
        }
        _ => return None,
    }
    for seg in rest {
        let mut deeper = at.clone();
        deeper.push(seg.clone());
        if !files.contains_key(&deeper) {
            break;
        }
        at = deeper;
    }
    files.contains_key(&at).then_some(at)
}

/// The cycles (strongly connected parts of more than one file) of a graph.
fn cycles(graph: &BTreeMap<Vec<String>, BTreeSet<Vec<String>>>) -> Vec<Vec<Vec<String>>> {
    // Two files are in one cycle when each reaches the other.
    let reach = |from: &Vec<String>| -> BTreeSet<Vec<String>> {
        let mut seen = BTreeSet::new();
        let mut stack = vec![from.clone()];
        while let Some(n) = stack.pop() {
            for m in graph.get(&n).into_iter().flatten() {
                if seen.insert(m.clone()) {
                    stack.push(m.clone());
                }
            }
        }
        seen
    };
    let reached: BTreeMap<&Vec<String>, BTreeSet<Vec<String>>> =
        graph.keys().map(|k| (k, reach(k))).collect();
    let mut done = BTreeSet::new();
    let mut out = Vec::new();
    for (k, r) in &reached {
        if done.contains(*k) || !r.contains(*k) {
            continue;
        }
        let part: Vec<Vec<String>> = r
            .iter()
            .filter(|m| reached.get(m).is_some_and(|back| back.contains(*k)))
            .cloned()
            .collect();
        done.extend(part.iter().cloned());
        if part.len() > 1 {
            out.push(part);
        }
    }
    out
}

/// The crate roots (library and binary targets) of the workspace.
fn crate_roots() -> Vec<PathBuf> {
    let meta = metadata();
    let mut roots = Vec::new();
    for p in meta["packages"].as_array().unwrap() {
        for t in p["targets"].as_array().unwrap() {
            let kinds: Vec<&str> = t["kind"]
                .as_array()
                .unwrap()
                .iter()
                .filter_map(|k| k.as_str())
                .collect();
            if kinds
                .iter()
                .any(|k| ["lib", "bin", "rlib", "cdylib"].contains(k))
            {
                roots.push(PathBuf::from(t["src_path"].as_str().unwrap()));
            }
        }
    }
    roots.sort();
    roots.dedup();
    roots
}

/// No two files of a crate import each other, directly or around a
/// longer loop: a module's parts depend one way, so each can be read (and
/// moved) without the others. A module file that declares or re-exports
/// its own submodules does not count as depending on them.
#[test]
fn no_import_cycle_between_the_files_of_a_crate() {
    let root_dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut found: Vec<Vec<String>> = Vec::new();
    for root in crate_roots() {
        let files = module_files(&root);
        let mut graph: BTreeMap<Vec<String>, BTreeSet<Vec<String>>> = BTreeMap::new();
        for (module, file) in &files {
            if file
                .file_stem()
                .is_some_and(|s| s == "tests" || s.to_string_lossy().ends_with("_tests"))
            {
                continue;
            }
            let code = code_of(&std::fs::read_to_string(file).expect("a source file reads"));
            let edges = graph.entry(module.clone()).or_default();
            for path in paths_in(&code) {
                let Some(to) = target_of(module, &path, &files) else {
                    continue;
                };
                // Not the file itself, nor one of its submodules.
                if !to.starts_with(module) {
                    edges.insert(to);
                }
            }
        }
        for cycle in cycles(&graph) {
            let mut names: Vec<String> = cycle
                .iter()
                .map(|m| {
                    files[m]
                        .strip_prefix(root_dir)
                        .unwrap_or(&files[m])
                        .to_string_lossy()
                        .into_owned()
                })
                .collect();
            names.sort();
            found.push(names);
        }
    }
    found.sort();
    found.dedup();
    assert!(found.is_empty(), "import cycles between files: {found:#?}");
}
