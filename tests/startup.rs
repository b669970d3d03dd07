//! The shape of a fast start (not its wall-clock time, which depends on
//! the machine): `btc` is linked position-dependent on Linux, so the loader
//! applies no relative relocations before `main` (build.rs), and
//! `btc --version` answers without building the other subcommands' parsers.

use std::process::Command;

const BTC: &str = env!("CARGO_BIN_EXE_btc");

/// ELF `e_type` at offset 16: 2 is `ET_EXEC` (position-dependent), 3 is
/// `ET_DYN` (a PIE).
#[test]
#[cfg(all(target_os = "linux", target_env = "gnu"))]
fn btc_is_a_position_dependent_executable() {
    let bytes = std::fs::read(BTC).expect("the btc binary");
    assert_eq!(&bytes[..4], b"\x7fELF");
    let e_type = u16::from_le_bytes([bytes[16], bytes[17]]);
    assert_eq!(e_type, 2, "btc is linked as a PIE (e_type {e_type})");
}

#[test]
fn version_prints_one_line_and_help_lists_every_subcommand() {
    let out = Command::new(BTC).arg("--version").output().unwrap();
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    assert_eq!(text.lines().count(), 1, "{text}");
    assert!(text.starts_with("btc "), "{text}");
    // Deferred subcommands still show in help and still parse.
    let help = Command::new(BTC).arg("--help").output().unwrap();
    let help = String::from_utf8(help.stdout).unwrap();
    for cmd in ["pddl", "check", "compile", "plan", "run", "lsp"] {
        assert!(
            help.lines().any(|l| l.trim_start().starts_with(cmd)),
            "{cmd} missing from\n{help}"
        );
    }
    let plan_help = Command::new(BTC).args(["plan", "--help"]).output().unwrap();
    let plan_help = String::from_utf8(plan_help.stdout).unwrap();
    assert!(plan_help.contains("--improve"), "{plan_help}");
    assert!(plan_help.contains("lama"), "{plan_help}");
}
