//! One item parsed: its tokens prepared (relative spans, PDDL groups and
//! name patterns read, nesting measured), then parsed quickly without error
//! messages, and again with them only when it has errors. The two parsers
//! of a file are built once per thread.

use super::items::item_parser;
use super::tokens::{read_name_pattern, read_pddl_group, rel};
use super::*;

/// Parses one item's tokens, which it takes out of `tokens` (a token
/// passed on to the parser is moved, not copied): first without building
/// error messages, then, only for an item that has errors, again with them.
pub(super) fn parse_item(
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
        diags.push(crate::rules::typo::keyword_hint(d, &input));
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
