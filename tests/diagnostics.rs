//! One fixture per diagnostic code: `tests/fixtures/diagnostics/CODE/` holds
//! the inputs and a `cmd` file with the `btc` arguments. Each run must report
//! its code; the whole output is snapshotted.

use std::path::Path;
use std::process::Command;

fn run_fixture(cmd_file: &Path) -> (String, i32) {
    let dir = cmd_file.parent().unwrap();
    let args = std::fs::read_to_string(cmd_file).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_btc"))
        .args(args.split_whitespace())
        .current_dir(dir)
        .env("NO_COLOR", "1")
        .output()
        .unwrap();
    let text = format!(
        "$ btc {}\nexit: {}\n--- stdout\n{}--- stderr\n{}",
        args.trim(),
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    (text, out.status.code().unwrap_or(-1))
}

#[test]
fn every_fixture_reports_its_code() {
    insta::glob!("fixtures/diagnostics/*/cmd", |path| {
        let code = path
            .parent()
            .unwrap()
            .file_name()
            .unwrap()
            .to_str()
            .unwrap();
        let (out, exit) = run_fixture(path);
        assert!(
            out.contains(&format!("[{code}]")),
            "fixture {code} did not report {code}:\n{out}"
        );
        assert!(exit != 101, "btc panicked on fixture {code}");
        insta::assert_snapshot!(out);
    });
}

/// Codes that no file-sized fixture can trigger, with where they are tested.
const NO_FIXTURE: &[(&str, &str)] = &[
    (
        "F003",
        "a file over 1 GiB: files::load checks the size first",
    ),
    (
        "X030",
        "a tree of more than 65,535 nodes: runtime/src/btlog.rs tests it",
    ),
    (
        "A001",
        "the C API only (a null pointer, a handle of another kind): capi/tests/abi.rs",
    ),
    (
        "A002",
        "the C API only: a panic caught at the boundary (capi/src/boundary.rs); no input is known to panic",
    ),
    (
        "F006",
        "the language server only: lsp/tests/protocol.rs opens a document over the limit",
    ),
];

#[test]
fn every_code_has_a_fixture() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/diagnostics");
    for code in btc_pddl::diagnostic::codes::ALL {
        if NO_FIXTURE.iter().any(|(c, _)| *c == code.id) {
            continue;
        }
        assert!(
            root.join(code.id).join("cmd").is_file(),
            "no fixture for {} ({})",
            code.id,
            code.title
        );
    }
}
