//! `include/btc.h` is written by hand: it declares exactly the functions
//! the crate exports, and the target numbers the crate defines.

use std::collections::BTreeSet;

fn read(rel: &str) -> String {
    std::fs::read_to_string(format!("{}/{rel}", env!("CARGO_MANIFEST_DIR"))).unwrap()
}

/// `NAME` of every `extern "C" fn NAME(` in the crate's sources.
fn exported() -> BTreeSet<String> {
    let mut names = BTreeSet::new();
    for entry in std::fs::read_dir(format!("{}/src", env!("CARGO_MANIFEST_DIR"))).unwrap() {
        let text = std::fs::read_to_string(entry.unwrap().path()).unwrap();
        let mut rest = text.as_str();
        while let Some(at) = rest.find("extern \"C\" fn ") {
            rest = &rest[at + "extern \"C\" fn ".len()..];
            let end = rest.find(['(', '<']).unwrap();
            names.insert(rest[..end].trim().to_owned());
        }
    }
    names
}

/// The functions the header declares: `btc_NAME(` after a return type.
fn declared(header: &str) -> BTreeSet<String> {
    let mut names = BTreeSet::new();
    for line in header.lines().filter(|l| !l.trim_start().starts_with('*')) {
        let mut rest = line;
        while let Some(at) = rest.find("btc_") {
            let tail = &rest[at..];
            let end = tail
                .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                .unwrap_or(tail.len());
            let name = &tail[..end];
            let before = rest[..at].trim_end();
            if tail[end..].starts_with('(') && !before.ends_with("(*") && !before.is_empty() {
                names.insert(name.to_owned());
            }
            rest = &tail[end..];
        }
    }
    names
}

#[test]
fn the_header_declares_every_exported_function() {
    let header = read("include/btc.h");
    let exported = exported();
    assert!(exported.len() > 15, "{exported:?}");
    assert_eq!(declared(&header), exported);
}

#[test]
fn the_header_has_the_crates_target_numbers() {
    let header = read("include/btc.h");
    for (name, value) in [
        ("BTC_TARGET_BTCPP_XML", btc_capi::BTC_TARGET_BTCPP_XML),
        ("BTC_TARGET_PY_TREES", btc_capi::BTC_TARGET_PY_TREES),
        ("BTC_TARGET_JSON", btc_capi::BTC_TARGET_JSON),
        ("BTC_TARGET_DOT", btc_capi::BTC_TARGET_DOT),
        ("BTC_TARGET_MERMAID", btc_capi::BTC_TARGET_MERMAID),
        ("BTC_TARGET_COMMANDS", btc_capi::BTC_TARGET_COMMANDS),
    ] {
        assert!(
            header.contains(&format!("#define {name} {value}\n")),
            "{name}"
        );
    }
}
