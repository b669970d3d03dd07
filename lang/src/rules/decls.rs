//! What a rules file is checked against: the declarations it sees
//! ([`Decls`]) and the PDDL side ([`DomainCtx`]). The checker, the
//! reachability of rules and the file-level checks all read them.

use super::actions::ActionIndex;
use super::ast::*;
use btc_pddl::ast::{Domain, Formula};
use btc_pddl::check::{DomainIndex, ProblemIndex};
use std::collections::BTreeMap;

/// Declarations visible in a rules file: its own, its imports' and the
/// standard library's. The first declaration of a name wins.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Decls {
    pub nodes: BTreeMap<String, NodeDecl>,
    pub trees: BTreeMap<String, TreeDecl>,
    pub tables: BTreeMap<String, TableDecl>,
    /// The names of the trees read from imported BT.CPP XML files, in
    /// `trees` with them; their bodies are checked with the importing file.
    pub imported: Vec<String>,
}

impl Decls {
    pub fn add_items(&mut self, items: &[ItemNode]) {
        for i in items {
            match &*i.item {
                Item::Node(n) => {
                    self.nodes
                        .entry(n.name.text.clone())
                        .or_insert_with(|| n.clone());
                }
                Item::Tree(t) => {
                    self.trees
                        .entry(t.name.text.clone())
                        .or_insert_with(|| t.clone());
                }
                Item::Table(t) => {
                    self.tables
                        .entry(t.name.text.clone())
                        .or_insert_with(|| t.clone());
                }
                _ => {}
            }
        }
    }

    /// Trees of an imported BT.CPP file, after the rules' own declarations
    /// (which win a name both have).
    pub fn add_imported(&mut self, trees: Vec<TreeDecl>) {
        for t in trees {
            if !self.trees.contains_key(&t.name.text) {
                self.imported.push(t.name.text.clone());
                self.trees.insert(t.name.text.clone(), t);
            }
        }
    }

    /// The ports of a callable: a node's or a tree's.
    pub fn ports(&self, name: &str) -> Option<&[PortDecl]> {
        self.nodes
            .get(name)
            .map(|n| n.ports.as_slice())
            .or_else(|| self.trees.get(name).map(|t| t.ports.as_slice()))
    }

    pub(crate) fn callables(&self) -> impl Iterator<Item = &str> {
        self.nodes
            .keys()
            .chain(self.trees.keys())
            .map(String::as_str)
    }
}

/// The PDDL side a rules file is checked against.
#[derive(Clone, Copy)]
pub struct DomainCtx<'a> {
    pub domain: &'a Domain,
    pub index: &'a DomainIndex,
    pub problem: Option<&'a ProblemIndex>,
    /// The domain's action names, indexed for patterns.
    pub actions: &'a ActionIndex,
}

pub const BASIC_TYPES: &[&str] = &["string", "int", "float", "bool"];

/// The formula a condition node is defined by, if any (for the runtime).
pub fn condition_formula<'a>(decls: &'a Decls, name: &str) -> Option<&'a Formula> {
    decls.nodes.get(name).and_then(|n| n.formula.as_ref())
}
