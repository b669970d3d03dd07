//! S-expressions built from tokens, with recovery for unbalanced parentheses.
//!
//! The builder is iterative, and nesting is capped at [`MAX_DEPTH`], so no
//! input can overflow the stack here or in the recursive passes after it.

use super::lexer::{Tok, Token};
use crate::diagnostic::{codes, Diagnostic};
use crate::source::Span;

/// Deepest nesting of parentheses btc accepts. Real PDDL stays below 30.
pub const MAX_DEPTH: usize = crate::limits::MAX_NESTING;

#[derive(Clone, Debug, PartialEq)]
pub enum Sexp {
    Atom(Token),
    List(List),
}

#[derive(Clone, Debug, PartialEq)]
pub struct List {
    pub items: Vec<Sexp>,
    /// From the `(` to the `)`, or to the last item when never closed.
    pub span: Span,
}

impl Sexp {
    pub fn span(&self) -> Span {
        match self {
            Sexp::Atom(t) => t.span,
            Sexp::List(l) => l.span,
        }
    }

    pub fn as_list(&self) -> Option<&List> {
        match self {
            Sexp::List(l) => Some(l),
            Sexp::Atom(_) => None,
        }
    }

    pub fn tok(&self) -> Option<&Tok> {
        match self {
            Sexp::Atom(t) => Some(&t.tok),
            Sexp::List(_) => None,
        }
    }

    /// The keyword (without `:`) if this is a keyword atom.
    pub fn keyword(&self) -> Option<&str> {
        match self.tok() {
            Some(Tok::Keyword(k)) => Some(k),
            _ => None,
        }
    }

    /// What the user would call this, for messages.
    pub fn describe(&self) -> String {
        match self {
            Sexp::List(l) => match l.items.first().and_then(Sexp::tok) {
                Some(Tok::Keyword(k)) => format!("a `(:{k} ...)` section"),
                Some(Tok::Name(n)) => format!("`({n} ...)`"),
                _ => "a parenthesised list".into(),
            },
            Sexp::Atom(t) => describe_tok(&t.tok),
        }
    }
}

impl List {
    /// The first item if it is a name or keyword: the list's "head".
    pub fn head(&self) -> Option<&str> {
        match self.items.first().and_then(Sexp::tok) {
            Some(Tok::Name(n)) | Some(Tok::Keyword(n)) => Some(n),
            _ => None,
        }
    }

    pub fn head_span(&self) -> Span {
        self.items.first().map_or(self.span, Sexp::span)
    }
}

pub fn describe_tok(t: &Tok) -> String {
    match t {
        Tok::LParen => "`(`".into(),
        Tok::RParen => "`)`".into(),
        Tok::Name(n) => format!("the name `{n}`"),
        Tok::Var(v) => format!("the variable `?{v}`"),
        Tok::Keyword(k) => format!("the keyword `:{k}`"),
        Tok::Number(n) => format!("the number `{n}`"),
        Tok::Dash => "`-`".into(),
        Tok::Invalid(w) => format!("`{w}`"),
    }
}

/// Keywords that open a top-level section of a domain or problem. Seeing one
/// deep inside another list means a `)` is missing before it.
const SECTION_KEYWORDS: &[&str] = &[
    "requirements",
    "types",
    "constants",
    "predicates",
    "functions",
    "action",
    "durative-action",
    "derived",
    "objects",
    "init",
    "goal",
    "metric",
    "constraints",
];

struct Open {
    open: Span,
    items: Vec<Sexp>,
}

/// Builds the forest of s-expressions. Every `(` gets a list, closed or not;
/// stray `)` are reported and dropped.
pub fn build(tokens: Vec<Token>) -> (Vec<Sexp>, Vec<Diagnostic>) {
    let mut diags = Vec::new();
    let mut top: Vec<Sexp> = Vec::new();
    let mut stack: Vec<Open> = Vec::new();
    // Depth of lists skipped because they were too deep; their tokens are dropped.
    let mut skipped_depth = 0usize;
    let mut iter = tokens.into_iter().peekable();

    fn push(stack: &mut [Open], top: &mut Vec<Sexp>, s: Sexp) {
        match stack.last_mut() {
            Some(o) => o.items.push(s),
            None => top.push(s),
        }
    }
    fn close(o: Open, end: Span) -> Sexp {
        Sexp::List(List {
            items: o.items,
            span: o.open.to(end),
        })
    }

    while let Some(t) = iter.next() {
        if skipped_depth > 0 {
            match t.tok {
                Tok::LParen => skipped_depth += 1,
                Tok::RParen => skipped_depth -= 1,
                _ => {}
            }
            continue;
        }
        match t.tok {
            Tok::LParen => {
                let is_section = matches!(
                    iter.peek().map(|n| &n.tok),
                    Some(Tok::Keyword(k)) if SECTION_KEYWORDS.contains(&k.as_str())
                );
                if is_section && stack.len() > 1 {
                    // `(:action` inside an action: close everything above `define`.
                    let innermost = stack.last().map(|o| o.open).unwrap_or(t.span);
                    while stack.len() > 1 {
                        let o = stack.pop().expect("len > 1");
                        let end = o.items.last().map_or(o.open, Sexp::span);
                        let list = close(o, end);
                        push(&mut stack, &mut top, list);
                    }
                    diags.push(
                        Diagnostic::error(
                            codes::UNCLOSED_PAREN,
                            innermost,
                            "this `(` is not closed before the next section starts",
                        )
                        .with_label(t.span, "next section starts here")
                        .with_hint("add the missing `)` before the new section"),
                    );
                }
                if stack.len() >= MAX_DEPTH {
                    diags.push(
                        Diagnostic::error(
                            codes::TOO_DEEP,
                            t.span,
                            format!("parentheses are nested more than {MAX_DEPTH} levels deep"),
                        )
                        .with_hint("split the formula; btc skips this list"),
                    );
                    skipped_depth = 1;
                    continue;
                }
                stack.push(Open {
                    open: t.span,
                    items: Vec::new(),
                });
            }
            Tok::RParen => match stack.pop() {
                Some(o) => {
                    let list = close(o, t.span);
                    push(&mut stack, &mut top, list);
                }
                None => diags.push(
                    Diagnostic::error(codes::UNEXPECTED_CLOSE, t.span, "this `)` closes nothing")
                        .with_hint("remove it, or look for a missing `(` before it"),
                ),
            },
            _ => push(&mut stack, &mut top, Sexp::Atom(t)),
        }
    }
    // Report each unclosed list at its `(`; close them all.
    while let Some(o) = stack.pop() {
        diags.push(
            Diagnostic::error(codes::UNCLOSED_PAREN, o.open, "this `(` is never closed")
                .with_hint("add a `)` at the end of the list"),
        );
        let end = o.items.last().map_or(o.open, Sexp::span);
        let list = close(o, end);
        push(&mut stack, &mut top, list);
    }
    (top, diags)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lexer::lex;

    fn parse(s: &str) -> (Vec<Sexp>, Vec<Diagnostic>) {
        build(lex(s, 0).0)
    }

    #[test]
    fn nests_lists() {
        let (forest, diags) = parse("(a (b c) d)");
        assert!(diags.is_empty());
        assert_eq!(forest.len(), 1);
        let l = forest[0].as_list().unwrap();
        assert_eq!(l.items.len(), 3);
        assert_eq!(l.span, Span::new(0, 0, 11));
    }

    #[test]
    fn recovers_from_a_missing_paren_before_a_section() {
        let (forest, diags) = parse("(define (domain x) (:action a (and (p)) (:action b))");
        let codes: Vec<_> = diags.iter().map(|d| d.code).collect();
        assert_eq!(codes, vec!["P002"]);
        assert_eq!(diags[0].span, Span::new(0, 19, 20));
        // both actions end up as sections of `define`
        assert_eq!(forest[0].as_list().unwrap().items.len(), 4);
    }

    #[test]
    fn reports_stray_close_and_unclosed_open() {
        let (forest, diags) = parse(") (a (b)");
        let codes: Vec<_> = diags.iter().map(|d| d.code).collect();
        assert_eq!(codes, vec!["P003", "P002"]);
        assert_eq!(forest.len(), 1);
    }

    #[test]
    fn caps_depth_without_recursion() {
        let n = 10_000;
        let text = format!("{}{}", "(and ".repeat(n), ")".repeat(n));
        let (forest, diags) = parse(&text);
        assert_eq!(forest.len(), 1);
        assert_eq!(diags.len(), 1);
        assert_eq!(diags[0].code, "P004");
    }
}
