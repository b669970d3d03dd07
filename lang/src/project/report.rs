//! What `btc check`, `btc compile`, `btc run` and the language server
//! report: one list per file of a project, in one order — the rules file
//! (with what it says about the files it names), its imports, the domain,
//! the problem, and for a compile job the plan. The CLI prints the lists
//! one after the other; the language server publishes them per file.

use super::loader::ReadFailure;
use super::refs::references;
use crate::db::{
    checked_domain, checked_problem, domain_file, file_id, import_closure, problem_file,
    rules_diagnostics, CompileJob, Db, ProblemOf, SourceFile,
};
use crate::path::FilePath;
use btc_pddl::diagnostic::{codes, Diagnostic};
use btc_pddl::source::{DecodeProblem, FileId, Span};

/// One file of a project and its diagnostics (some of a rules file's are
/// about places in the PDDL files, e.g. an action no rule covers).
#[derive(Clone, Debug, PartialEq)]
pub struct FileReport {
    pub file: SourceFile,
    pub diagnostics: Vec<Diagnostic>,
}

/// The diagnostic for a file's undecodable bytes.
pub fn decode_diagnostic(id: FileId, problem: &DecodeProblem) -> Diagnostic {
    match *problem {
        DecodeProblem::InvalidUtf8 { offset, byte } => Diagnostic::error(
            codes::FILE_ENCODING,
            Span::new(id, offset, offset + 3),
            format!("this file is not UTF-8: byte 0x{byte:02X} at offset {offset} is not valid"),
        )
        .with_hint("save the file as UTF-8; btc read the rest with the bad bytes replaced"),
        DecodeProblem::BadUtf16 => Diagnostic::error(
            codes::FILE_ENCODING,
            Span::new(id, 0, 0),
            "this file starts with a UTF-16 byte-order mark but is not valid UTF-16",
        )
        .with_hint("save the file as UTF-8"),
        DecodeProblem::TooLarge { bytes } => {
            let max = btc_pddl::source::MAX_FILE_BYTES;
            // A stream that went on past the limit has no known size.
            let message = if bytes == max + 1 {
                format!("this input goes on past {max} bytes, the most btc reads")
            } else {
                format!("this file has {bytes} bytes; btc reads files of at most {max} bytes")
            };
            Diagnostic::error(codes::FILE_TOO_LARGE, Span::new(id, 0, 0), message)
        }
    }
}

/// What was wrong with a file's bytes.
#[salsa::tracked(returns(ref))]
pub fn read_diagnostics(db: &dyn Db, file: SourceFile) -> Vec<Diagnostic> {
    file.decode(db)
        .iter()
        .map(|p| decode_diagnostic(file_id(db, file), p))
        .collect()
}

/// The paths a rules file names that exist but could not be read. (Paths
/// that do not exist are the checker's "cannot find", R017 and R018.)
fn unreadable_references(db: &dyn Db, rules: SourceFile) -> Vec<Diagnostic> {
    let unread = db.workspace().unread(db);
    references(db, rules)
        .iter()
        .filter_map(|r| {
            let (code, reason) = match unread.get(&r.path)? {
                ReadFailure::NotFound => return None,
                ReadFailure::NotAFile { reason } => (codes::FILE_NOT_REGULAR, reason),
                ReadFailure::Unreadable { reason } => (codes::FILE_UNREADABLE, reason),
            };
            Some(Diagnostic::error(
                code,
                r.span,
                format!("cannot read the {} `{}`: {reason}", r.kind.noun(), r.path),
            ))
        })
        .collect()
}

/// The rules file's own list: read problems, unreadable references and
/// the checker's diagnostics, in the checker's order. A file that exists
/// but cannot be read is F001, not also "cannot find" (R017, R018).
fn rules_section(db: &dyn Db, rules: SourceFile) -> FileReport {
    let id = file_id(db, rules);
    let mut diagnostics = read_diagnostics(db, rules).clone();
    let unreadable = unreadable_references(db, rules);
    let inside =
        |d: &Diagnostic, u: &Diagnostic| d.span.start <= u.span.start && u.span.end <= d.span.end;
    let mut checked: Vec<Diagnostic> = rules_diagnostics(db, rules)
        .iter()
        .filter(|d| {
            !([codes::R_NO_DOMAIN.id, codes::R_IMPORT.id].contains(&d.code)
                && unreadable.iter().any(|u| inside(d, u)))
        })
        .cloned()
        .collect();
    checked.extend(unreadable);
    checked.sort_by_key(|d| (d.span.file != id, d.span.start));
    diagnostics.extend(checked);
    FileReport {
        file: rules,
        diagnostics,
    }
}

/// A project's lists, given its domain and problem.
fn sections(
    db: &dyn Db,
    rules: SourceFile,
    domain: Option<SourceFile>,
    problem: Option<SourceFile>,
) -> Vec<FileReport> {
    let mut out = vec![rules_section(db, rules)];
    for f in import_closure(db, rules).0.iter().skip(1) {
        if !matches!(f.path(db), FilePath::Std(_)) {
            out.push(FileReport {
                file: *f,
                diagnostics: read_diagnostics(db, *f).clone(),
            });
        }
    }
    if let Some(d) = domain {
        let mut diagnostics = read_diagnostics(db, d).clone();
        diagnostics.extend(checked_domain(db, d).diagnostics.iter().cloned());
        out.push(FileReport {
            file: d,
            diagnostics,
        });
    }
    if let Some(p) = problem {
        let mut diagnostics = read_diagnostics(db, p).clone();
        if let Some(d) = domain {
            diagnostics.extend(
                checked_problem(db, ProblemOf::new(db, p, d))
                    .diagnostics
                    .iter()
                    .cloned(),
            );
        }
        out.push(FileReport {
            file: p,
            diagnostics,
        });
    }
    out
}

/// `btc check RULES` and the language server: the rules file with the
/// domain and problem it names.
#[salsa::tracked(returns(ref))]
pub fn project_report(db: &dyn Db, rules: SourceFile) -> Vec<FileReport> {
    sections(db, rules, domain_file(db, rules), problem_file(db, rules))
}

/// A compile job: the rules file with the job's domain and problem (given,
/// or named by the rules file), and the plan.
#[salsa::tracked(returns(ref))]
pub fn job_report(db: &dyn Db, job: CompileJob) -> Vec<FileReport> {
    let rules = job.rules(db);
    let domain = crate::db::job_domain(db, job);
    let problem = crate::db::job_problem(db, job);
    let mut out = sections(db, rules, domain, problem);
    let plan = job.plan(db);
    let mut diagnostics = read_diagnostics(db, plan).clone();
    if domain.is_some() && problem.is_none() {
        diagnostics.push(
            Diagnostic::error(
                codes::R_NO_DOMAIN,
                Span::new(file_id(db, plan), 0, 0),
                "compiling a plan needs the PDDL problem it solves",
            )
            .with_hint(
                "pass `--problem FILE`, name it in the rules file (`problem \"problem.pddl\"`), or put `PLAN-STEM.pddl` beside the plan",
            ),
        );
    } else {
        diagnostics.extend(super::misfit::plan_diagnostics(db, job).iter().cloned());
        diagnostics.extend(
            super::concurrent::in_order_diagnostics(db, job)
                .iter()
                .cloned(),
        );
    }
    out.push(FileReport {
        file: plan,
        diagnostics,
    });
    out
}

/// Every list, one after the other.
pub fn flatten(reports: &[FileReport]) -> Vec<Diagnostic> {
    reports
        .iter()
        .flat_map(|r| r.diagnostics.iter().cloned())
        .collect()
}
