//! The `.btrules` parser. The token stream is first cut into top-level items
//! (at item keywords outside brackets, or at the start of a line), and each
//! item is parsed on its own with spans relative to its start: a broken item
//! becomes [`Item::Error`] and the others still parse.

mod grammar;
mod items;
mod run;
mod strings;
mod template;
#[cfg(test)]
mod tests;
mod tokens;

use run::parse_item;
pub use run::quick_and_rich_disagree;
use tokens::Cutter;

use super::ast::*;
use super::lexer::{lex, lex_each, Comment, Tok};
use btc_ir::vocab::{Arity, ControlName, NodeSpec};
use btc_pddl::diagnostic::{codes, Diagnostic};
use btc_pddl::lexer::{Tok as PTok, Token as PToken};
use btc_pddl::parse::{effect_of, formula_of};
use btc_pddl::sexpr;
use btc_pddl::source::{FileId, Span};
use chumsky::cache::{Cache, Cached};
use chumsky::input::{MappedInput, ValueInput};
use chumsky::prelude::*;
use smol_str::SmolStr;
use std::cell::RefCell;
use std::collections::HashMap;
use std::rc::Rc;

/// Deepest nesting inside one item: brackets, and decorators chained on one
/// template (`inverter retry(3) X()` is three levels), which the parser and
/// every pass after it recurse through.
pub const MAX_ITEM_DEPTH: usize = 64;

/// The vocabulary's entry for a node keyword.
fn node_spec(word: &str) -> Option<&'static NodeSpec> {
    NodeSpec::by_keyword(word)
}

/// How deep an item nests as the parser will recurse: each bracket is a
/// level, and so is each decorator of a chain, until the template the
/// chain decorates ends. Computed on the tokens, before parsing, so that
/// the limit holds for the parser too.
#[derive(Default)]
struct Nesting {
    /// Per open bracket: its kind, and the template depth and chain
    /// outside it.
    open: Vec<(&'static str, usize, usize)>,
    /// Depth of the template being read at the current level.
    base: usize,
    /// Decorators chained on it so far.
    chain: usize,
}

impl Nesting {
    /// The depth after `tokens[i]`.
    fn step(&mut self, tokens: &[(Tok, Span)], i: usize) -> usize {
        let in_block = matches!(self.open.last(), None | Some(("{", _, _)));
        match &tokens[i].0 {
            Tok::Punct(p @ ("(" | "{" | "[")) => {
                let outside = self.base + self.chain;
                self.open.push((p, self.base, self.chain));
                self.base = outside + 1;
                self.chain = 0;
            }
            Tok::Punct(")" | "}" | "]") => {
                let closed = self.open.pop();
                self.base = closed.map_or(0, |(_, b, _)| b);
                // A block ends the template that owns it (and its chain);
                // the parenthesis of `retry(3)` leaves the chain going.
                self.chain = match closed {
                    Some(("(", _, chain)) => chain,
                    _ => 0,
                };
            }
            Tok::Ident(w) if in_block => {
                let next = tokens.get(i + 1).map(|t| &t.0);
                let spec = node_spec(w);
                // Words that make a decorator of the template after them.
                let decorator = spec.filter(|s| s.arity == Arity::One).map(|s| {
                    if s.params.is_empty() {
                        matches!(next, Some(Tok::Ident(_) | Tok::Str(_)))
                    } else {
                        matches!(next, Some(Tok::Punct("(")))
                    }
                });
                if decorator == Some(true) {
                    self.chain += 1;
                } else if spec.is_some_and(|s| s.arity != Arity::One) {
                    // Its block (after `parallel(...)`'s arguments) nests
                    // inside the chain.
                } else if matches!(next, Some(Tok::Punct("("))) || matches!(w.as_str(), "steps") {
                    // A call (or `steps`): the chain ends at this leaf,
                    // after its own argument list.
                    let depth = self.base + self.chain + 1;
                    self.chain = 0;
                    return depth;
                }
            }
            _ => {}
        }
        self.base + self.chain
    }
}

/// Words that start a template: the vocabulary's node keywords, and
/// `steps`.
pub fn template_keywords() -> impl Iterator<Item = &'static str> {
    btc_ir::vocab::NODES
        .iter()
        .map(|s| s.keyword)
        .chain(["steps"])
}

/// Words that start a top-level item.
pub const ITEM_KEYWORDS: &[&str] = &[
    "domain",
    "problem",
    "import",
    "action",
    "condition",
    "tree",
    "table",
    "rule",
    "plan",
];

#[derive(Clone, Debug, PartialEq)]
pub struct ParsedRules {
    pub items: Vec<ItemNode>,
    pub comments: Vec<Comment>,
    /// Syntax diagnostics, with absolute spans.
    pub diagnostics: Vec<Diagnostic>,
}

pub fn parse_rules(text: &str, file: FileId) -> ParsedRules {
    parse_rules_with(text, file, |item| {
        let (item, diagnostics) = parse_item_text(item, file);
        (std::sync::Arc::new(item), diagnostics)
    })
}

/// [`parse_rules`] with each item's text parsed by `parse_item`, which the
/// database memoizes: an edit re-lexes the file to cut it into items but
/// parses only the items whose text changed.
pub fn parse_rules_with(
    text: &str,
    file: FileId,
    mut parse_item: impl FnMut(&str) -> (std::sync::Arc<Item>, Vec<Diagnostic>),
) -> ParsedRules {
    let cut = cut_rules(text, file);
    let parsed: Vec<_> = cut
        .items
        .iter()
        .map(|&(start, end)| parse_item(&text[start as usize..end as usize]))
        .collect();
    assemble(cut, parsed, file)
}

/// A rules file cut into items, before any item is parsed.
#[derive(Clone, Debug, PartialEq)]
pub struct CutRules {
    /// Where each item starts and ends.
    pub items: Vec<(u32, u32)>,
    pub comments: Vec<Comment>,
    /// Lexical diagnostics, with absolute spans.
    pub diagnostics: Vec<Diagnostic>,
}

/// Cuts a rules file into items (see [`Cutter`]).
pub fn cut_rules(text: &str, file: FileId) -> CutRules {
    // Cutting needs only the item keywords' names: the other tokens'
    // names are left unallocated, and the tokens are not kept (each item
    // is lexed again to parse it).
    let mut cut = Cutter::new(text);
    let lexed = lex_each(
        text,
        file,
        &|w| ITEM_KEYWORDS.contains(&w),
        &mut |t, span| cut.token(&t, span),
    );
    CutRules {
        items: cut.finish(),
        comments: lexed.comments,
        diagnostics: lexed.diagnostics,
    }
}

/// A file's parse from its cut and its items' parses, in the cut's order
/// (spans relative to each item, as [`parse_item_text`] gives them).
pub fn assemble(
    cut: CutRules,
    parsed: Vec<(std::sync::Arc<Item>, Vec<Diagnostic>)>,
    file: FileId,
) -> ParsedRules {
    let mut diagnostics = cut.diagnostics;
    let mut items = Vec::with_capacity(cut.items.len());
    for (&(offset, _), (item, diags)) in cut.items.iter().zip(parsed) {
        diagnostics.extend(diags.into_iter().map(|d| shift(d, file, offset)));
        items.push(ItemNode { offset, item });
    }
    ParsedRules {
        items,
        comments: cut.comments,
        diagnostics,
    }
}

/// Parses the text of one item (cut by [`parse_rules_with`]), with spans
/// relative to its start. The item starts with a token, outside any comment
/// or string, so lexing it alone gives the same tokens as in the file; the
/// file's lexer has reported lexical errors already, so these are dropped.
pub fn parse_item_text(text: &str, file: FileId) -> (Item, Vec<Diagnostic>) {
    let mut lexed = lex(text, file);
    parse_item(&mut lexed.tokens, text, 0, file)
}

/// Moves a diagnostic's spans in `file` by `offset` (from item-relative to
/// absolute). Spans in other files (the PDDL domain) are absolute already.
pub fn shift(mut d: Diagnostic, file: FileId, offset: u32) -> Diagnostic {
    let mv = |s: &mut Span| {
        if s.file == file {
            s.start += offset;
            s.end += offset;
        }
    };
    mv(&mut d.span);
    for l in &mut d.labels {
        mv(&mut l.span);
    }
    for f in &mut d.fixes {
        mv(&mut f.span);
    }
    d
}

fn at_line_start(text: &str, offset: u32) -> bool {
    offset == 0 || text.as_bytes().get(offset as usize - 1) == Some(&b'\n')
}

/// A list read by the parser, without the room its growth left (a list
/// of one starts with room for four): an item's tree lives as long as its
/// text is unchanged, and a huge file has tens of thousands of them.
fn exact<T>(mut v: Vec<T>) -> Vec<T> {
    v.shrink_to_fit();
    v
}
