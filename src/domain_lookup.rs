//! Which domain a problem goes with, when no command line or rules file
//! says: one rule for every command (`btc pddl`, `btc run --tree`), said
//! once in docs/language.md ("Which domain").

use btc_pddl::Document;
use std::path::{Path, PathBuf};

/// The domain of a problem `STEM.pddl` that names domain `name`:
/// `STEM-domain.pddl` beside it, else `domain.pddl` beside it, else the
/// first `.pddl` file there (by name) that defines domain `name`.
pub fn beside(problem: &Path, name: &str) -> Option<PathBuf> {
    let dir = problem
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let stem = problem.file_stem()?.to_string_lossy();
    for candidate in [
        dir.join(format!("{stem}-domain.pddl")),
        dir.join("domain.pddl"),
    ] {
        if candidate.is_file() {
            return Some(candidate);
        }
    }
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .ok()?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .collect();
    entries.sort();
    entries.into_iter().find(|p| {
        p.extension().is_some_and(|e| e.eq_ignore_ascii_case("pddl"))
            && btc_files::read(p, btc_pddl::source::MAX_FILE_BYTES).is_ok_and(|bytes| {
                let text = btc_pddl::source::decode(&bytes).0;
                matches!(btc_pddl::parse_document(&text, 0).0, Some(Document::Domain(d)) if d.name.name == name)
            })
    })
}

/// [`beside`] for a problem given as its text (the domain name is read
/// from its `(:domain ...)`).
pub fn for_problem(problem: &Path, text: &str) -> Option<PathBuf> {
    match btc_pddl::parse_document(text, 0).0 {
        Some(Document::Problem(p)) => beside(problem, &p.domain.name),
        _ => None,
    }
}
