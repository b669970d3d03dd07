//! `btc pddl FILE...`: parse and check domains and problems.

use crate::stdout::outln;
use crate::{domain_lookup, files, report, Format};
use btc_pddl::diagnostic::{codes, Diagnostic};
use btc_pddl::pipeline::{domain_unit, problem_unit, DomainUnit};
use btc_pddl::source::Sources;
use btc_pddl::{self as pddl, Document};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

pub fn run(
    paths: &[PathBuf],
    domain: Option<&Path>,
    json: bool,
    format: Format,
) -> anyhow::Result<ExitCode> {
    let mut sources = Sources::new();
    let mut all_diags: Vec<Diagnostic> = Vec::new();
    let mut models = Vec::new();
    let mut summaries = Vec::new();
    let mut explicit: Option<DomainUnit> = None;
    if let Some(path) = domain {
        let id = files::load(&mut sources, path, &mut all_diags)?;
        let unit = domain_unit(&sources, id);
        all_diags.extend(unit.diagnostics.iter().cloned());
        explicit = Some(unit);
    }
    // The domains found beside problems, each loaded once; one the command
    // line lists reports its diagnostics as its own file only.
    let listed: Vec<PathBuf> = paths.iter().map(|p| same_file(p)).collect();
    let mut found: Vec<(PathBuf, DomainUnit)> = Vec::new();
    for path in paths {
        let mut diags = Vec::new();
        let id = files::load(&mut sources, path, &mut diags)?;
        let (doc, _) = pddl::parse_document(sources.text(id), id);
        let summary = match doc {
            Some(Document::Domain(_)) | None => {
                let unit = domain_unit(&sources, id);
                diags.extend(unit.diagnostics.iter().cloned());
                if let Some(d) = &unit.domain {
                    if json {
                        models.push(
                            serde_json::json!({ "file": path, "kind": "domain", "model": d }),
                        );
                    }
                    format!(
                        "domain {}: {}, {}, {}",
                        d.name.name,
                        report::plural(d.types.len(), "type"),
                        report::plural(d.predicates.len(), "predicate"),
                        report::plural(d.actions.len(), "action")
                    )
                } else {
                    "not a PDDL domain or problem".to_owned()
                }
            }
            Some(Document::Problem(p)) => {
                let du = match &explicit {
                    Some(u) => Some(u),
                    None => match domain_lookup::beside(path, &p.domain.name) {
                        Some(dpath) => {
                            let key = same_file(&dpath);
                            if !found.iter().any(|(k, _)| *k == key) {
                                // A domain the command line does not list is
                                // reported here once, in its own line: its
                                // errors are not the problem's.
                                let mut ddiags = Vec::new();
                                let did = files::load(&mut sources, &dpath, &mut ddiags)?;
                                let u = domain_unit(&sources, did);
                                if !listed.contains(&key) {
                                    ddiags.extend(u.diagnostics.iter().cloned());
                                    let (e, w) = report::count(&ddiags);
                                    summaries.push(format!(
                                        "{}: the domain of {}; {}, {}",
                                        dpath.display(),
                                        path.display(),
                                        report::plural(e, "error"),
                                        report::plural(w, "warning")
                                    ));
                                    all_diags.extend(ddiags);
                                }
                                found.push((key.clone(), u));
                            }
                            found.iter().find(|(k, _)| *k == key).map(|(_, u)| u)
                        }
                        None => None,
                    },
                };
                match du {
                    Some(du) => {
                        let pu = problem_unit(&sources, id, du);
                        diags.extend(pu.diagnostics.iter().cloned());
                    }
                    None => {
                        diags.extend(pddl::parse_problem(sources.text(id), id).1);
                        diags.push(
                            Diagnostic::error(codes::DOMAIN_MISMATCH, p.domain.span, format!("cannot find domain `{}` to check this problem against", p.domain.name))
                                .with_hint("pass it with `--domain FILE`, or put it beside the problem as `domain.pddl`"),
                        );
                    }
                }
                if json {
                    models.push(serde_json::json!({ "file": path, "kind": "problem", "model": p }));
                }
                format!(
                    "problem {} (domain {}): {}, {}",
                    p.name.name,
                    p.domain.name,
                    report::plural(p.objects.len(), "object"),
                    report::plural(p.init.len(), "initial fact")
                )
            }
        };
        let (e, w) = report::count(&diags);
        summaries.push(format!(
            "{}: {summary}; {}, {}",
            path.display(),
            report::plural(e, "error"),
            report::plural(w, "warning")
        ));
        all_diags.extend(diags);
    }
    let diag_json = report::diagnostics(&all_diags, &sources, format);
    let failed = all_diags.iter().any(Diagnostic::is_error);
    if json || format == Format::Json {
        let doc = serde_json::json!({
            "ok": !failed,
            "files": if json { serde_json::Value::Array(models) } else { serde_json::Value::Null },
            "summaries": summaries,
            "diagnostics": diag_json,
        });
        outln!("{}", serde_json::to_string_pretty(&doc)?)?;
    } else {
        for s in summaries {
            outln!("{s}")?;
        }
    }
    Ok(if failed {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    })
}

/// A path as the file it names, to tell two spellings of one file apart.
fn same_file(p: &Path) -> PathBuf {
    std::fs::canonicalize(p).unwrap_or_else(|_| p.to_path_buf())
}
