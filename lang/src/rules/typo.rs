//! "Did you mean" for node keywords: a syntax error right after a word
//! that is one or two letters off a node keyword of the vocabulary
//! (`retyr(3) T`, `sequense { ... }`) is most likely that keyword
//! misspelt, which the parser alone can only call unexpected text.

use super::lexer::Tok;
use btc_ir::NodeSpec;
use btc_pddl::diagnostic::Diagnostic;
use btc_pddl::source::Span;
use chumsky::span::SimpleSpan;

/// `d` (a syntax error of the item whose tokens are `tokens`, spans
/// relative to the item as the diagnostic's) with a hint and a fix when
/// the word before it (or before the `(` before it) is a keyword's typo.
pub fn keyword_hint(d: Diagnostic, tokens: &[(Tok, SimpleSpan)]) -> Diagnostic {
    if d.hint.is_some() {
        return d;
    }
    let before = tokens.partition_point(|(_, s)| s.end <= d.span.start as usize);
    let mut k = before.checked_sub(1);
    if let Some(i) = k.filter(|&i| tokens[i].0 == Tok::Punct("(")) {
        k = i.checked_sub(1);
    }
    let Some((Tok::Ident(word), at)) = k.map(|i| &tokens[i]) else {
        return d;
    };
    match NodeSpec::closest(word) {
        Some(spec) if spec.keyword != word => {
            let span = Span::new(d.span.file, at.start, at.end);
            d.with_hint(format!(
                "did you mean `{}`? ({}: {})",
                spec.keyword,
                spec.shape(),
                spec.summary
            ))
            .with_fix(format!("change to `{}`", spec.keyword), span, spec.keyword)
        }
        _ => d,
    }
}
