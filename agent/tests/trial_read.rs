//! The trial reader on files that do not fit the ARIAC 2023 format: every
//! problem gets a code and a line and column, none stops the others.

use btc_agent::trial;
use btc_pddl::render;
use btc_pddl::source::Sources;

fn diagnostics(path: &std::path::Path) -> (bool, String) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut sources = Sources::new();
    let name = path.file_name().unwrap().to_string_lossy().into_owned();
    let id = sources.add(name, text.clone());
    let (t, diags) = trial::read(&text, id);
    let out: Vec<String> = diags
        .iter()
        .map(|d| render::to_short(d, &sources))
        .collect();
    (t.is_some(), out.join("\n") + "\n")
}

#[test]
fn bad_trial_files_get_a_diagnostic_for_each_problem() {
    insta::glob!("fixtures/trials/*.yaml", |path| {
        let (read, out) = diagnostics(path);
        insta::assert_snapshot!(format!("read: {read}\n{out}"));
    });
}
