//! The grammar's pieces every production uses: the error type the item
//! parser is generic over, keywords and punctuation, brackets with
//! recovery, and the terminals (names, variables, numbers, strings) and
//! values.

use super::strings::interpolate;
use super::*;

/// What the item parser reads: an item's tokens, spans relative to it.
pub(super) trait Tokens<'t>: ValueInput<'t, Token = Tok, Span = SimpleSpan> {}

impl<'t, I: ValueInput<'t, Token = Tok, Span = SimpleSpan>> Tokens<'t> for I {}

/// A template parser, as the productions that hold templates are given it.
pub(super) trait Templates<'t, I: Tokens<'t>, R: ItemError<'t, I> + 't>:
    Parser<'t, I, Template, extra::Err<R>> + Clone + 't
{
}

impl<'t, I: Tokens<'t>, R: ItemError<'t, I> + 't, T> Templates<'t, I, R> for T where
    T: Parser<'t, I, Template, extra::Err<R>> + Clone + 't
{
}

/// What the item parser needs of its error type: chumsky's error, labels,
/// and messages of its own. Two types have it: [`Rich`], what users read,
/// and [`EmptyErr`], for a first attempt that builds no expected-token
/// sets as alternatives fail (most of a parse's work otherwise), since
/// nearly every item parses without errors. An item that has errors is
/// parsed again with [`Rich`]; the error type does not steer the parse, so
/// an item without errors reads the same either way.
pub(super) trait ItemError<'t, I: Input<'t, Span = SimpleSpan>>:
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

pub(super) fn kw<'t, I: Tokens<'t>, R: ItemError<'t, I> + 't>(
    word: &'static str,
) -> impl Parser<'t, I, (), extra::Err<R>> + Clone {
    just(Tok::Ident(SmolStr::new_static(word)))
        .ignored()
        .labelled(word)
}

/// Templates in braces; a block that does not parse becomes one error
/// node and parsing goes on after its closing brace.
pub(super) fn block_of<'t, I: Tokens<'t>, R: ItemError<'t, I> + 't>(
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

pub(super) fn punct<'t, I: Tokens<'t>, R: ItemError<'t, I> + 't>(
    p: &'static str,
) -> impl Parser<'t, I, (), extra::Err<R>> + Clone {
    just(Tok::Punct(p)).ignored()
}

/// `p`s separated by commas (a trailing one allowed) between `open` and
/// `close`: ports, arguments, scripts, a table's entries.
pub(super) fn listed<'t, I, R, T, P>(
    p: P,
    open: &'static str,
    close: &'static str,
) -> impl Parser<'t, I, Vec<T>, extra::Err<R>> + Clone
where
    I: Tokens<'t>,
    R: ItemError<'t, I> + 't,
    P: Parser<'t, I, T, extra::Err<R>> + Clone,
{
    p.separated_by(punct(","))
        .allow_trailing()
        .collect::<Vec<_>>()
        .map(exact)
        .delimited_by(punct(open), punct(close))
}

/// Spans of `file` from the parser's relative ones.
pub(super) fn spans(file: FileId) -> impl Fn(SimpleSpan) -> Span + Copy {
    move |s: SimpleSpan| Span::new(file, s.start, s.end)
}

pub(super) fn ident<'t, I: Tokens<'t>, R: ItemError<'t, I> + 't>(
    file: FileId,
) -> impl Parser<'t, I, Ident, extra::Err<R>> + Copy {
    let sp = spans(file);
    select! { Tok::Ident(s) => s }
        .map_with(move |text: SmolStr, e| Ident::new(text.into(), sp(e.span())))
        .labelled("a name")
}

/// Variables are PDDL's, so they are shown (and compared) folded.
pub(super) fn var<'t, I: Tokens<'t>, R: ItemError<'t, I> + 't>(
    file: FileId,
) -> impl Parser<'t, I, Ident, extra::Err<R>> + Copy {
    let sp = spans(file);
    select! { Tok::Var(s) => s }
        .map_with(move |text: SmolStr, e| Ident::new(Key::new(&text).into_string(), sp(e.span())))
        .labelled("a variable")
}

pub(super) fn int<'t, I: Tokens<'t>, R: ItemError<'t, I> + 't>(
) -> impl Parser<'t, I, i64, extra::Err<R>> + Copy {
    select! { Tok::Int(n) => n }.labelled("a whole number")
}

pub(super) fn count<'t, I: Tokens<'t>, R: ItemError<'t, I> + 't>(
) -> impl Parser<'t, I, u32, extra::Err<R>> + Copy {
    int().try_map(|n, span| {
        u32::try_from(n)
            .map_err(|_| R::custom(span, "expected a count from 0 to 4294967295".into()))
    })
}

/// A bad escape or interpolation is reported, and the string still
/// parses (as its raw text): failing here would let chumsky merge the
/// error into "expected a string, found a string".
pub(super) fn strlit<'t, I: Tokens<'t>, R: ItemError<'t, I> + 't>(
    file: FileId,
) -> impl Parser<'t, I, StrLit, extra::Err<R>> + Copy {
    select! { Tok::Str(s) => s }
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
        .labelled("a string")
}

/// A table's value.
pub(super) fn literal<'t, I: Tokens<'t>, R: ItemError<'t, I> + 't>(
    file: FileId,
) -> impl Parser<'t, I, Literal, extra::Err<R>> + Clone {
    let sp = spans(file);
    choice((
        int().map_with(move |value, e| Literal::Int {
            value,
            span: sp(e.span()),
        }),
        select! { Tok::Float(f) => f }.map_with(move |value, e| Literal::Float {
            value,
            span: sp(e.span()),
        }),
        strlit(file).map(|value| Literal::Str { value }),
        kw("true").map_with(move |_, e| Literal::Bool {
            value: true,
            span: sp(e.span()),
        }),
        kw("false").map_with(move |_, e| Literal::Bool {
            value: false,
            span: sp(e.span()),
        }),
        ident(file).map(|name| Literal::Name { name }),
    ))
    .labelled("a value")
}

/// A value given to a port or a decorator: a literal, a variable, a
/// capture's name, or a table lookup.
pub(super) fn value<'t, I: Tokens<'t>, R: ItemError<'t, I> + 't>(
    file: FileId,
) -> impl Parser<'t, I, Value, extra::Err<R>> + Clone {
    let sp = spans(file);
    let ident = ident(file);
    recursive(move |value| {
        choice((
            var(file).map(|name| Value::Var { name }),
            strlit(file).map(|value| Value::Str { value }),
            int().map_with(move |value, e| Value::Int {
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
    })
}
