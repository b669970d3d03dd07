//! Every example × every emitter, snapshotted: one glob over `examples/`,
//! so a new example is covered without a list. Review every snapshot change
//! as if it were code.

use std::path::Path;
use std::process::Command;

const EMITTERS: &[&str] = &["btcpp", "pytrees", "json", "dot", "mermaid", "commands"];

/// The first plan of an example folder (`plan.*`, sorted).
fn plan_of(dir: &Path) -> std::path::PathBuf {
    let mut plans: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            p.file_name()
                .unwrap()
                .to_string_lossy()
                .starts_with("plan.")
        })
        .collect();
    plans.sort();
    plans.into_iter().next().expect("an example has a plan.*")
}

fn compile(rules: &Path, emit: &str, extra: &[&str]) -> String {
    let dir = rules.parent().unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_btc"))
        .arg("compile")
        .arg(rules)
        .arg("--plan")
        .arg(plan_of(dir))
        .args(["--emit", emit])
        .args(extra)
        .env("NO_COLOR", "1")
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{} --emit {emit}: {}",
        rules.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

#[test]
fn every_example_with_every_emitter() {
    insta::glob!("../examples", "*/rules.btrules", |rules| {
        let rel = rules.strip_prefix(env!("CARGO_MANIFEST_DIR")).unwrap();
        for emit in EMITTERS {
            // The py_trees runtime is a file of its own (emit/python/), tested
            // there: the snapshot is the module, with the runtime imported.
            let extra: &[&str] = if *emit == "pytrees" {
                &["--runtime", "import"]
            } else {
                &[]
            };
            let text = compile(rel, emit, extra);
            insta::assert_snapshot!(format!("{emit}"), text);
        }
        insta::assert_snapshot!("btcpp_inline", compile(rel, "btcpp", &["--inline"]));
    });
}
