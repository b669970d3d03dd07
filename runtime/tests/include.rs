//! `<include path="...">` (`btc_runtime::include`): trees of other files,
//! paths relative to the including file, cycles, missing files, duplicate
//! trees and chains deeper than `include::MAX_DEPTH` refused with the file
//! the error is in. Fixtures: `tests/fixtures/include/`.

use btc_runtime::include::{self, Located, Opened, MAX_DEPTH};
use btc_runtime::{Engine, Options, Status, TreeDoc};
use std::path::{Path, PathBuf};

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/include")
}

/// Loads `path`; files are numbered in the order they are read, `names`
/// holds their paths.
fn load(path: &Path, names: &mut Vec<PathBuf>) -> Result<TreeDoc, Located<usize>> {
    let text = std::fs::read_to_string(path).unwrap();
    names.push(path.to_path_buf());
    let mut open = |p: &Path| -> Result<Opened<usize>, String> {
        let text = std::fs::read_to_string(p).map_err(|e| e.to_string())?;
        names.push(p.to_path_buf());
        Ok(Opened {
            file: names.len() - 1,
            text,
        })
    };
    include::load(path, Opened { file: 0, text }, &mut open)
}

fn refused(name: &str) -> (String, String, PathBuf) {
    let mut names = Vec::new();
    let err = load(&fixtures().join(name), &mut names).unwrap_err();
    let file = names[err.file].clone();
    (err.error.code.id.to_owned(), err.error.message, file)
}

#[test]
fn included_trees_run_with_paths_relative_to_each_file() {
    let mut names = Vec::new();
    let doc = load(&fixtures().join("main.xml"), &mut names).unwrap();
    // main.xml, then parts/pick.xml, then ../count.xml from there.
    let shown: Vec<String> = names
        .iter()
        .map(|p| {
            p.strip_prefix(fixtures())
                .unwrap()
                .to_string_lossy()
                .into_owned()
        })
        .collect();
    assert_eq!(shown, ["main.xml", "parts/pick.xml", "parts/../count.xml"]);
    let ids: Vec<&str> = doc.trees.iter().map(|(id, _)| id.as_str()).collect();
    assert_eq!(ids, ["Main", "Pick", "Count"]);
    assert_eq!(doc.main, "Main");
    let mut e = Engine::build(&doc, None, Options::default()).unwrap();
    assert_eq!(e.run(100, |_| {}), Status::Success);
}

#[test]
fn a_file_that_includes_itself_is_refused_naming_the_cycle() {
    let (code, message, file) = refused("cycle_a.xml");
    assert_eq!(code, "X043");
    assert_eq!(
        message,
        "<include path=\"./cycle_a.xml\">: `cycle_a.xml` includes itself (cycle_a.xml -> cycle_b.xml -> cycle_a.xml)"
    );
    assert!(file.ends_with("cycle_b.xml"), "{}", file.display());
}

#[test]
fn a_missing_file_is_refused_naming_it() {
    let (code, message, file) = refused("missing.xml");
    assert_eq!(code, "X042");
    assert!(
        message.starts_with("<include path=\"parts/nowhere.xml\">: `")
            && message.contains("parts/nowhere.xml` cannot be read"),
        "{message}"
    );
    assert!(file.ends_with("missing.xml"));
}

#[test]
fn an_error_in_an_included_file_is_reported_in_that_file() {
    let (code, message, file) = refused("bad_inner.xml");
    assert_eq!(code, "X003");
    assert!(message.contains("num_cycles"), "{message}");
    assert!(file.ends_with("parts/broken.xml"), "{}", file.display());
}

#[test]
fn a_script_that_does_not_parse_in_an_included_file_is_reported_at_its_attribute_there() {
    let mut names = Vec::new();
    let err = load(&fixtures().join("bad_script_inner.xml"), &mut names).unwrap_err();
    let file = &names[err.file];
    assert!(file.ends_with("parts/bad_script.xml"), "{}", file.display());
    assert_eq!(err.error.code.id, "X040");
    let text = std::fs::read_to_string(file).unwrap();
    let at = err.error.offset.unwrap();
    assert!(text[at..].starts_with("_skipIf="), "{}", &text[at..]);
}

#[test]
fn a_tree_defined_twice_across_files_is_refused() {
    let (code, message, _) = refused("twice.xml");
    assert_eq!(code, "X001");
    assert_eq!(
        message,
        "<include path=\"count.xml\">: the tree `Count` it defines is defined already"
    );
}

#[test]
fn includes_nest_at_most_max_depth_files() {
    // A chain of files, each including the next: one more than the limit.
    let dir = btc_testkit::target_dir("include-depth");
    std::fs::create_dir_all(&dir).unwrap();
    let n = MAX_DEPTH + 1;
    for k in 0..n {
        let inc = if k + 1 < n {
            format!(r#"<include path="f{}.xml"/>"#, k + 1)
        } else {
            String::new()
        };
        let text = format!(
            r#"<root BTCPP_format="4" main_tree_to_execute="T{k}">{inc}<BehaviorTree ID="T{k}"><AlwaysSuccess/></BehaviorTree></root>"#
        );
        std::fs::write(dir.join(format!("f{k}.xml")), text).unwrap();
    }
    let mut names = Vec::new();
    let err = load(&dir.join("f0.xml"), &mut names).unwrap_err();
    assert_eq!(err.error.code.id, "X043");
    assert_eq!(
        err.error.message,
        format!(
            "<include path=\"f{MAX_DEPTH}.xml\">: includes nest more than {MAX_DEPTH} files deep"
        )
    );
    // One fewer is read whole.
    let mut names = Vec::new();
    let doc = load(&dir.join("f1.xml"), &mut names).unwrap();
    assert_eq!(doc.trees.len(), MAX_DEPTH);
}

#[test]
fn a_tree_read_as_text_refuses_includes() {
    let text = std::fs::read_to_string(fixtures().join("main.xml")).unwrap();
    let err = btc_runtime::xml::parse(&text).unwrap_err();
    assert_eq!(err.code.id, "X042");
}
