//! The crate graph carries the architecture (ARCHITECTURE.md): each crate's
//! normal dependencies on the workspace's crates (and on salsa) are exactly
//! the ones listed here, so the layering cannot erode without this test
//! failing. Dev-dependencies (tests, benchmarks) are free.

use std::collections::{BTreeMap, BTreeSet};
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
    ("btc-python", &["btc-api"]),
    ("btc-capi", &["btc-api", "btc-pddl"]),
    ("btc-lsp", &["btc-files", "btc-ir", "btc-lang", "btc-pddl"]),
    ("btc-testkit", &[]),
    ("btc-files", &[]),
    ("btc-script", &[]),
];

/// Crates that may use the salsa database.
const SALSA: &[&str] = &["btc-lang"];

fn normal_deps() -> BTreeMap<String, BTreeSet<String>> {
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
    let meta: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
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
            .filter(|d| d.starts_with("btc-"))
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
