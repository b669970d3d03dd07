//! The `.btrules` parser. The token stream is first cut into top-level items
//! (at item keywords outside brackets, or at the start of a line), and each
//! item is parsed on its own with spans relative to its start: a broken item
//! becomes [`Item::Error`] and the others still parse.

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

/// Cuts a file into items as its tokens come: an item starts at an item
/// keyword outside brackets or at the start of a line, and runs from its
/// first token's start to its last token's end.
struct Cutter<'t> {
    text: &'t str,
    depth: usize,
    /// The current item's start, and the end of its last token so far.
    current: Option<(u32, u32)>,
    items: Vec<(u32, u32)>,
}

impl<'t> Cutter<'t> {
    fn new(text: &'t str) -> Cutter<'t> {
        Cutter {
            text,
            depth: 0,
            current: None,
            items: Vec::new(),
        }
    }

    fn token(&mut self, t: &Tok, span: Span) {
        let is_kw = matches!(t, Tok::Ident(k) if ITEM_KEYWORDS.contains(&k.as_str()));
        if is_kw && (self.depth == 0 || at_line_start(self.text, span.start)) {
            if let Some(item) = self.current.take() {
                self.items.push(item);
            }
            self.depth = 0;
        }
        // Text before the first keyword is an item of its own (an error).
        let item = self.current.get_or_insert((span.start, span.end));
        item.1 = span.end;
        match t {
            Tok::Punct("(" | "{" | "[") => self.depth += 1,
            Tok::Punct(")" | "}" | "]") => self.depth = self.depth.saturating_sub(1),
            _ => {}
        }
    }

    /// Each item's start and end.
    fn finish(mut self) -> Vec<(u32, u32)> {
        self.items.extend(self.current);
        self.items
    }
}

fn rel(span: Span, offset: u32) -> SimpleSpan {
    SimpleSpan::from((span.start - offset) as usize..(span.end - offset) as usize)
}

/// Reads the PDDL group starting at `tokens[i]` (a `(`) with the PDDL
/// front end; returns the replacement token and the index after the group.
fn read_pddl_group(
    tokens: &[(Tok, Span)],
    i: usize,
    offset: u32,
    file: FileId,
    effect: bool,
    diags: &mut Vec<Diagnostic>,
) -> ((Tok, SimpleSpan), usize) {
    let mut depth = 0usize;
    let mut j = i;
    let mut ptoks = Vec::new();
    while j < tokens.len() {
        let (t, span) = &tokens[j];
        let s = Span::new(
            file,
            (span.start - offset) as usize,
            (span.end - offset) as usize,
        );
        let pt = match t {
            Tok::Punct("(") => {
                depth += 1;
                PTok::LParen
            }
            Tok::Punct(")") => {
                depth -= 1;
                PTok::RParen
            }
            Tok::Ident(n) => PTok::Name(Key::new(n).into_string()),
            Tok::Var(v) => PTok::Var(Key::new(v).into_string()),
            Tok::Int(n) => PTok::Number(*n as f64),
            Tok::Float(n) => PTok::Number(*n),
            Tok::Punct("-") => PTok::Dash,
            Tok::Punct("=") => PTok::Name("=".into()),
            other => {
                diags.push(Diagnostic::error(
                    codes::R_SYNTAX,
                    s,
                    format!("{other} cannot appear in a PDDL formula"),
                ));
                PTok::Invalid(other.to_string())
            }
        };
        ptoks.push(PToken { tok: pt, span: s });
        j += 1;
        if depth == 0 {
            break;
        }
    }
    let start = rel(tokens[i].1, offset).start;
    let end = rel(tokens[j - 1].1, offset).end;
    let (forest, sdiags) = sexpr::build(ptoks);
    diags.extend(sdiags);
    let tok = match forest.first() {
        Some(sx) if effect => match effect_of(sx) {
            (Some(e), d) => {
                diags.extend(d);
                Tok::Effect(Box::new(e))
            }
            (None, d) => {
                diags.extend(d);
                Tok::BadPddl
            }
        },
        Some(sx) => match formula_of(sx) {
            (Some(f), d) => {
                diags.extend(d);
                Tok::Formula(Box::new(f))
            }
            (None, d) => {
                diags.extend(d);
                Tok::BadPddl
            }
        },
        None => Tok::BadPddl,
    };
    ((tok, SimpleSpan::from(start..end)), j)
}

/// Characters that may stand in the literal parts of an action-name
/// pattern: those of PDDL names.
fn is_name_char(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_' || c == '-'
}

/// Reads the action-name pattern that starts at `tokens[i]` (just after
/// `rule (`): the run of touching name tokens, hyphens, numbers and
/// `{capture}`s, split into parts from the item's text. Returns the
/// replacement token (`None` when no name starts here) and the index after
/// the run.
fn read_name_pattern(
    tokens: &[(Tok, Span)],
    i: usize,
    text: &str,
    offset: u32,
    file: FileId,
    diags: &mut Vec<Diagnostic>,
) -> (Option<(Tok, SimpleSpan)>, usize) {
    let part_of_name =
        |t: &Tok| matches!(t, Tok::Ident(_) | Tok::Int(_) | Tok::Punct("-" | "{" | "}"));
    if !tokens
        .get(i)
        .is_some_and(|(t, _)| matches!(t, Tok::Ident(_) | Tok::Punct("{")))
    {
        return (None, i);
    }
    let mut j = i + 1;
    while j < tokens.len() && part_of_name(&tokens[j].0) && tokens[j].1.start == tokens[j - 1].1.end
    {
        j += 1;
    }
    // Spans relative to the item, as everything the parser makes.
    let (start, end) = (
        (tokens[i].1.start - offset) as usize,
        (tokens[j - 1].1.end - offset) as usize,
    );
    let span = |a: usize, b: usize| Span::new(file, a, b);
    if let Some((t, s)) = tokens.get(j) {
        if matches!(t, Tok::Ident(_) | Tok::Punct("{")) {
            let r = rel(*s, offset);
            diags.push(Diagnostic::error(
                codes::R_SYNTAX,
                span(r.start, r.end),
                "the parts of an action-name pattern must touch: write `move-{src}-to-curb`, without spaces",
            ));
        }
    }
    let raw = &text[start..end];
    let mut parts = Vec::new();
    let mut lit_start = None::<usize>;
    let mut k = 0;
    let flush = |parts: &mut Vec<NamePart>, from: Option<usize>, to: usize| {
        if let Some(a) = from {
            let t = &raw[a..to];
            parts.push(NamePart::Lit {
                text: t.to_owned(),
                key: Key::new(t),
                span: span(start + a, start + to),
            });
        }
    };
    while k < raw.len() {
        let c = raw[k..].chars().next().expect("in bounds");
        match c {
            '{' => {
                flush(&mut parts, lit_start.take(), k);
                let Some(close) = raw[k..].find('}').map(|n| k + n) else {
                    diags.push(
                        Diagnostic::error(
                            codes::R_SYNTAX,
                            span(start + k, end),
                            "this `{` opens a capture that is never closed",
                        )
                        .with_hint("a capture is a name in braces, such as `{op}`"),
                    );
                    return (Some((Tok::BadPddl, rel_range(start, end))), j);
                };
                let inner = &raw[k + 1..close];
                let ok = inner.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_')
                    && inner.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
                if !ok {
                    diags.push(
                        Diagnostic::error(
                            codes::R_SYNTAX,
                            span(start + k, start + close + 1),
                            format!("`{{{inner}}}` is not a capture: a capture is a name in braces, such as `{{op}}`"),
                        ),
                    );
                    return (Some((Tok::BadPddl, rel_range(start, end))), j);
                }
                parts.push(NamePart::Capture {
                    name: Ident::new(inner.to_owned(), span(start + k + 1, start + close)),
                });
                k = close + 1;
            }
            '}' => {
                diags.push(Diagnostic::error(
                    codes::R_SYNTAX,
                    span(start + k, start + k + 1),
                    "this `}` closes no capture",
                ));
                return (Some((Tok::BadPddl, rel_range(start, end))), j);
            }
            c if is_name_char(c) => {
                lit_start.get_or_insert(k);
                k += c.len_utf8();
            }
            c => {
                diags.push(Diagnostic::error(
                    codes::R_SYNTAX,
                    span(start + k, start + k + c.len_utf8()),
                    format!("`{c}` cannot stand in an action name"),
                ));
                return (Some((Tok::BadPddl, rel_range(start, end))), j);
            }
        }
    }
    flush(&mut parts, lit_start.take(), raw.len());
    (Some((Tok::NamePattern(parts), rel_range(start, end))), j)
}

fn rel_range(start: usize, end: usize) -> SimpleSpan {
    SimpleSpan::from(start..end)
}

/// Parses one item's tokens, which it takes out of `tokens` (a token
/// passed on to the parser is moved, not copied): first without building
/// error messages, then, only for an item that has errors, again with them.
fn parse_item(
    tokens: &mut [(Tok, Span)],
    text: &str,
    offset: u32,
    file: FileId,
) -> (Item, Vec<Diagnostic>) {
    let mut diags = Vec::new();
    let whole = Span::new(
        file,
        0,
        (tokens.last().map_or(offset, |t| t.1.end) - offset) as usize,
    );
    let Some(input) = prepare(tokens, text, offset, file, &mut diags) else {
        return (Item::Error { span: whole }, diags);
    };
    let eoi = SimpleSpan::from(whole.end as usize..whole.end as usize);
    let parsers = cached_item_parsers(file);
    if let Some(item) = parse_quick(&parsers, &input, eoi) {
        return (item, diags);
    }
    let (item, errors) = parse_rich(&parsers, &input, eoi);
    for e in errors {
        let d = rich_to_diagnostic(&e, file);
        diags.push(super::typo::keyword_hint(d, &input));
    }
    (item.unwrap_or(Item::Error { span: whole }), diags)
}

/// The parser's input for an item's tokens: spans relative to the item,
/// PDDL groups and a rule's name pattern read into tokens of their own;
/// `None` (reported) when brackets and decorators nest too deep.
fn prepare(
    tokens: &mut [(Tok, Span)],
    text: &str,
    offset: u32,
    file: FileId,
    diags: &mut Vec<Diagnostic>,
) -> Option<Vec<(Tok, SimpleSpan)>> {
    let mut input: Vec<(Tok, SimpleSpan)> = Vec::with_capacity(tokens.len());
    let is_condition = matches!(tokens.first(), Some((Tok::Ident(k), _)) if k == "condition");
    let is_rule = matches!(tokens.first(), Some((Tok::Ident(k), _)) if k == "rule")
        && matches!(tokens.get(1), Some((Tok::Punct("("), _)));
    let mut nesting = Nesting::default();
    let mut i = 0;
    while i < tokens.len() {
        let (t, span) = &tokens[i];
        if i == 2 && is_rule {
            let (tok, next) = read_name_pattern(tokens, i, text, offset, file, diags);
            if let Some(tok) = tok {
                input.push(tok);
                i = next;
                continue;
            }
        }
        let prev = input.last().map(|p| &p.0);
        if matches!(t, Tok::Punct("(")) {
            let effect = matches!(prev, Some(Tok::Ident(k)) if k == "effect");
            let formula = is_condition && matches!(prev, Some(Tok::Punct("=")));
            if effect || formula {
                let (tok, next) = read_pddl_group(tokens, i, offset, file, effect, diags);
                input.push(tok);
                i = next;
                continue;
            }
        }
        if nesting.step(tokens, i) > MAX_ITEM_DEPTH {
            let what = if matches!(t, Tok::Punct(_)) {
                "brackets"
            } else {
                "brackets and chained decorators"
            };
            diags.push(
                Diagnostic::error(
                    codes::R_TOO_DEEP,
                    Span::new(file, rel(*span, offset).start, rel(*span, offset).end),
                    format!("{what} are nested more than {MAX_ITEM_DEPTH} levels deep here"),
                )
                .with_hint("split the template into `tree`s that call each other"),
            );
            return None;
        }
        // Every look at the tokens (above) is at `i` or after it.
        let span = rel(*span, offset);
        input.push((std::mem::replace(&mut tokens[i].0, Tok::BadPddl), span));
        i += 1;
    }
    Some(input)
}

/// The item, if it parses without any error.
fn parse_quick(
    parsers: &ItemParsers,
    input: &[(Tok, SimpleSpan)],
    eoi: SimpleSpan,
) -> Option<Item> {
    let quick = parsers
        .quick
        .get()
        .parse(input.map(eoi, split_token as SplitToken<'_>));
    if quick.has_errors() {
        return None;
    }
    quick.into_output()
}

fn parse_rich<'t>(
    parsers: &ItemParsers,
    input: &'t [(Tok, SimpleSpan)],
    eoi: SimpleSpan,
) -> (Option<Item>, Vec<RichErr<'t>>) {
    parsers
        .rich
        .get()
        .parse(input.map(eoi, split_token as SplitToken<'_>))
        .into_output_errors()
}

/// Where the quick parse of an item of `text` (no error messages) and the
/// rich one disagree: on whether it has errors, or on what it reads. The
/// quick parse stands in for the rich one only where they agree; the tests
/// and the fuzzer check that they always do.
#[doc(hidden)]
pub fn quick_and_rich_disagree(text: &str) -> Option<String> {
    let parsers = cached_item_parsers(0);
    cut_rules(text, 0).items.iter().find_map(|&(start, end)| {
        let item = &text[start as usize..end as usize];
        let mut lexed = lex(item, 0);
        let input = prepare(&mut lexed.tokens, item, 0, 0, &mut Vec::new())?;
        let eoi = SimpleSpan::from(item.len()..item.len());
        let quick = parse_quick(&parsers, &input, eoi);
        let (rich, errors) = parse_rich(&parsers, &input, eoi);
        let agree = match &quick {
            None => !errors.is_empty(),
            Some(_) => errors.is_empty() && quick == rich,
        };
        (!agree).then(|| format!("{item}\nquick: {quick:?}\nrich: {rich:?} {errors:?}"))
    })
}

fn rich_to_diagnostic(e: &Rich<'_, Tok, SimpleSpan>, file: FileId) -> Diagnostic {
    let span = Span::new(file, e.span().start, e.span().end);
    let found = match e.found() {
        Some(t) => t.to_string(),
        None => "the end of the item".to_owned(),
    };
    // chumsky quotes tokens ('…'); ours already read `…`.
    let mut expected: Vec<String> = e
        .expected()
        .map(|p| p.to_string().trim_matches('\'').to_owned())
        .filter(|p| p != "something else")
        .collect();
    expected.sort();
    expected.dedup();
    let message = match (e.reason(), expected.as_slice()) {
        (chumsky::error::RichReason::Custom(msg), _) => msg.to_string(),
        (_, []) => format!("unexpected {found}"),
        (_, [one]) => format!("expected {one}, found {found}"),
        (_, many) => format!("expected one of {}, found {found}", many.join(", ")),
    };
    Diagnostic::error(codes::R_SYNTAX, span, message)
}

/// What the item parser needs of its error type: chumsky's error, labels,
/// and messages of its own. Two types have it: [`Rich`], what users read,
/// and [`EmptyErr`], for a first attempt that builds no expected-token
/// sets as alternatives fail (most of a parse's work otherwise), since
/// nearly every item parses without errors. An item that has errors is
/// parsed again with [`Rich`]; the error type does not steer the parse, so
/// an item without errors reads the same either way.
trait ItemError<'t, I: Input<'t, Span = SimpleSpan>>:
    chumsky::error::Error<'t, I> + chumsky::label::LabelError<'t, I, &'static str>
{
    fn custom(span: SimpleSpan, message: String) -> Self;
}

impl<'t, I: Input<'t, Token = Tok, Span = SimpleSpan>> ItemError<'t, I>
    for Rich<'t, Tok, SimpleSpan>
{
    fn custom(span: SimpleSpan, message: String) -> Self {
        Rich::custom(span, message)
    }
}

impl<'t, I: Input<'t, Span = SimpleSpan>> ItemError<'t, I> for EmptyErr {
    fn custom(_: SimpleSpan, _: String) -> Self {
        EmptyErr::default()
    }
}

type RichErr<'t> = Rich<'t, Tok, SimpleSpan>;

/// What the item parser reads: an item's tokens with their relative spans.
type ItemInput<'t> = MappedInput<'t, Tok, SimpleSpan, &'t [(Tok, SimpleSpan)], SplitToken<'t>>;
type SplitToken<'t> = fn(&'t (Tok, SimpleSpan)) -> (&'t Tok, &'t SimpleSpan);

fn split_token(pair: &(Tok, SimpleSpan)) -> (&Tok, &SimpleSpan) {
    (&pair.0, &pair.1)
}

/// The item parsers of one file, built once: building one (a few hundred
/// combinators, a string per keyword) cost more than parsing a typical
/// item, and a file has tens of thousands of items. chumsky's [`Cache`]
/// holds them for inputs of any lifetime.
struct RichItemParser {
    file: FileId,
}

struct QuickItemParser {
    file: FileId,
}

impl Cached for RichItemParser {
    type Parser<'t> = Boxed<'t, 't, ItemInput<'t>, Item, extra::Err<RichErr<'t>>>;

    fn make_parser<'t>(self) -> Self::Parser<'t> {
        item_parser(self.file).boxed()
    }
}

impl Cached for QuickItemParser {
    type Parser<'t> = Boxed<'t, 't, ItemInput<'t>, Item, extra::Err<EmptyErr>>;

    fn make_parser<'t>(self) -> Self::Parser<'t> {
        item_parser(self.file).boxed()
    }
}

/// Both parsers of one file.
struct ItemParsers {
    quick: Cache<QuickItemParser>,
    rich: Cache<RichItemParser>,
}

thread_local! {
    /// Per thread, since a parser shares its recursive parts through `Rc`;
    /// per file, since the parser puts the file in every span it makes.
    static ITEM_PARSERS: RefCell<HashMap<FileId, Rc<ItemParsers>>> =
        RefCell::default();
}

fn cached_item_parsers(file: FileId) -> Rc<ItemParsers> {
    ITEM_PARSERS.with(|parsers| {
        parsers
            .borrow_mut()
            .entry(file)
            .or_insert_with(|| {
                Rc::new(ItemParsers {
                    quick: Cache::new(QuickItemParser { file }),
                    rich: Cache::new(RichItemParser { file }),
                })
            })
            .clone()
    })
}

fn kw<'t, I: ValueInput<'t, Token = Tok, Span = SimpleSpan>, R: ItemError<'t, I> + 't>(
    word: &'static str,
) -> impl Parser<'t, I, (), extra::Err<R>> + Clone {
    just(Tok::Ident(SmolStr::new_static(word)))
        .ignored()
        .labelled(word)
}

/// Templates in braces; a block that does not parse becomes one error
/// node and parsing goes on after its closing brace.
fn block_of<'t, I: ValueInput<'t, Token = Tok, Span = SimpleSpan>, R: ItemError<'t, I> + 't>(
    template: impl Parser<'t, I, Template, extra::Err<R>> + Clone,
    file: FileId,
) -> impl Parser<'t, I, Vec<Template>, extra::Err<R>> + Clone {
    template
        .repeated()
        .collect::<Vec<Template>>()
        .map(exact)
        .delimited_by(punct("{"), punct("}"))
        .recover_with(via_parser(nested_delimiters(
            Tok::Punct("{"),
            Tok::Punct("}"),
            [
                (Tok::Punct("("), Tok::Punct(")")),
                (Tok::Punct("["), Tok::Punct("]")),
            ],
            move |s: SimpleSpan| {
                vec![Template::Error {
                    span: Span::new(file, s.start, s.end),
                }]
            },
        )))
}

/// A list read by the parser, without the room its growth left (a list
/// of one starts with room for four): an item's tree lives as long as its
/// text is unchanged, and a huge file has tens of thousands of them.
fn exact<T>(mut v: Vec<T>) -> Vec<T> {
    v.shrink_to_fit();
    v
}

fn punct<'t, I: ValueInput<'t, Token = Tok, Span = SimpleSpan>, R: ItemError<'t, I> + 't>(
    p: &'static str,
) -> impl Parser<'t, I, (), extra::Err<R>> + Clone {
    just(Tok::Punct(p)).ignored()
}

fn item_parser<'t, I: ValueInput<'t, Token = Tok, Span = SimpleSpan>, R: ItemError<'t, I> + 't>(
    file: FileId,
) -> impl Parser<'t, I, Item, extra::Err<R>> {
    let sp = move |s: SimpleSpan| Span::new(file, s.start, s.end);
    let ident = select! { Tok::Ident(s) => s }
        .map_with(move |text: SmolStr, e| Ident::new(text.into(), sp(e.span())))
        .labelled("a name");
    // Variables are PDDL's, so they are shown (and compared) folded.
    let var = select! { Tok::Var(s) => s }
        .map_with(move |text: SmolStr, e| Ident::new(Key::new(&text).into_string(), sp(e.span())))
        .labelled("a variable");
    let int = select! { Tok::Int(n) => n }.labelled("a whole number");
    let count = int.try_map(|n, span| {
        u32::try_from(n)
            .map_err(|_| R::custom(span, "expected a count from 0 to 4294967295".into()))
    });
    // A bad escape or interpolation is reported, and the string still
    // parses (as its raw text): failing here would let chumsky merge the
    // error into "expected a string, found a string".
    let strlit = select! { Tok::Str(s) => s }
        .validate(move |raw: SmolStr, e, emitter| {
            let span: SimpleSpan = e.span();
            interpolate(&raw, file, span.start).unwrap_or_else(|(msg, at)| {
                emitter.emit(R::custom(at, msg));
                StrLit {
                    span: Span::new(file, span.start, span.end),
                    parts: vec![StrPart::Text { text: raw.into() }],
                    escapes: Vec::new(),
                }
            })
        })
        .labelled("a string");

    let literal = choice((
        int.map_with(move |value, e| Literal::Int {
            value,
            span: sp(e.span()),
        }),
        select! { Tok::Float(f) => f }.map_with(move |value, e| Literal::Float {
            value,
            span: sp(e.span()),
        }),
        strlit.map(|value| Literal::Str { value }),
        kw("true").map_with(move |_, e| Literal::Bool {
            value: true,
            span: sp(e.span()),
        }),
        kw("false").map_with(move |_, e| Literal::Bool {
            value: false,
            span: sp(e.span()),
        }),
        ident.map(|name| Literal::Name { name }),
    ))
    .labelled("a value");

    let value = recursive(|value| {
        choice((
            var.map(|name| Value::Var { name }),
            strlit.map(|value| Value::Str { value }),
            int.map_with(move |value, e| Value::Int {
                value,
                span: sp(e.span()),
            }),
            select! { Tok::Float(f) => f }.map_with(move |value, e| Value::Float {
                value,
                span: sp(e.span()),
            }),
            kw("true").map_with(move |_, e| Value::Bool {
                value: true,
                span: sp(e.span()),
            }),
            kw("false").map_with(move |_, e| Value::Bool {
                value: false,
                span: sp(e.span()),
            }),
            ident
                .then(value.delimited_by(punct("["), punct("]")))
                .map_with(move |(table, key), e| Value::Lookup {
                    table,
                    key: Box::new(key),
                    span: sp(e.span()),
                }),
            ident.map(|name| Value::Name { name }),
        ))
        .labelled("a value")
    });

    let ports = kw("out")
        .or_not()
        .then(ident)
        .then_ignore(punct(":"))
        .then(ident)
        .map_with(move |((out, name), ty), e| PortDecl {
            out: out.is_some(),
            name,
            ty,
            span: sp(e.span()),
        })
        .separated_by(punct(","))
        .allow_trailing()
        .collect::<Vec<_>>()
        .map(exact)
        .delimited_by(punct("("), punct(")"))
        .labelled("a port list such as `(robot: robot)`");

    let template = recursive(|template| {
        let block = block_of(template.clone(), file);
        // A control keyword of the vocabulary, and its parameters by name
        // (`parallel(success: 2, failure: 1)`), all of them, in its order.
        let control_name = select! {
            Tok::Ident(s) if ControlName::from_keyword(&s).is_some() => s,
        }
        .map(|s| ControlName::from_keyword(&s).expect("selected"));
        let control_args = select! { Tok::Ident(s) => s }
            .then_ignore(punct(":"))
            .then(count)
            .separated_by(punct(","))
            .collect::<Vec<_>>()
            .map(exact)
            .delimited_by(punct("("), punct(")"));
        let control_kind = control_name.then(control_args.or_not()).try_map(
            |(name, args): (ControlName, Option<Vec<(SmolStr, u32)>>), span| {
                let spec = name.spec();
                let given = args.unwrap_or_default();
                let names = given.iter().map(|(n, _)| n.as_str());
                if names.ne(spec.params.iter().map(|p| p.name)) {
                    let shape: Vec<String> = spec
                        .params
                        .iter()
                        .map(|p| format!("{}: N", p.name))
                        .collect();
                    return Err(R::custom(
                        span,
                        format!("expected `{}({})`", spec.keyword, shape.join(", ")),
                    ));
                }
                let values: Vec<u32> = given.into_iter().map(|(_, v)| v).collect();
                Ok(ControlKind::new(name, &values))
            },
        );
        let control = control_kind.then(strlit.or_not()).then(block).map_with(
            move |((control, name), children), e| Template::Control {
                control,
                name,
                children,
                span: sp(e.span()),
            },
        );
        // Arguments are read for every decorator and checked against its
        // parameter by the checker, which can say what is wrong.
        let decorator_arg = ident
            .then_ignore(punct(":"))
            .or_not()
            .then(value.clone())
            .map_with(move |(param, value), e| DecoratorArg {
                param,
                value,
                span: sp(e.span()),
            });
        let decorator_name = select! {
            Tok::Ident(s) if DecoratorName::from_keyword(&s).is_some() => s,
        }
        .map(|s| DecoratorName::from_keyword(&s).expect("selected"))
        .labelled("a decorator");
        let decorator = decorator_name
            .then(
                decorator_arg
                    .separated_by(punct(","))
                    .allow_trailing()
                    .collect::<Vec<_>>()
                    .map(exact)
                    .delimited_by(punct("("), punct(")"))
                    .or_not(),
            )
            .then(strlit.or_not())
            .then(template.clone())
            .map_with(
                move |(((decorator, args), name), child), e| Template::Decorator {
                    decorator,
                    args: args.unwrap_or_default(),
                    name,
                    child: Box::new(child),
                    span: sp(e.span()),
                },
            );
        let steps = kw("steps")
            .ignore_then(
                choice((
                    kw("parallel")
                        .then_ignore(punct("(").not().rewind())
                        .to(StepsMode::Parallel),
                    kw("backchained").to(StepsMode::Backchained),
                ))
                .or_not(),
            )
            .map_with(move |mode, e| Template::Steps {
                mode: mode.unwrap_or(StepsMode::InOrder),
                span: sp(e.span()),
            });
        let arg = ident
            .then_ignore(punct(":"))
            .then(value.clone())
            .map(|(port, value)| Arg { port, value });
        let script_attr =
            ident
                .then_ignore(punct(":"))
                .then(strlit)
                .map_with(move |(key, code), e| ScriptAttr {
                    key,
                    code,
                    span: sp(e.span()),
                });
        let script_attrs = script_attr
            .separated_by(punct(","))
            .allow_trailing()
            .collect::<Vec<_>>()
            .map(exact)
            .delimited_by(punct("["), punct("]"))
            .labelled("scripts such as `[skip_if: \"done == true\"]`");
        let call = ident
            .then(
                arg.separated_by(punct(","))
                    .allow_trailing()
                    .collect::<Vec<_>>()
                    .map(exact)
                    .delimited_by(punct("("), punct(")")),
            )
            .then(script_attrs.or_not())
            .map_with(move |((name, args), scripts), e| Template::Call {
                name,
                args,
                scripts: scripts.unwrap_or_default(),
                span: sp(e.span()),
            });
        // A node called `script(...)` is still a call: the leaf is the
        // keyword followed by a string.
        let script = choice((kw("script").to(false), kw("script_condition").to(true)))
            .then(strlit)
            .map_with(move |(condition, code), e| Template::Script {
                condition,
                code,
                span: sp(e.span()),
            });
        choice((steps, control, decorator, script, call))
            .labelled("a node, a control such as `sequence`, or a decorator")
    });

    let body_block = block_of(template.clone(), file);

    let formula = select! { Tok::Formula(f) => Some(*f), Tok::BadPddl => None }
        .labelled("a PDDL formula in parentheses");
    let effect = select! { Tok::Effect(f) => Some(*f), Tok::BadPddl => None }
        .labelled("a PDDL effect in parentheses");

    let domain = kw("domain")
        .ignore_then(strlit)
        .map_with(move |path, e| Item::Domain {
            path,
            span: sp(e.span()),
        });
    let problem = kw("problem")
        .ignore_then(strlit)
        .map_with(move |path, e| Item::Problem {
            path,
            span: sp(e.span()),
        });
    let import = kw("import")
        .ignore_then(choice((
            strlit.map(|path| ImportTarget::Path { path }),
            kw("std")
                .ignore_then(punct("::"))
                .ignore_then(ident)
                .map(|module| ImportTarget::Std { module }),
        )))
        .map_with(move |target, e| Item::Import {
            target,
            span: sp(e.span()),
        });
    let node = choice((
        kw("action").to(NodeKind::Action),
        kw("condition").to(NodeKind::Condition),
    ))
    .then(ident)
    .then(ports.clone())
    .then(punct("=").ignore_then(formula).or_not())
    .validate(move |(((kind, name), ports), formula), e, emitter| {
        if kind == NodeKind::Action && formula.is_some() {
            emitter.emit(R::custom(
                e.span(),
                "only a `condition` can be defined by a formula".into(),
            ));
        }
        Item::Node(NodeDecl {
            kind,
            name,
            ports,
            formula: formula.flatten(),
            span: sp(e.span()),
        })
    });
    let tree = kw("tree")
        .ignore_then(ident)
        .then(ports)
        .then(body_block.clone())
        .map_with(move |((name, ports), body), e| {
            Item::Tree(TreeDecl {
                name,
                ports,
                body,
                span: sp(e.span()),
            })
        });
    let table = kw("table")
        .ignore_then(ident)
        .then(
            ident
                .then_ignore(punct(":"))
                .then(literal)
                .map(|(key, value)| TableEntry { key, value })
                .separated_by(punct(","))
                .allow_trailing()
                .collect::<Vec<_>>()
                .map(exact)
                .delimited_by(punct("{"), punct("}")),
        )
        .map_with(move |(name, entries), e| {
            Item::Table(TableDecl {
                name,
                entries,
                span: sp(e.span()),
            })
        });

    let param = choice((
        var.map_with(move |var, e| Param {
            var,
            optional: false,
            span: sp(e.span()),
        }),
        var.delimited_by(punct("["), punct("]"))
            .map_with(move |var, e| Param {
                var,
                optional: true,
                span: sp(e.span()),
            }),
    ));
    // The name was read by the pre-pass (`read_name_pattern`); a broken
    // one is reported there and reads as an empty name.
    let name_pattern = select! {
        Tok::NamePattern(parts) => parts,
        Tok::BadPddl => Vec::new(),
    }
    .labelled("an action name such as `move` or `pick-{op}`");
    let pattern = name_pattern
        .then(param.repeated().collect::<Vec<_>>().map(exact))
        .delimited_by(punct("("), punct(")"))
        .map_with(move |(name, params), e| Pattern {
            name,
            params,
            span: sp(e.span()),
        })
        .labelled("an action pattern such as `(move ?robot ?from ?to)`");
    // `"floor_robot"`: a plain string names an object or constant.
    let object = strlit
        .try_map(|s: StrLit, span| match s.plain() {
            Some(text) => Ok(Ident::new(text, s.span)),
            None => Err(R::custom(
                span,
                "a guard compares with an object's name: a string without `{...}`".into(),
            )),
        })
        .map(|name| Operand::Object { name });
    let operand = choice((var.map(|name| Operand::Var { name }), object))
        .labelled("a variable or an object name in quotes");
    let guard = choice((
        operand
            .then_ignore(punct("!="))
            .then(operand)
            .map_with(move |(left, right), e| Guard::Ne {
                left,
                right,
                span: sp(e.span()),
            }),
        operand
            .then_ignore(punct("=="))
            .then(operand)
            .map_with(move |(left, right), e| Guard::Eq {
                left,
                right,
                span: sp(e.span()),
            }),
        var.then_ignore(punct("-"))
            .then(ident)
            .map_with(move |(var, ty), e| Guard::IsType {
                var,
                ty,
                span: sp(e.span()),
            }),
        ident
            .then_ignore(kw("in"))
            .then(ident)
            .map_with(move |(key, table), e| Guard::InTable {
                key,
                table,
                span: sp(e.span()),
            }),
    ))
    .labelled("a guard such as `?a != ?b`");
    let rule_body = choice((
        punct("=>")
            .ignore_then(kw("skip"))
            .map_with(move |_, e| RuleBody::Skip { span: sp(e.span()) }),
        template
            .clone()
            .repeated()
            .collect::<Vec<_>>()
            .map(exact)
            .then(kw("effect").ignore_then(effect).or_not())
            .delimited_by(punct("{"), punct("}"))
            .map(|(body, effect)| RuleBody::Template {
                body,
                effect: effect.flatten(),
            })
            .recover_with(via_parser(nested_delimiters(
                Tok::Punct("{"),
                Tok::Punct("}"),
                [
                    (Tok::Punct("("), Tok::Punct(")")),
                    (Tok::Punct("["), Tok::Punct("]")),
                ],
                move |s| RuleBody::Template {
                    body: vec![Template::Error { span: sp(s) }],
                    effect: None,
                },
            ))),
    ));
    let rule = kw("rule")
        .ignore_then(pattern)
        .then(
            kw("where")
                .ignore_then(
                    guard
                        .separated_by(punct(","))
                        .at_least(1)
                        .collect::<Vec<_>>()
                        .map(exact),
                )
                .or_not(),
        )
        .then(rule_body)
        .map_with(move |((pattern, guards), body), e| {
            Item::Rule(Rule {
                pattern,
                guards: guards.unwrap_or_default(),
                body,
                span: sp(e.span()),
            })
        });
    let plan = kw("plan")
        .ignore_then(body_block)
        .map_with(move |body, e| Item::Plan {
            body,
            span: sp(e.span()),
        });

    choice((domain, problem, import, node, tree, table, rule, plan))
        .labelled(
            "an item: `domain`, `import`, `action`, `condition`, `tree`, `table`, `rule` or `plan`",
        )
        .then_ignore(end())
}

/// Splits a string literal's raw text at `{?var}` / `{capture}` and
/// processes escapes. `start` is the offset of the opening quote.
fn interpolate(raw: &str, file: FileId, start: usize) -> Result<StrLit, (String, SimpleSpan)> {
    let mut parts = Vec::new();
    let mut text = String::new();
    let base = start + 1;
    let mut escapes = Vec::new();
    // The text's length in the parts before `text`.
    let mut done = 0;
    let mut chars = raw.char_indices().peekable();
    while let Some((i, c)) = chars.next() {
        match c {
            '\\' => match chars.next() {
                Some((_, c @ ('n' | 't' | '\\' | '"' | '{' | '}'))) => {
                    escapes.push((done + text.len()) as u32);
                    text.push(match c {
                        'n' => '\n',
                        't' => '\t',
                        c => c,
                    });
                }
                Some((j, c)) => {
                    return Err((format!("`\\{c}` is not an escape; use `\\\\`, `\\\"`, `\\n`, `\\t`, `\\{{` or `\\}}`"), SimpleSpan::from(base + i..base + j + c.len_utf8())))
                }
                None => return Err(("a string cannot end with `\\`".into(), SimpleSpan::from(base + i..base + i + 1))),
            },
            '{' => {
                let close = raw[i..].find('}').map(|k| i + k);
                let Some(close) = close else {
                    return Err(("`{` opens an interpolation that is never closed; write `\\{` for a brace".into(), SimpleSpan::from(base + i..base + i + 1)));
                };
                let inner = &raw[i + 1..close];
                let span = Span::new(file, base + i + 1, base + close);
                let (is_var, name) = match inner.strip_prefix('?') {
                    Some(v) => (true, v),
                    None => (false, inner),
                };
                if name.is_empty() || !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-') {
                    return Err((format!("`{{{inner}}}` is not `{{?variable}}` or `{{capture}}`"), SimpleSpan::from(base + i..base + close + 1)));
                }
                if !text.is_empty() {
                    done += text.len();
                    parts.push(StrPart::Text { text: std::mem::take(&mut text) });
                }
                parts.push(if is_var {
                    StrPart::Var { name: Ident::new(Key::new(name).into_string(), span) }
                } else {
                    StrPart::Capture { name: Ident::new(name.to_owned(), span) }
                });
                while chars.peek().is_some_and(|(k, _)| *k <= close) {
                    chars.next();
                }
            }
            c => text.push(c),
        }
    }
    if !text.is_empty() || parts.is_empty() {
        parts.push(StrPart::Text { text });
    }
    Ok(StrLit {
        parts: exact(parts),
        span: Span::new(file, start, start + raw.len() + 2),
        escapes,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rules_files(dir: &std::path::Path, out: &mut Vec<std::path::PathBuf>) {
        for entry in std::fs::read_dir(dir).expect("a readable folder") {
            let path = entry.expect("a folder entry").path();
            if path.is_dir() {
                rules_files(&path, out);
            } else if path.extension().is_some_and(|e| e == "btrules") {
                out.push(path);
            }
        }
    }

    /// The quick parse (no error messages) is only sound if it fails
    /// exactly where the rich one reports errors, and reads what the rich
    /// one reads elsewhere: checked on every item of every rules file in
    /// the repository, the diagnostics fixtures' broken items included.
    #[test]
    fn quick_and_rich_parses_agree_on_every_item() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        let mut files = Vec::new();
        for dir in ["examples", "tests", "lang/tests", "stdlib", "lsp/tests"] {
            rules_files(&root.join(dir), &mut files);
        }
        let (mut items, mut broken) = (0, 0);
        for path in &files {
            let text = std::fs::read_to_string(path).expect("a UTF-8 rules file");
            let parsed = parse_rules(&text, 0);
            items += parsed.items.len();
            broken += usize::from(!parsed.diagnostics.is_empty());
            if let Some(d) = quick_and_rich_disagree(&text) {
                panic!("{}: {d}", path.display());
            }
        }
        assert!(
            files.len() > 50 && items > 500 && broken > 20,
            "{} files, {items} items, {broken} with errors",
            files.len()
        );
    }

    fn parse(text: &str) -> ParsedRules {
        parse_rules(text, 0)
    }

    fn codes(p: &ParsedRules) -> Vec<(&'static str, u32)> {
        p.diagnostics
            .iter()
            .map(|d| (d.code, d.span.start))
            .collect()
    }

    #[test]
    fn the_design_examples_parse_without_errors() {
        for text in [
            include_str!("../../../examples/ariac/rules.btrules"),
            include_str!("../../../examples/p3_assembler/rules.btrules"),
        ] {
            let p = parse(text);
            assert!(p.diagnostics.is_empty(), "{:#?}", p.diagnostics);
            assert!(p
                .items
                .iter()
                .all(|i| !matches!(*i.item, Item::Error { .. })));
        }
    }

    #[test]
    fn reads_patterns_guards_and_effects() {
        let p = parse("rule (PICK_{op} ?a [?loc]) where op in markers, ?a != ?loc {\n  Pick(agent: ?A, marker: markers[op])\n  effect (and (holding ?a) (not (free ?a)))\n}");
        assert!(p.diagnostics.is_empty(), "{:#?}", p.diagnostics);
        let Item::Rule(r) = &*p.items[0].item else {
            panic!()
        };
        assert_eq!(r.pattern.name_text(), "PICK_{op}");
        assert!(r.pattern.params[1].optional);
        assert_eq!(r.guards.len(), 2);
        let RuleBody::Template { body, effect } = &r.body else {
            panic!()
        };
        assert!(effect.is_some());
        let Template::Call { args, .. } = &body[0] else {
            panic!()
        };
        assert!(matches!(&args[0].value, Value::Var { name } if name.text == "a"));
        assert!(matches!(&args[1].value, Value::Lookup { .. }));
    }

    #[test]
    fn spans_are_relative_to_their_item() {
        let p = parse("action A()\n\naction B(x: int)");
        assert_eq!(p.items[1].offset, 12);
        let Item::Node(n) = &*p.items[1].item else {
            panic!()
        };
        assert_eq!(n.name.span, Span::new(0, 7, 8));
    }

    #[test]
    fn a_broken_item_does_not_hide_the_next_ones() {
        let text = "rule (move ?r ?a ?b) {\n  MoveTo(robot: ?r, target: )\n}\nrule (pick ?r) {\n  Pick(robot ?r)\n}\naction Pick(robot: robot)\n";
        let p = parse(text);
        assert_eq!(codes(&p).len(), 2, "{:#?}", p.diagnostics);
        assert_eq!(p.items.len(), 3);
        assert!(matches!(*p.items[2].item, Item::Node(_)));
    }

    #[test]
    fn a_missing_brace_is_recovered_at_the_next_line_start_keyword() {
        let text =
            "rule (move ?r ?a ?b) {\n  MoveTo(robot: ?r)\nrule (pick ?r) { Pick(robot: ?r) }\n";
        let p = parse(text);
        assert_eq!(p.items.len(), 2);
        assert_eq!(p.diagnostics.len(), 1, "{:#?}", p.diagnostics);
        assert!(matches!(*p.items[1].item, Item::Rule(_)));
    }

    #[test]
    fn interpolation_and_escapes() {
        let p = parse("tree T() { sequence \"move {?Robot} to {op} \\{x\\}\" { } }");
        assert!(p.diagnostics.is_empty(), "{:#?}", p.diagnostics);
        let Item::Tree(t) = &*p.items[0].item else {
            panic!()
        };
        let Template::Control { name: Some(s), .. } = &t.body[0] else {
            panic!()
        };
        assert_eq!(s.parts.len(), 5);
        assert!(matches!(&s.parts[1], StrPart::Var { name } if name.text == "robot"));
        assert!(matches!(&s.parts[4], StrPart::Text { text } if text == " {x}"));
    }

    #[test]
    fn escapes_map_offsets_in_the_text_back_into_the_file() {
        let src = r#"tree T() { sequence "a\"b\\c\n{?x}d" { } }"#;
        let p = parse(src);
        assert!(p.diagnostics.is_empty(), "{:#?}", p.diagnostics);
        let Item::Tree(t) = &*p.items[0].item else {
            panic!()
        };
        let Template::Control { name: Some(s), .. } = &t.body[0] else {
            panic!()
        };
        // a " b \ c \n: the escapes are the text's bytes 1, 3 and 5.
        assert_eq!(s.escapes, [1, 3, 5]);
        let open = src.find('"').unwrap();
        assert_eq!(s.span.start as usize, open);
        assert_eq!(s.source_offset(0), open + 1);
        // `b` comes after `\"`, `c` after two escapes, the newline is at its `\`.
        assert_eq!(&src[s.source_offset(2)..][..1], "b");
        assert_eq!(&src[s.source_offset(4)..][..1], "c");
        assert_eq!(&src[s.source_offset(5)..][..2], "\\n");
    }

    #[test]
    fn deep_nesting_is_refused_not_overflowed() {
        let text = format!(
            "plan {{ {} steps {} }}",
            "sequence { ".repeat(5000),
            "} ".repeat(5000)
        );
        let p = parse(&text);
        assert!(p.diagnostics.iter().any(|d| d.message.contains("nested")));
        let formula = format!(
            "condition C() = {}(p){}",
            "(not ".repeat(5000),
            ")".repeat(5000)
        );
        let p = parse(&formula);
        assert!(p.diagnostics.iter().any(|d| d.code == "P004"));
    }
}
