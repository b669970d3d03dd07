//! The reference table in `docs/language.md` lists exactly the codes the
//! library defines, with the same titles.

#[test]
fn diagnostic_reference_matches_the_code_list() {
    let doc =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/language.md")).unwrap();
    let rows: Vec<(String, String)> = doc
        .lines()
        .filter_map(|l| {
            let cells: Vec<&str> = l.split('|').map(str::trim).collect();
            (cells.len() == 5 && cells[1].len() == 4 && cells[1] != "code")
                .then(|| (cells[1].to_owned(), cells[3].to_owned()))
        })
        .collect();
    let codes: Vec<(String, String)> = btc_pddl::diagnostic::codes::ALL
        .iter()
        .map(|c| (c.id.to_owned(), c.title.to_owned()))
        .collect();
    assert_eq!(rows, codes);
}

/// Text between `<!-- begin -->` and `<!-- end -->` markers, and where.
fn between<'a>(text: &'a str, begin: &str, end: &str) -> (usize, &'a str) {
    let start = text
        .find(begin)
        .unwrap_or_else(|| panic!("{begin} not found"))
        + begin.len();
    let len = text[start..]
        .find(end)
        .unwrap_or_else(|| panic!("{end} not found"));
    (start, &text[start..start + len])
}

/// Replaces the text at `at` with `new` in `path` when regenerating
/// (`BTC_REGENERATE=1`), else fails with the expected text.
fn check_generated(path: &str, text: &str, at: usize, old: &str, new: &str) {
    if old == new {
        return;
    }
    if std::env::var_os("BTC_REGENERATE").is_some() {
        let updated = format!("{}{new}{}", &text[..at], &text[at + old.len()..]);
        std::fs::write(path, updated).unwrap();
        return;
    }
    panic!(
        "{path} is out of date with the node vocabulary (ir/src/vocab.rs); \
         run `BTC_REGENERATE=1 cargo test --test docs` to regenerate it.\nexpected:\n{new}"
    );
}

/// The node table of `docs/language.md` is the vocabulary's.
#[test]
fn node_table_matches_the_vocabulary() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/docs/language.md");
    let doc = std::fs::read_to_string(path).unwrap();
    let (at, old) = between(
        &doc,
        "<!-- node-vocabulary:begin -->\n",
        "<!-- node-vocabulary:end -->",
    );
    check_generated(path, &doc, at, old, &btc_ir::vocab::markdown_table());
}

/// The VS Code grammar highlights the vocabulary's keywords.
#[test]
fn vscode_grammar_matches_the_vocabulary() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/editors/vscode/syntaxes/btrules.tmLanguage.json"
    );
    let grammar = std::fs::read_to_string(path).unwrap();
    let rule = "\"name\": \"keyword.control.template.btrules\",\n          \"match\": \"";
    let (at, old) = between(&grammar, rule, "\"\n");
    let new = btc_ir::vocab::grammar_keyword_pattern();
    check_generated(path, &grammar, at, old, &new);
    // Still JSON, and the pattern is the one written.
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).expect("the grammar is JSON");
    assert!(json.to_string().contains(&new.replace('\\', "\\\\")));
}
