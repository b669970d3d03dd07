use super::*;

/// Loads a file of the repository under its repository-relative path.
pub(crate) fn load(db: &mut Database, path: &str) -> SourceFile {
    let full = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join(path);
    let text = std::fs::read_to_string(&full).unwrap();
    db.set_file(path, text)
}

fn errors(db: &Database, f: SourceFile) -> Vec<String> {
    let sources = db.sources();
    rules_diagnostics(db, f)
        .iter()
        .map(|d| btc_pddl::render::to_short(d, &sources))
        .collect()
}

/// Rendering diagnostics copies the files they point into (spans,
/// labels, fixes) and no other: a long plan is not copied for nothing.
#[test]
fn sources_for_diagnostics_hold_the_files_they_point_into() {
    use btc_pddl::diagnostic::Fix;
    let mut db = Database::new();
    let mut files = Vec::new();
    for p in ["a.pddl", "b.pddl", "c.btrules", "plan.txt"] {
        let f = db.set_file(p, format!("text of {p}"));
        files.push(file_id(&db, f));
    }
    let mut d = Diagnostic::error(codes::INVALID_TOKEN, Span::new(files[0], 0, 1), "here")
        .with_label(Span::new(files[1], 0, 1), "and there");
    d.fixes = Box::new([Fix {
        title: "fix".into(),
        span: Span::new(files[2], 0, 1),
        replacement: String::new(),
    }]);
    let kept: Vec<FileId> = db.sources_for(&[d]).iter().map(|(id, _)| id).collect();
    assert_eq!(kept, files[..3]);
    assert_eq!(db.sources_for(&[]).iter().count(), 0);
    assert!(db.sources().iter().any(|(id, _)| id == files[3]));
}

#[test]
fn the_design_examples_check_clean() {
    for dir in ["examples/ariac", "examples/p3_assembler"] {
        let mut db = Database::new();
        load(&mut db, &format!("{dir}/domain.pddl"));
        load(&mut db, &format!("{dir}/problem.pddl"));
        let rules = load(&mut db, &format!("{dir}/rules.btrules"));
        assert_eq!(errors(&db, rules), Vec::<String>::new(), "{dir}");
    }
}

/// A file's items are its items' parses, not copies of them (copying
/// every item of a huge file on each edit was a large part of the
/// edit's time): before and after an edit, each item of the parsed
/// file is the allocation its `parsed_item` memo holds.
#[test]
fn the_parsed_file_shares_its_items_with_their_parses() {
    let mut db = Database::new();
    load(&mut db, "examples/ariac/domain.pddl");
    let f = load(&mut db, "lang/tests/fixtures/large.btrules");
    let shared = |db: &Database| {
        let parsed = parsed_file(db, f);
        assert!(parsed.rules.items.len() > 700);
        for (n, t) in parsed.rules.items.iter().zip(&parsed.texts) {
            let t = t.expect("a rules file's items have texts");
            assert!(Arc::ptr_eq(&n.item, &parsed_item(db, t).0));
        }
        for i in rules_items(db, f) {
            let ItemSource::Text(t) = i.source(db) else {
                panic!("not a palette")
            };
            assert!(std::ptr::eq(i.item(db), &*parsed_item(db, t).0));
        }
    };
    shared(&db);
    let first = parsed_rules(&db, f).items[5].item.clone();
    let text = format!("// a comment first\n{}", f.text(&db));
    db.set_file(&f.path(&db).clone(), text);
    shared(&db);
    // The items the edit left alone are the same allocations as before.
    assert!(Arc::ptr_eq(&first, &parsed_rules(&db, f).items[5].item));
}

#[test]
fn editing_one_rule_rechecks_only_that_rule() {
    let mut db = Database::new();
    load(&mut db, "examples/ariac/domain.pddl");
    let f = load(&mut db, "lang/tests/fixtures/large.btrules");
    let items = rules_items(&db, f).len();
    assert!(items > 700);
    assert!(
        errors(&db, f).iter().all(|e| e.contains("R013")),
        "{:?}",
        &errors(&db, f)[..3]
    );
    db.start_logging();
    // Change one rule in the middle, and the text's length with it.
    let text = f.text(&db).replacen(
        "retry(3) MoveTo(robot: ?r, target: ?b)",
        "retry(30) MoveTo(robot: ?r, target: ?destination)",
        1,
    );
    db.set_file(&f.path(&db).clone(), text);
    let after = errors(&db, f);
    let log = db.take_log();
    let rechecked = log
        .iter()
        .filter(|l| l.starts_with("item_diagnostics"))
        .count();
    assert_eq!(rechecked, 1, "{log:#?}");
    let reparsed = log.iter().filter(|l| l.starts_with("parsed_item")).count();
    assert_eq!(
        reparsed, 1,
        "only the edited item is parsed again: {log:#?}"
    );
    // The file-level checks read summaries the edit left equal: they
    // do not run again over every rule.
    for query in [
        "file_coverage",
        "file_unused",
        "file_structure",
        "item_heads",
    ] {
        assert!(
            !log.iter().any(|l| l.starts_with(query)),
            "{query} ran again: {log:#?}"
        );
    }
    let summarized = log.iter().filter(|l| l.starts_with("rule_facts")).count();
    assert_eq!(summarized, 1, "{log:#?}");
    assert_eq!(after.len(), 1, "{after:?}");
    assert!(
        after[0].ends_with(":27:45: error[R006]: `?destination` is not bound here"),
        "{after:?}"
    );
}

#[test]
fn a_new_rule_reruns_coverage_once() {
    let mut db = Database::new();
    load(&mut db, "examples/ariac/domain.pddl");
    let f = load(&mut db, "lang/tests/fixtures/large.btrules");
    let before = errors(&db, f).len();
    db.start_logging();
    let text = format!(
        "{}\nrule (flip ?robot ?p ?c) {{ Flip(robot: ?robot, part: ?p, container: ?c) }}\n",
        f.text(&db)
    );
    db.set_file(&f.path(&db).clone(), text);
    let after = errors(&db, f);
    let log = db.take_log();
    let count = |q: &str| log.iter().filter(|l| l.starts_with(q)).count();
    assert_eq!(count("file_coverage"), 1, "{log:#?}");
    assert_eq!(count("rule_facts"), 1, "only the new rule: {log:#?}");
    assert_eq!(after.len(), before + 1, "{after:?}");
    assert!(after.iter().any(|e| e.contains("R013")));
}

#[test]
fn an_unknown_stdlib_module_and_import_cycles() {
    let mut db = Database::new();
    db.set_file(
        "a.btrules",
        "import \"b.btrules\"\nimport std::nope\naction A()\n".into(),
    );
    db.set_file("b.btrules", "import \"a.btrules\"\naction B()\n".into());
    let a = db.file("a.btrules").unwrap();
    let codes: Vec<&str> = rules_diagnostics(&db, a).iter().map(|d| d.code).collect();
    assert!(codes.contains(&"R018"));
    assert!(declarations(&db, a).nodes.contains_key("B"));
}
