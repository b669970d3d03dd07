//! `btc init` (a starter rules file from a domain) and `btc stubs` (rule
//! stubs appended to an existing file): both write `btc_lang::stubs`.

use crate::{files, report, Format};
use btc_lang::db::{Database, SourceFile};
use btc_lang::path::FilePath;
use btc_lang::project;
use btc_lang::stubs;
use btc_pddl::diagnostic::has_errors;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Prints every file's diagnostics of the project `rules` heads; whether
/// any is an error.
fn report_errors(db: &Database, rules: SourceFile) -> bool {
    let diags = project::flatten(project::project_report(db, rules));
    let sources = db.sources_for(&diags);
    report::diagnostics(&diags, &sources, Format::Text);
    has_errors(&diags)
}

/// `btc init DOMAIN [PROBLEM] [-o RULES]`: writes a rules file with a rule
/// per action of the domain, after checking it the way `btc check` would.
/// An existing file is never overwritten.
pub fn init(
    domain: &Path,
    problem: Option<&Path>,
    output: Option<&Path>,
) -> anyhow::Result<ExitCode> {
    let out: PathBuf = match output {
        Some(o) => o.to_path_buf(),
        None => domain
            .parent()
            .unwrap_or(Path::new(""))
            .join("rules.btrules"),
    };
    if out.exists() {
        anyhow::bail!(
            "`{}` exists; btc init never overwrites a file: `btc stubs {}` adds rules for the actions it lacks",
            out.display(),
            out.display()
        );
    }
    // Paths in a rules file are relative to it.
    let dir = out.parent().unwrap_or(Path::new(""));
    let relative = |p: &Path| crate::paths::text(&crate::paths::relative_to(p, dir));
    let head = stubs::starter_head(&relative(domain), problem.map(relative).as_deref());
    let mut db = Database::new();
    let path = FilePath::new(&out);
    let file = db.set_file(&path, head.clone());
    project::load_references(&mut db, &files::Disk, file);
    let Some(stubs) = stubs::missing(&db, file) else {
        // An unusable domain, or one without actions: say what is wrong.
        if report_errors(&db, file) {
            return Ok(ExitCode::from(1));
        }
        anyhow::bail!(
            "the domain `{}` has no actions to write rules for",
            domain.display()
        );
    };
    let text = format!("{head}{}", stubs.text);
    let file = db.set_file(&path, text.clone());
    // What is written checks clean; a problem file with errors is reported
    // and nothing is written.
    if report_errors(&db, file) {
        return Ok(ExitCode::from(1));
    }
    files::write_atomically(&out, &text)?;
    eprintln!(
        "wrote {}: {} for the domain's actions; next: `btc check {}`",
        out.display(),
        report::plural(stubs.actions.len(), "rule"),
        out.display()
    );
    Ok(ExitCode::SUCCESS)
}

/// `btc stubs RULES`: appends a rule stub for each domain action no rule
/// covers; the file's own bytes are kept as they are.
pub fn stubs(rules: &Path) -> anyhow::Result<ExitCode> {
    let mut db = Database::new();
    let file = crate::rules_cmd::load_rules(&mut db, rules)?;
    let Some(stubs) = stubs::missing(&db, file) else {
        if report_errors(&db, file) {
            return Ok(ExitCode::from(1));
        }
        eprintln!("{}: every domain action has a rule", rules.display());
        return Ok(ExitCode::SUCCESS);
    };
    let bytes = btc_files::read(rules, btc_pddl::source::MAX_FILE_BYTES)
        .map_err(|e| anyhow::anyhow!("cannot read `{}`: {e}", rules.display()))?;
    let text = file.text(&db);
    // Appended as they are only to bytes that are the text (after a BOM):
    // UTF-16 would need re-encoding, which btc does not do to a user's file.
    let plain = match bytes.len().checked_sub(text.len()) {
        Some(bom @ (0 | 3)) => bytes[bom..] == *text.as_bytes(),
        _ => false,
    };
    if !plain {
        anyhow::bail!(
            "`{}` is not UTF-8: save it as UTF-8 to add stubs to it",
            rules.display()
        );
    }
    let addition = if text.contains("\r\n") {
        stubs.text.replace('\n', "\r\n")
    } else {
        stubs.text
    };
    let mut updated = bytes;
    updated.extend_from_slice(addition.as_bytes());
    files::write_bytes_atomically(rules, &updated)?;
    eprintln!(
        "{}: added {} ({})",
        rules.display(),
        report::plural(stubs.actions.len(), "rule stub"),
        stubs.actions.join(", ")
    );
    Ok(ExitCode::SUCCESS)
}
