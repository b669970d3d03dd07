//! What a position in a rules file points at, worked out from the tokens
//! (which exist for any text, however broken) and the parsed items (where
//! they parsed). Hover, go-to-definition, references, rename, completion
//! and semantic tokens all start here.

use btc_lang::rules::ast::{Item, ItemNode, NamePart};
use btc_lang::rules::check::Decls;
use btc_lang::rules::lexer::{lex, Comment, Tok};
use btc_lang::rules::name::{find_folded, Key};
use btc_pddl::source::Span;
use btc_pddl::DomainIndex;

/// Item keywords: a name after one of these is being declared.
pub const DECL_KEYWORDS: &[&str] = &["action", "condition", "tree", "table"];

pub use btc_lang::rules::parse::ITEM_KEYWORDS;

/// Node keywords (from the node vocabulary) and `steps`.
pub use btc_lang::rules::parse::template_keywords;

pub const OTHER_KEYWORDS: &[&str] = &[
    "effect",
    "where",
    "in",
    "skip",
    "out",
    "true",
    "false",
    "std",
    "backchained",
];

/// The tokens of a file with absolute spans, and its comments.
pub struct Tokens {
    pub toks: Vec<(Tok, Span)>,
    pub comments: Vec<Comment>,
}

impl Tokens {
    pub fn new(text: &str) -> Tokens {
        let l = lex(text, 0);
        Tokens {
            toks: l.tokens,
            comments: l.comments,
        }
    }

    /// The token under `offset`, or the one that ends right at it (the
    /// cursor just after a name still points at the name).
    pub fn at(&self, offset: usize) -> Option<usize> {
        let o = offset as u32;
        // The first token that ends after the cursor: it holds the cursor
        // if it starts at or before it.
        let i = self.toks.partition_point(|(_, s)| s.end <= o);
        let before = i.checked_sub(1).filter(|&j| self.toks[j].1.end == o);
        match self.toks.get(i) {
            Some((t, s)) if s.start <= o => {
                // Between `a(`: prefer the name over the punctuation.
                let name_before = before.filter(|&j| !matches!(self.toks[j].0, Tok::Punct(_)));
                match (t, name_before) {
                    (Tok::Punct(_), Some(j)) if s.start == o => Some(j),
                    _ => Some(i),
                }
            }
            _ => before,
        }
    }

    /// Index of the first token at or after `offset`.
    pub fn after(&self, offset: usize) -> usize {
        self.toks
            .partition_point(|(_, s)| (s.start as usize) < offset)
    }

    pub fn punct(&self, i: usize) -> Option<&'static str> {
        match self.toks.get(i) {
            Some((Tok::Punct(p), _)) => Some(p),
            _ => None,
        }
    }

    pub fn ident(&self, i: usize) -> Option<&str> {
        match self.toks.get(i) {
            Some((Tok::Ident(s), _)) => Some(s),
            _ => None,
        }
    }

    /// The innermost unclosed `(` before token `i` (stopping at `{`, which
    /// opens a template block), if any.
    pub fn open_paren(&self, i: usize) -> Option<usize> {
        let mut depth = 0i32;
        for j in (0..i).rev() {
            match self.punct(j) {
                Some(")") => depth += 1,
                Some("(") if depth == 0 => return Some(j),
                Some("(") => depth -= 1,
                Some("{" | "}") if depth == 0 => return None,
                _ => {}
            }
        }
        None
    }

    /// The node call or declaration whose parentheses hold token `i`:
    /// `(name, is_declaration)`.
    pub fn enclosing_call(&self, i: usize) -> Option<(String, bool)> {
        let open = self.open_paren(i)?;
        let name = self.ident(open.checked_sub(1)?)?;
        if !name.starts_with(|c: char| c.is_alphabetic() || c == '_') {
            return None;
        }
        let decl = open >= 2
            && self
                .ident(open - 2)
                .is_some_and(|k| ["action", "condition", "tree"].contains(&k));
        if !decl && ITEM_KEYWORDS.contains(&name) {
            return None;
        }
        Some((name.to_owned(), decl))
    }

    /// Whether token `i` sits inside a PDDL formula: an `effect (...)` or a
    /// condition's `= (...)`.
    pub fn in_pddl(&self, i: usize) -> bool {
        let mut depth = 0i32;
        for j in (0..i).rev() {
            match self.punct(j) {
                Some(")") => depth += 1,
                Some("(") if depth > 0 => depth -= 1,
                Some("(") => {
                    let before = j.checked_sub(1);
                    if before.and_then(|b| self.ident(b)) == Some("effect")
                        || before.and_then(|b| self.punct(b)) == Some("=")
                    {
                        return true;
                    }
                }
                Some("{" | "}") => return false,
                _ => {}
            }
            if self.ident(j).is_some_and(|k| ITEM_KEYWORDS.contains(&k)) && depth <= 0 {
                return false;
            }
        }
        false
    }
}

/// What a token means.
#[derive(Clone, Debug, PartialEq)]
pub enum Symbol {
    /// The action name of a rule's pattern.
    RuleHead {
        item: usize,
    },
    /// A capture in a rule's pattern name or a `{capture}` use.
    Capture {
        item: usize,
        name: String,
    },
    /// `?name` in an item.
    Var {
        item: usize,
        name: String,
    },
    /// A node or tree, called or declared.
    Node {
        name: String,
        declaration: bool,
    },
    Table {
        name: String,
        declaration: bool,
    },
    /// A port in a call or in a declaration.
    Port {
        node: String,
        port: String,
        declaration: bool,
    },
    /// A PDDL predicate in an effect or formula.
    Predicate {
        name: String,
    },
    /// A PDDL type: a port's type or a guard's `?x - type`.
    Type {
        name: String,
    },
    /// The path string of `domain`, `problem` or `import`.
    Path {
        written: String,
    },
    /// `std::NAME`.
    Std {
        module: String,
    },
    Keyword,
}

/// A file's tokens with its parsed items, for classification.
pub struct FileSyntax<'a> {
    pub text: &'a str,
    pub tokens: Tokens,
    pub items: &'a [ItemNode],
    /// Declarations visible in the file (its own and its imports').
    pub decls: &'a Decls,
    pub dix: Option<&'a DomainIndex>,
}

impl FileSyntax<'_> {
    fn is_node(&self, name: &str) -> bool {
        self.decls.nodes.contains_key(name) || self.decls.trees.contains_key(name)
    }

    fn is_table(&self, name: &str) -> bool {
        self.decls.tables.contains_key(name)
    }

    fn is_predicate(&self, name: &str) -> bool {
        self.dix.is_some_and(|d| d.predicates.contains_key(name))
    }

    /// The item holding a byte offset.
    pub fn item_at(&self, offset: u32) -> Option<usize> {
        let i = self.items.partition_point(|n| n.offset <= offset);
        i.checked_sub(1)
    }

    /// The absolute span of an item-relative span of item `item`.
    pub fn abs(&self, item: usize, s: Span) -> Span {
        let o = self.items[item].offset;
        Span {
            start: s.start + o,
            end: s.end + o,
            ..s
        }
    }

    /// The symbol of token `i`.
    pub fn classify(&self, i: usize) -> Option<Symbol> {
        let (tok, span) = self.tokens.toks.get(i)?;
        let item = self.item_at(span.start);
        let prev_ident = |k: usize| i.checked_sub(k).and_then(|j| self.tokens.ident(j));
        let prev_punct = |k: usize| i.checked_sub(k).and_then(|j| self.tokens.punct(j));
        match tok {
            Tok::Var(v) => Some(Symbol::Var {
                item: item?,
                name: Key::new(v).into_string(),
            }),
            Tok::Str(s) => {
                let it = &self.items[item?].item;
                match it {
                    Item::Domain { .. } | Item::Problem { .. } | Item::Import { .. } => {
                        Some(Symbol::Path { written: s.clone() })
                    }
                    _ => None,
                }
            }
            Tok::Ident(name) => {
                if prev_punct(1) == Some("::") && prev_ident(2) == Some("std") {
                    return Some(Symbol::Std {
                        module: name.clone(),
                    });
                }
                if let Some(ix) = item {
                    if let Item::Rule(r) = &self.items[ix].item {
                        let head = self.abs(ix, r.pattern.name_span());
                        if head.start <= span.start && span.end <= head.end {
                            let capture = r.pattern.name.iter().find_map(|p| match p {
                                NamePart::Capture { name: c } if self.abs(ix, c.span) == *span => {
                                    Some(c.text.clone())
                                }
                                _ => None,
                            });
                            return Some(match capture {
                                Some(name) => Symbol::Capture { item: ix, name },
                                None => Symbol::RuleHead { item: ix },
                            });
                        }
                    }
                }
                if let Some(k) = prev_ident(1) {
                    if DECL_KEYWORDS.contains(&k) {
                        // `action Name`, `tree Name`, `table name`
                        if self.tokens.toks[i - 1].1.start == self.items.get(item?)?.offset {
                            return Some(if k == "table" {
                                Symbol::Table {
                                    name: name.clone(),
                                    declaration: true,
                                }
                            } else {
                                Symbol::Node {
                                    name: name.clone(),
                                    declaration: true,
                                }
                            });
                        }
                    }
                }
                let in_pddl = self.tokens.in_pddl(i);
                if in_pddl {
                    let key = Key::new(name);
                    if prev_punct(1) == Some("(") && self.is_predicate(key.as_str()) {
                        return Some(Symbol::Predicate {
                            name: key.into_string(),
                        });
                    }
                    return None;
                }
                if self.tokens.punct(i + 1) == Some(":") {
                    if let Some((node, declaration)) = self.tokens.enclosing_call(i) {
                        return Some(Symbol::Port {
                            node,
                            port: name.clone(),
                            declaration,
                        });
                    }
                }
                if prev_punct(1) == Some(":") {
                    if let Some((_, true)) = self.tokens.enclosing_call(i) {
                        return Some(Symbol::Type { name: name.clone() });
                    }
                }
                if prev_punct(1) == Some("-")
                    && i >= 2
                    && matches!(self.tokens.toks[i - 2].0, Tok::Var(_))
                {
                    return Some(Symbol::Type { name: name.clone() });
                }
                if self.is_node(name) {
                    return Some(Symbol::Node {
                        name: name.clone(),
                        declaration: false,
                    });
                }
                if self.is_table(name) {
                    return Some(Symbol::Table {
                        name: name.clone(),
                        declaration: false,
                    });
                }
                if ITEM_KEYWORDS.contains(&name.as_str())
                    || template_keywords().any(|k| k == name.as_str())
                    || OTHER_KEYWORDS.contains(&name.as_str())
                {
                    return Some(Symbol::Keyword);
                }
                None
            }
            _ => None,
        }
    }

    /// The symbol at a byte offset, with its token's span.
    pub fn symbol_at(&self, offset: usize) -> Option<(Symbol, Span)> {
        let i = self.tokens.at(offset)?;
        let span = self.tokens.toks[i].1;
        self.classify(i).map(|s| (s, span))
    }

    /// Spans of `{?var}` / `{capture}` interpolations named `name` inside
    /// the string tokens of item `item` (`var` says which kind).
    pub fn interpolations(&self, item: usize, name: &str, var: bool) -> Vec<Span> {
        let start = self.items[item].offset;
        let end = self
            .items
            .get(item + 1)
            .map_or(self.text.len() as u32, |n| n.offset);
        let needle = if var {
            format!("{{?{name}}}")
        } else {
            format!("{{{name}}}")
        };
        let mut out = Vec::new();
        for (t, s) in &self.tokens.toks {
            if s.start < start || s.end > end || !matches!(t, Tok::Str(_)) {
                continue;
            }
            let raw = &self.text[s.start as usize..s.end as usize];
            for k in find_folded(raw, &needle) {
                let at = s.start + k as u32 + 1;
                out.push(Span {
                    start: at,
                    end: at + needle.len() as u32 - 2,
                    ..*s
                });
            }
        }
        out
    }
}
