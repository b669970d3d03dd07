//! The files a rules file names: `domain`, `problem` and `import "PATH"`,
//! resolved against the rules file's folder.

use crate::db::{parsed_rules, Db, SourceFile};
use crate::path::FilePath;
use crate::rules::{ImportTarget, Item};
use btc_pddl::source::Span;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum RefKind {
    Domain,
    Problem,
    Import,
}

impl RefKind {
    pub fn noun(self) -> &'static str {
        match self {
            RefKind::Domain => "domain file",
            RefKind::Problem => "problem file",
            RefKind::Import => "import",
        }
    }
}

/// One path a rules file names.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Reference {
    pub kind: RefKind,
    /// As written between the quotes.
    pub written: String,
    /// The path string, absolute in the rules file.
    pub span: Span,
    /// Where it points.
    pub path: FilePath,
}

/// Every path a rules file names, in the order written. Paths with an
/// interpolation (`"{x}.pddl"`) name nothing and are left out.
#[salsa::tracked(returns(ref))]
pub fn references(db: &dyn Db, file: SourceFile) -> Vec<Reference> {
    let from = file.path(db);
    let id = crate::db::file_id(db, file);
    let mut out = Vec::new();
    for n in &parsed_rules(db, file).items {
        let (kind, path) = match &*n.item {
            Item::Domain { path, .. } => (RefKind::Domain, path),
            Item::Problem { path, .. } => (RefKind::Problem, path),
            Item::Import {
                target: ImportTarget::Path { path, .. },
                ..
            } => (RefKind::Import, path),
            _ => continue,
        };
        let Some(written) = path.plain() else {
            continue;
        };
        let Some(target) = from.sibling(&written) else {
            continue;
        };
        out.push(Reference {
            kind,
            written,
            span: Span {
                file: id,
                start: path.span.start + n.offset,
                end: path.span.end + n.offset,
            },
            path: target,
        });
    }
    out
}
