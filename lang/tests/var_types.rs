//! What the checker records of a rule's variables (`db::rule_var_types`,
//! which the language server's hovers, completions and inlay hints read):
//! each `?variable` with the types of the parameter it stands for in the
//! actions the rule's template is checked against — the actions a step
//! can come from, after the guards.

use btc_lang::db::{rule_var_types, rules_items, Database};
use btc_lang::path::FilePath;
use std::path::Path;

#[test]
fn variables_are_typed_by_the_actions_a_step_can_come_from() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/var_types");
    let mut db = Database::new();
    for name in ["domain.pddl", "rules.btrules"] {
        let p = dir.join(name);
        db.set_file(&FilePath::new(&p), std::fs::read_to_string(&p).unwrap());
    }
    let rules = db.file(&FilePath::new(dir.join("rules.btrules"))).unwrap();
    let text = rules.text(&db).clone();
    let mut out = Vec::new();
    for item in rules_items(&db, rules) {
        let vars = rule_var_types(&db, *item);
        if vars.is_empty() {
            continue;
        }
        let at = item.offset(&db) as usize;
        let head = text[at..].lines().next().unwrap_or_default();
        out.push(head.to_owned());
        for v in vars {
            let types = if v.types.is_empty() {
                "no type".to_owned()
            } else {
                v.types.join(" | ")
            };
            out.push(format!("  ?{}: {types}", v.name));
        }
    }
    insta::assert_snapshot!(out.join("\n"));
}
