//! The PDDL files a rules file names, and the domain and problem parsed
//! and checked.

use super::*;

/// Resolves a path written in a rules file (relative to that file).
pub(crate) fn resolve(db: &dyn Db, from: SourceFile, written: &str) -> Option<SourceFile> {
    let path = from.path(db).sibling(written)?;
    db.workspace().files(db).get(&path).copied()
}

/// The path a rules file gives for its domain (or problem), as written.
pub fn declared_path(db: &dyn Db, file: SourceFile, problem: bool) -> Option<(String, Span, u32)> {
    parsed_rules(db, file)
        .items
        .iter()
        .find_map(|n| match &*n.item {
            Item::Domain { path, span } if !problem => path.plain().map(|p| (p, *span, n.offset)),
            Item::Problem { path, span } if problem => path.plain().map(|p| (p, *span, n.offset)),
            _ => None,
        })
}

#[salsa::tracked(returns(copy))]
pub fn domain_file(db: &dyn Db, rules: SourceFile) -> Option<SourceFile> {
    let (path, _, _) = declared_path(db, rules, false)?;
    resolve(db, rules, &path)
}

#[salsa::tracked(returns(copy))]
pub fn problem_file(db: &dyn Db, rules: SourceFile) -> Option<SourceFile> {
    let (path, _, _) = declared_path(db, rules, true)?;
    resolve(db, rules, &path)
}

/// A PDDL domain parsed and checked.
#[derive(Clone, Debug, PartialEq)]
pub struct CheckedDomain {
    pub domain: Option<Domain>,
    pub index: DomainIndex,
    pub diagnostics: Vec<Diagnostic>,
}

#[salsa::tracked(returns(ref))]
pub fn checked_domain(db: &dyn Db, file: SourceFile) -> CheckedDomain {
    let u = domain_unit_from(file.text(db), file_id(db, file));
    CheckedDomain {
        domain: u.domain,
        index: u.index,
        diagnostics: u.diagnostics,
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct CheckedProblem {
    pub problem: Option<Problem>,
    pub index: ProblemIndex,
    pub diagnostics: Vec<Diagnostic>,
}

/// A problem checked against a domain. (Inputs are salsa structs, so the
/// pair is interned.)
#[salsa::interned(debug)]
pub struct ProblemOf<'db> {
    #[returns(copy)]
    pub problem: SourceFile,
    #[returns(copy)]
    pub domain: SourceFile,
}

#[salsa::tracked(returns(ref))]
pub fn checked_problem<'db>(db: &'db dyn Db, pair: ProblemOf<'db>) -> CheckedProblem {
    let d = checked_domain(db, pair.domain(db));
    let (file, id) = (pair.problem(db), file_id(db, pair.problem(db)));
    let u = match file.value(db) {
        Some(FileValue::Problem(w)) => btc_pddl::pipeline::problem_unit_of(
            Some(w.problem(id)),
            Vec::new(),
            id,
            d.domain.as_ref(),
            &d.index,
        ),
        _ => problem_unit_from(file.text(db), id, d.domain.as_ref(), &d.index),
    };
    CheckedProblem {
        problem: u.problem,
        index: u.index,
        diagnostics: u.diagnostics,
    }
}
