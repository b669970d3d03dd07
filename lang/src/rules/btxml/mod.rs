//! BehaviorTree.CPP v4 tree files a rules file imports (`import "move.xml"
//! as Move`, PlanSys2's per-action trees): each `<BehaviorTree>` read once
//! into the rules' own templates, so every emitter and btc's engine get the
//! imported tree through the same lowering as a `tree` of the rules.
//!
//! Reading (`read`) depends on the file alone: elements become templates
//! with spans into the XML, `{key}` attribute values become variables, a
//! `<SubTree>` becomes a call marked as one, and what btc cannot carry is
//! refused (R072) rather than approximated. Typing (`typing`) depends on the
//! importing file's declarations: a tree's ports are the blackboard keys it
//! reads, typed by the ports of the nodes (or trees) they are bound to.

mod read;
mod typing;

pub use read::{has_trees, read_trees};
pub use typing::{imported_trees, tree_names};

use super::ast::{Ident, Template};
use btc_pddl::diagnostic::Diagnostic;
use btc_pddl::source::Span;

/// The name a `<SubTree ID="X">` call carries until typing names the tree
/// it calls: `SubTree:X`, which no rules name can spell.
pub const SUBTREE_PREFIX: &str = "SubTree:";

/// The argument that stands for `_autoremap="true"` on a `<SubTree>` until
/// typing turns it into one argument per port of the called tree.
pub const AUTOREMAP: &str = "_autoremap";

/// One `<BehaviorTree ID="...">`.
#[derive(Clone, Debug, PartialEq)]
pub struct XmlTree {
    /// The `ID` as written, at its value in the XML.
    pub id: Ident,
    pub body: Vec<Template>,
    /// The `<BehaviorTree` element's opening tag.
    pub span: Span,
}

/// A BT.CPP file's trees and what is wrong with them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct XmlTrees {
    pub trees: Vec<XmlTree>,
    /// `main_tree_to_execute` on `<root>`, when it names a tree of the file.
    pub main: Option<String>,
    pub diagnostics: Vec<Diagnostic>,
}

impl XmlTrees {
    /// The tree an `as` name stands for: the `main_tree_to_execute`, or the
    /// only tree of the file.
    pub fn main_tree(&self) -> Option<&XmlTree> {
        match &self.main {
            Some(m) => self.trees.iter().find(|t| &t.id.text == m),
            None if self.trees.len() == 1 => self.trees.first(),
            None => None,
        }
    }
}
