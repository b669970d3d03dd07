//! `btc executor RULES -o DIR`: the C++ executor for BehaviorTree.CPP.

use crate::stdout::outln;
use crate::{files, report, rules_cmd, Format};
use btc_emit::executor::{self, Owner, Spec};
use btc_lang::db::{self, Database};
use btc_lang::declared::declared_nodes;
use btc_pddl::diagnostic::{codes, has_errors, Diagnostic};
use btc_pddl::source::{FileId, Sources, Span};
use std::path::Path;
use std::process::ExitCode;

/// The id the user's `nodes.hpp` gets in the rendered sources (past any
/// the database hands out).
const USER_FILE: FileId = FileId::MAX - 1;

pub struct Args<'a> {
    pub rules: &'a Path,
    pub out: &'a Path,
    pub name: Option<&'a str>,
    /// Write nothing; exit 1 when something is out of date.
    pub check: bool,
    pub format: Format,
}

fn print(diags: &[Diagnostic], sources: &Sources, format: Format, ok: bool) -> anyhow::Result<()> {
    let json = report::diagnostics(diags, sources, format);
    if format == Format::Json {
        outln!(
            "{}",
            serde_json::to_string_pretty(&serde_json::json!({ "ok": ok, "diagnostics": json }))
                .unwrap_or_default()
        )?;
    }
    Ok(())
}

/// The namespace: given, or the rules file's folder name.
fn namespace(a: &Args) -> String {
    let folder = std::fs::canonicalize(a.rules).ok().and_then(|p| {
        p.parent()
            .and_then(|d| d.file_name())
            .map(|n| n.to_string_lossy().into_owned())
    });
    executor::namespace_for(
        a.name
            .map(str::to_owned)
            .or(folder)
            .as_deref()
            .unwrap_or("btc"),
    )
}

/// The C003 warnings for the user's classes that lost their base.
fn stale_classes(update: &executor::UserUpdate, existing: &str) -> Vec<Diagnostic> {
    update
        .stale
        .iter()
        .map(|(class, range)| {
            Diagnostic::warning(
                codes::C_STALE_CLASS,
                Span::new(USER_FILE, range.start, range.end),
                format!(
                    "`{class}` derives from `{}`, which btc no longer generates: the rules do not declare `{class}` any more",
                    &existing[range.clone()]
                ),
            )
            .with_hint(format!(
                "delete the class `{class}` from {}, or declare the node in the rules again",
                executor::USER_NODES
            ))
        })
        .collect()
}

pub fn run(a: &Args) -> anyhow::Result<ExitCode> {
    let mut database = Database::new();
    let mut diags = Vec::new();
    let file = rules_cmd::load_rules(&mut database, a.rules)?;
    diags.extend(
        btc_lang::project::report::read_diagnostics(&database, file)
            .iter()
            .cloned(),
    );
    diags.extend(db::rules_diagnostics(&database, file).iter().cloned());
    let nodes: Vec<_> = declared_nodes(&database, file)
        .into_iter()
        // BT.CPP's own leaves and btc's KB nodes are registered already.
        .filter(|d| !matches!(d.stdlib.as_deref(), Some("btcpp" | "kb")))
        .collect();
    let with_spans: Vec<_> = nodes.iter().map(|d| (&d.model, d.span)).collect();
    diags.extend(executor::check(&with_spans));
    let mut sources = database.sources();
    if has_errors(&diags) {
        print(&diags, &sources, a.format, false)?;
        return Ok(ExitCode::from(1));
    }
    let name = namespace(a);
    let models: Vec<_> = nodes.iter().map(|d| d.model.clone()).collect();
    let rules_text = a.rules.display().to_string();
    let spec = Spec {
        name: &name,
        rules: &rules_text,
        nodes: &models,
    };
    if !a.check {
        std::fs::create_dir_all(a.out)
            .map_err(|e| anyhow::anyhow!("cannot create `{}`: {e}", a.out.display()))?;
    }
    let mut changed: Vec<String> = Vec::new();
    let mut user_note = String::new();
    for f in executor::files(&spec) {
        let path = a.out.join(&f.path);
        let text = match f.owner {
            Owner::Btc => Some(f.text),
            Owner::User if !path.exists() => {
                user_note = format!(
                    "{}: written (yours from now on: btc never overwrites it)",
                    f.path
                );
                Some(f.text)
            }
            Owner::User => {
                let existing = std::fs::read_to_string(&path)
                    .map_err(|e| anyhow::anyhow!("cannot read `{}`: {e}", path.display()))?;
                let update = executor::update_user_nodes(&existing, &spec);
                user_note = match &update.text {
                    Some(_) => format!(
                        "{}: kept, classes appended for {}",
                        f.path,
                        update
                            .added
                            .iter()
                            .map(|a| format!("`{a}`"))
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                    None => format!("{}: kept as it is", f.path),
                };
                let stale = stale_classes(&update, &existing);
                if !stale.is_empty() {
                    sources.insert(USER_FILE, path.display().to_string(), existing);
                    diags.extend(stale);
                }
                update.text
            }
        };
        let Some(text) = text else { continue };
        if std::fs::read_to_string(&path).is_ok_and(|old| old == text) {
            continue;
        }
        changed.push(f.path.clone());
        if !a.check {
            if let Some(dir) = path.parent() {
                std::fs::create_dir_all(dir)
                    .map_err(|e| anyhow::anyhow!("cannot create `{}`: {e}", dir.display()))?;
            }
            files::write_atomically(&path, &text)?;
        }
    }
    print(&diags, &sources, a.format, true)?;
    if a.format == Format::Text {
        let verb = if a.check { "out of date" } else { "wrote" };
        if changed.is_empty() {
            eprintln!("{}: up to date with {}", a.out.display(), a.rules.display());
        } else {
            eprintln!(
                "{verb} in {}: {} ({}; namespace `{name}`, executable `{name}_executor`)",
                a.out.display(),
                changed.join(", "),
                report::plural(models.len(), "node")
            );
        }
        if !user_note.is_empty() && !a.check {
            eprintln!("  {user_note}");
        }
    }
    Ok(if a.check && !changed.is_empty() {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    })
}
