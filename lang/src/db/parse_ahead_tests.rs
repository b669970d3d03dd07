use super::*;

/// A large file's items parsed ahead on two threads are the items the
/// file's parse then reads (none parsed again), equal to a parse on one.
#[test]
fn items_parsed_ahead_are_not_parsed_again() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let fixture = std::fs::read_to_string(root.join("tests/fixtures/large.btrules"))
        .expect("the large fixture");
    // Copies renamed, so that their items' texts differ.
    let text: String = (0..4)
        .map(|k| fixture.replace("\"move ", &format!("\"m{k} ")))
        .collect();
    let mut db = Database::new();
    let f = db.set_file("/w/huge.btrules", text.clone());
    db.start_logging();
    parse_ahead(&db, f);
    let ahead = db
        .take_log()
        .iter()
        .filter(|l| l.starts_with("parsed_item"))
        .count();
    assert!(ahead > 2_000, "{ahead} items parsed ahead");
    let parsed = parsed_rules(&db, f);
    let log = db.take_log();
    assert!(
        !log.iter().any(|l| l.starts_with("parsed_item")),
        "{log:#?}"
    );
    assert_eq!(
        *parsed,
        crate::rules::parse::parse_rules(&text, file_id(&db, f))
    );
}
