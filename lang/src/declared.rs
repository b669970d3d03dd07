//! The leaf nodes a rules file declares (its own and its imports'), for
//! code generators such as the C++ executor (`btc executor`): each with its
//! IR model, the span of its declaration and the stdlib module it comes
//! from, if any. The first declaration of a name wins, as in checking.

use crate::db::{file_id, import_closure, parsed_rules, Db, SourceFile};
use crate::lower::node_model;
use crate::rules::ast::Item;
use btc_ir::NodeModel;
use btc_pddl::source::Span;

#[derive(Clone, Debug, PartialEq)]
pub struct DeclaredNode {
    pub model: NodeModel,
    /// The node's name in its declaration, with an absolute span.
    pub span: Span,
    /// `Some("btcpp")` for a declaration of `std::btcpp`.
    pub stdlib: Option<String>,
}

/// Every node visible in `file`, in the order of the import closure (the
/// file's own declarations first).
pub fn declared_nodes(db: &dyn Db, file: SourceFile) -> Vec<DeclaredNode> {
    let mut out: Vec<DeclaredNode> = Vec::new();
    for &f in &import_closure(db, file).0 {
        let path = f.path(db);
        let stdlib = match path {
            crate::path::FilePath::Std(module) => Some(module.clone()),
            crate::path::FilePath::Disk(_) => None,
        };
        let fid = file_id(db, f);
        for n in &parsed_rules(db, f).items {
            let Item::Node(decl) = &*n.item else { continue };
            if out.iter().any(|d| d.model.id == decl.name.text) {
                continue;
            }
            let mut span = decl.name.span;
            if span.file == fid {
                span.start += n.offset;
                span.end += n.offset;
            }
            out.push(DeclaredNode {
                model: node_model(&decl.name.text, decl),
                span,
                stdlib: stdlib.clone(),
            });
        }
    }
    out
}
