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
