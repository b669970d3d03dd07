//! Semantic tokens and inlay hints.

use crate::analysis::{shift, Analysis};
use crate::syntax::is_keyword;
use btc_lang::rules::ast::Item;
use btc_lang::rules::lexer::Tok;
use btc_lang::rules::resolve::Target;
use btc_pddl::source::Span;
use tower_lsp::lsp_types::{
    InlayHint, InlayHintKind, InlayHintLabel, Range, SemanticToken, SemanticTokenType,
    SemanticTokensLegend,
};

/// The token types btc reports, in legend order.
pub const TOKEN_TYPES: &[SemanticTokenType] = &[
    SemanticTokenType::KEYWORD,
    SemanticTokenType::FUNCTION,
    SemanticTokenType::PARAMETER,
    SemanticTokenType::STRING,
    SemanticTokenType::NUMBER,
    SemanticTokenType::COMMENT,
    SemanticTokenType::PROPERTY,
    SemanticTokenType::TYPE,
    SemanticTokenType::ENUM,
    SemanticTokenType::MACRO,
    SemanticTokenType::METHOD,
];

pub fn legend() -> SemanticTokensLegend {
    SemanticTokensLegend {
        token_types: TOKEN_TYPES.to_vec(),
        token_modifiers: Vec::new(),
    }
}

fn type_index(t: SemanticTokenType) -> u32 {
    TOKEN_TYPES.iter().position(|x| *x == t).unwrap_or(0) as u32
}

/// The token type of a resolved name.
fn of_target(t: &Target) -> SemanticTokenType {
    match t {
        Target::Callable { .. } => SemanticTokenType::FUNCTION,
        Target::Table { .. } => SemanticTokenType::ENUM,
        Target::Port { .. } => SemanticTokenType::PROPERTY,
        Target::Var { .. } | Target::Capture { .. } => SemanticTokenType::PARAMETER,
        Target::Action { .. } => SemanticTokenType::METHOD,
        Target::Predicate { .. } => SemanticTokenType::MACRO,
        Target::Type { .. } | Target::BasicType { .. } | Target::Std { .. } => {
            SemanticTokenType::TYPE
        }
        Target::Object { .. } | Target::File { .. } => SemanticTokenType::STRING,
    }
}

/// Classified spans of a file, in order: names as the checker resolved
/// them, keywords, literals and comments from the tokens (so a file that
/// does not parse still shows its keywords and strings).
pub fn classified(a: &Analysis) -> Vec<(Span, SemanticTokenType)> {
    // The resolved names by position (the first resolution of a position
    // wins), read alongside the tokens, which come in the same order: a
    // huge file has hundreds of thousands of both.
    let mut names: Vec<(u32, &Target)> = Vec::new();
    for k in 0..a.items.len() {
        names.extend(a.names_of(k).map(|(span, r)| (span.start, &r.target)));
    }
    names.sort_by_key(|(start, _)| *start);
    names.dedup_by_key(|(start, _)| *start);
    let mut next = names.iter().peekable();
    let mut out = Vec::with_capacity(a.syntax.tokens().toks.len());
    for (tok, span) in a.syntax.tokens().toks {
        let ty = match tok {
            Tok::Str(_) => Some(SemanticTokenType::STRING),
            Tok::Int(_) | Tok::Float(_) => Some(SemanticTokenType::NUMBER),
            Tok::Var(_) => Some(SemanticTokenType::PARAMETER),
            Tok::Ident(word) => {
                while next.next_if(|(start, _)| *start < span.start).is_some() {}
                next.next_if(|(start, _)| *start == span.start)
                    .map(|(_, target)| of_target(target))
                    .or_else(|| is_keyword(word).then_some(SemanticTokenType::KEYWORD))
            }
            _ => None,
        };
        if let Some(t) = ty {
            out.push((*span, t));
        }
    }
    for c in a.syntax.tokens().comments {
        out.push((c.span, SemanticTokenType::COMMENT));
    }
    out.sort_by_key(|(s, _)| s.start);
    out
}

/// The file's semantic tokens in LSP's relative encoding; spans over
/// several lines are cut at line ends.
pub fn semantic_tokens(a: &Analysis) -> Vec<SemanticToken> {
    let ix = a.line_index();
    let mut out = Vec::new();
    let (mut last_line, mut last_col) = (0u32, 0u32);
    for (span, ty) in classified(a) {
        let piece_text = a
            .text
            .get(span.start as usize..span.end as usize)
            .unwrap_or_default();
        let mut start = span.start as usize;
        for line in piece_text.split_inclusive('\n') {
            let content = line.trim_end_matches(['\n', '\r']);
            let len: u32 = content.encode_utf16().count() as u32;
            if len > 0 {
                let p = ix.position(start);
                let delta_line = p.line - last_line;
                let delta_start = if delta_line == 0 {
                    p.character - last_col
                } else {
                    p.character
                };
                out.push(SemanticToken {
                    delta_line,
                    delta_start,
                    length: len,
                    token_type: type_index(ty.clone()),
                    token_modifiers_bitset: 0,
                });
                last_line = p.line;
                last_col = p.character;
            }
            start += line.len();
        }
    }
    out
}

/// `: type` after each rule parameter whose PDDL type is known.
pub fn inlay_hints(a: &Analysis, range: Range) -> Vec<InlayHint> {
    let ix = a.line_index();
    let (from, to) = (ix.offset(range.start) as u32, ix.offset(range.end) as u32);
    let mut out = Vec::new();
    for (k, n) in a.items.iter().enumerate() {
        let Item::Rule(r) = &*n.item else { continue };
        let whole = shift(r.span, n.offset);
        if whole.end < from || whole.start > to {
            continue;
        }
        for p in &r.pattern.params {
            let types = a.var_types(k, &p.var.text);
            if types.is_empty() {
                continue;
            }
            let at = shift(p.var.span, n.offset).end as usize;
            out.push(InlayHint {
                position: ix.position(at),
                label: InlayHintLabel::String(format!(": {}", types.join(" | "))),
                kind: Some(InlayHintKind::TYPE),
                text_edits: None,
                tooltip: None,
                padding_left: Some(false),
                padding_right: Some(false),
                data: None,
            });
        }
    }
    out
}
