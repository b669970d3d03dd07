//! A rules file's tokens (which exist for any text, however broken) and
//! its parsed items, for what reads the text around the cursor:
//! completion, signature help, keywords in semantic tokens. What a name
//! means is the checker's (`btc_lang::resolutions`), not worked out here.

use btc_lang::rules::ast::ItemNode;
use btc_lang::rules::lexer::{Comment, Tok};
use btc_pddl::source::Span;

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
    "scheduled",
];

/// The tokens of a file with absolute spans, and its comments (lexed once
/// per text by the database: `btc_lang::db::rules_tokens`).
pub struct Tokens<'a> {
    pub toks: &'a [(Tok, Span)],
    pub comments: &'a [Comment],
}

impl<'a> Tokens<'a> {
    pub fn of(t: &'a btc_lang::db::FileTokens) -> Tokens<'a> {
        Tokens {
            toks: &t.tokens,
            comments: &t.comments,
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

/// Whether a word is one of the language's keywords.
pub fn is_keyword(word: &str) -> bool {
    ITEM_KEYWORDS.contains(&word)
        || template_keywords().any(|k| k == word)
        || OTHER_KEYWORDS.contains(&word)
}

/// A file's tokens with its parsed items.
pub struct FileSyntax<'a> {
    pub text: &'a str,
    pub items: &'a [ItemNode],
    /// Where the tokens come from, read when a request first needs them
    /// (symbols and hovers do not: lexing a huge file costs a tenth of a
    /// second after each edit).
    pub db: &'a btc_lang::db::Database,
    pub file: btc_lang::db::SourceFile,
    pub tokens: std::cell::OnceCell<Tokens<'a>>,
}

impl<'a> FileSyntax<'a> {
    /// The file's tokens (lexed once per text by the database).
    pub fn tokens(&self) -> &Tokens<'a> {
        self.tokens
            .get_or_init(|| Tokens::of(btc_lang::db::rules_tokens(self.db, self.file)))
    }

    /// The tokens from the start of the item holding `offset` to the next
    /// item's, with absolute spans: what a request that looks only around
    /// the cursor needs, without lexing the whole file. An item starts at
    /// a token outside any string or comment, so its text lexes as it does
    /// in the file.
    pub fn item_tokens(&self, offset: u32) -> Option<btc_lang::db::FileTokens> {
        let i = self.item_at(offset)?;
        let start = self.items[i].offset;
        let end = self
            .items
            .get(i + 1)
            .map_or(self.text.len(), |n| n.offset as usize);
        let lexed = btc_lang::rules::lexer::lex(self.text.get(start as usize..end)?, 0);
        let shift = |s: Span| Span {
            start: s.start + start,
            end: s.end + start,
            ..s
        };
        Some(btc_lang::db::FileTokens {
            tokens: lexed
                .tokens
                .into_iter()
                .map(|(t, s)| (t, shift(s)))
                .collect(),
            comments: lexed
                .comments
                .into_iter()
                .map(|c| Comment {
                    span: shift(c.span),
                    ..c
                })
                .collect(),
        })
    }

    /// The item holding a byte offset.
    pub fn item_at(&self, offset: u32) -> Option<usize> {
        let i = self.items.partition_point(|n| n.offset <= offset);
        i.checked_sub(1)
    }
}
