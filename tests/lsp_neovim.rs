//! End to end: a real Neovim (headless, Debian's package) starts `btc lsp`,
//! opens a rules file with an error, receives the diagnostic at the right
//! place, fixes it and sees it cleared. CI installs Neovim (`.ci/run`).

use std::path::Path;
use std::process::Command;

#[test]
fn neovim_sees_a_diagnostic_and_its_fix() {
    if !btc_testkit::tool("nvim", "`apt-get install neovim`; .ci/run installs it") {
        return;
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let rules = root.join("tests/fixtures/lsp/e2e.btrules");
    let script = root.join("tests/fixtures/lsp/neovim_e2e.lua");
    let out = tempfile::NamedTempFile::new().unwrap();
    let status = Command::new("nvim")
        .args(["--headless", "--clean", "-n", "-c"])
        .arg(format!("luafile {}", script.display()))
        .env("BTC", env!("CARGO_BIN_EXE_btc"))
        .env("RULES", &rules)
        .env("OUT", out.path())
        .status()
        .expect("Neovim runs (apt-get install neovim; .ci/run installs it)");
    let report = std::fs::read_to_string(out.path()).unwrap();
    assert!(status.success(), "{report}");

    // Where the server says the misspelled name is, in byte columns after
    // Neovim's conversion from UTF-16: right after the non-ASCII comment.
    let text = std::fs::read_to_string(&rules).unwrap();
    let (line_no, line) = text
        .lines()
        .enumerate()
        .find(|(_, l)| l.contains("Grsp("))
        .unwrap();
    let col = line.find("Grsp").unwrap();
    let lines: Vec<&str> = report.lines().collect();
    assert_eq!(
        lines[0],
        format!("R007 {line_no}:{col}-{line_no}:{}", col + 4)
    );
    assert_eq!(
        lines[1],
        "message no node or tree is called `Grsp` | hint: did you mean `Grasp`?"
    );
    assert_eq!(lines[2], "hover (:action grasp");
    assert_eq!(lines[3], "cleared");
}
