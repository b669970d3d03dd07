//! A pattern with captures and the parameter counts of the actions it
//! names (docs/language.md, "Rules and matching"): it matches the named
//! actions whose count it fits; R003 only when it fits none of them, or
//! when the name is literal. The fixture has driverlog's shape:
//! `{verb}-truck` names three actions of three parameters and one of four.

use btc_lang::db::{file_id, rules_diagnostics, Database};
use btc_lang::path::FilePath;
use std::path::Path;

/// `CODE line:column message` for each diagnostic of a rules file of the
/// fixture (`CODE (in the domain) message` for one placed in the domain).
fn check(rules: &str) -> Vec<String> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/captures");
    let mut db = Database::new();
    for name in ["domain.pddl", rules] {
        let p = dir.join(name);
        db.set_file(&FilePath::new(&p), std::fs::read_to_string(&p).unwrap());
    }
    let file = db.file(&FilePath::new(dir.join(rules))).unwrap();
    let text = std::fs::read_to_string(dir.join(rules)).unwrap();
    let id = file_id(&db, file);
    rules_diagnostics(&db, file)
        .iter()
        .map(|d| {
            if d.span.file != id {
                return format!("{} (in the domain) {}", d.code, d.message);
            }
            let before = &text[..d.span.start as usize];
            let line = before.matches('\n').count() + 1;
            let col = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
            format!("{} {line}:{col} {}", d.code, d.message)
        })
        .collect()
}

#[test]
fn a_capture_pattern_is_for_the_actions_whose_count_it_fits() {
    assert_eq!(check("rules.btrules"), Vec::<String>::new());
}

#[test]
fn an_action_of_another_count_is_left_uncovered_not_refused() {
    let found = check("uncovered.btrules");
    assert!(found.iter().all(|d| !d.starts_with("R003")), "{found:?}");
    insta::assert_snapshot!(found.join("\n"));
}

#[test]
fn a_count_that_fits_none_or_a_literal_name_is_r003() {
    insta::assert_snapshot!(check("fits_none.btrules").join("\n"));
}
