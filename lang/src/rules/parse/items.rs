//! The items of a rules file, one production each: `domain`, `problem`,
//! `import`, node declarations, `tree`, `table`, `rule` (its pattern, guards
//! and body) and `plan`.

use super::grammar::{
    block_of, ident, kw, listed, literal, punct, spans, strlit, var, ItemError, Templates, Tokens,
};
use super::template::template;
use super::*;

/// One item, up to the end of its tokens.
pub(super) fn item_parser<'t, I: Tokens<'t>, R: ItemError<'t, I> + 't>(
    file: FileId,
) -> impl Parser<'t, I, Item, extra::Err<R>> {
    let template = template(file);
    choice((
        domain(file),
        problem(file),
        import(file),
        node(file),
        tree(template.clone(), file),
        table(file),
        rule(template.clone(), file),
        plan(template, file),
    ))
    .labelled(
        "an item: `domain`, `import`, `action`, `condition`, `tree`, `table`, `rule` or `plan`",
    )
    .then_ignore(end())
}

fn domain<'t, I: Tokens<'t>, R: ItemError<'t, I> + 't>(
    file: FileId,
) -> impl Parser<'t, I, Item, extra::Err<R>> + Clone {
    path_item("domain", file, |path, span| Item::Domain { path, span })
}

fn problem<'t, I: Tokens<'t>, R: ItemError<'t, I> + 't>(
    file: FileId,
) -> impl Parser<'t, I, Item, extra::Err<R>> + Clone {
    path_item("problem", file, |path, span| Item::Problem { path, span })
}

/// `domain "FILE"` and `problem "FILE"`: a keyword and a path.
fn path_item<'t, I: Tokens<'t>, R: ItemError<'t, I> + 't>(
    word: &'static str,
    file: FileId,
    make: fn(StrLit, Span) -> Item,
) -> impl Parser<'t, I, Item, extra::Err<R>> + Clone {
    let sp = spans(file);
    kw(word)
        .ignore_then(strlit(file))
        .map_with(move |path, e| make(path, sp(e.span())))
}

fn import<'t, I: Tokens<'t>, R: ItemError<'t, I> + 't>(
    file: FileId,
) -> impl Parser<'t, I, Item, extra::Err<R>> + Clone {
    let sp = spans(file);
    kw("import")
        .ignore_then(choice((
            strlit(file)
                .then(kw("as").ignore_then(ident(file)).or_not())
                .map(|(path, alias)| ImportTarget::Path { path, alias }),
            kw("std")
                .ignore_then(punct("::"))
                .ignore_then(ident(file))
                .map(|module| ImportTarget::Std { module }),
        )))
        .map_with(move |target, e| Item::Import {
            target,
            span: sp(e.span()),
        })
}

/// A port list: `(robot: robot, out pose: string)`.
fn ports<'t, I: Tokens<'t>, R: ItemError<'t, I> + 't>(
    file: FileId,
) -> impl Parser<'t, I, Vec<PortDecl>, extra::Err<R>> + Clone {
    let sp = spans(file);
    let port = kw("out")
        .or_not()
        .then(ident(file))
        .then_ignore(punct(":"))
        .then(ident(file))
        .map_with(move |((out, name), ty), e| PortDecl {
            out: out.is_some(),
            name,
            ty,
            span: sp(e.span()),
        });
    listed(port, "(", ")").labelled("a port list such as `(robot: robot)`")
}

/// `action NAME(ports)` or `condition NAME(ports) = (formula)`.
fn node<'t, I: Tokens<'t>, R: ItemError<'t, I> + 't>(
    file: FileId,
) -> impl Parser<'t, I, Item, extra::Err<R>> + Clone {
    let sp = spans(file);
    let formula = select! { Tok::Formula(f) => Some(*f), Tok::BadPddl => None }
        .labelled("a PDDL formula in parentheses");
    choice((
        kw("action").to(NodeKind::Action),
        kw("condition").to(NodeKind::Condition),
    ))
    .then(ident(file))
    .then(ports(file))
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
    })
}

fn tree<'t, I: Tokens<'t>, R: ItemError<'t, I> + 't, T: Templates<'t, I, R>>(
    template: T,
    file: FileId,
) -> impl Parser<'t, I, Item, extra::Err<R>> + Clone {
    let sp = spans(file);
    kw("tree")
        .ignore_then(ident(file))
        .then(ports(file))
        .then(block_of(template, file))
        .map_with(move |((name, ports), body), e| {
            Item::Tree(TreeDecl {
                name,
                ports,
                body,
                span: sp(e.span()),
            })
        })
}

fn table<'t, I: Tokens<'t>, R: ItemError<'t, I> + 't>(
    file: FileId,
) -> impl Parser<'t, I, Item, extra::Err<R>> + Clone {
    let sp = spans(file);
    kw("table")
        .ignore_then(ident(file))
        .then(listed(
            ident(file)
                .then_ignore(punct(":"))
                .then(literal(file))
                .map(|(key, value)| TableEntry { key, value }),
            "{",
            "}",
        ))
        .map_with(move |(name, entries), e| {
            Item::Table(TableDecl {
                name,
                entries,
                span: sp(e.span()),
            })
        })
}

/// `rule (pattern) where guards { templates effect (...) }` or
/// `rule (pattern) => skip`.
fn rule<'t, I: Tokens<'t>, R: ItemError<'t, I> + 't, T: Templates<'t, I, R>>(
    template: T,
    file: FileId,
) -> impl Parser<'t, I, Item, extra::Err<R>> + Clone {
    let sp = spans(file);
    kw("rule")
        .ignore_then(pattern(file))
        .then(
            kw("where")
                .ignore_then(
                    guard(file)
                        .separated_by(punct(","))
                        .at_least(1)
                        .collect::<Vec<_>>()
                        .map(exact),
                )
                .or_not(),
        )
        .then(rule_body(template, file))
        .map_with(move |((pattern, guards), body), e| {
            Item::Rule(Rule {
                pattern,
                guards: guards.unwrap_or_default(),
                body,
                span: sp(e.span()),
            })
        })
}

/// A rule's action pattern: its name and parameters (`[?x]` optional).
fn pattern<'t, I: Tokens<'t>, R: ItemError<'t, I> + 't>(
    file: FileId,
) -> impl Parser<'t, I, Pattern, extra::Err<R>> + Clone {
    let sp = spans(file);
    let param = choice((
        var(file).map_with(move |var, e| Param {
            var,
            optional: false,
            span: sp(e.span()),
        }),
        var(file)
            .delimited_by(punct("["), punct("]"))
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
    name_pattern
        .then(param.repeated().collect::<Vec<_>>().map(exact))
        .delimited_by(punct("("), punct(")"))
        .map_with(move |(name, params), e| Pattern {
            name,
            params,
            span: sp(e.span()),
        })
        .labelled("an action pattern such as `(move ?robot ?from ?to)`")
}

/// A guard: `?a != ?b`, `?a == "obj"`, `?a - type`, `capture in table`.
fn guard<'t, I: Tokens<'t>, R: ItemError<'t, I> + 't>(
    file: FileId,
) -> impl Parser<'t, I, Guard, extra::Err<R>> + Clone {
    let sp = spans(file);
    // `"floor_robot"`: a plain string names an object or constant.
    let object = strlit(file)
        .try_map(|s: StrLit, span| match s.plain() {
            Some(text) => Ok(Ident::new(text, s.span)),
            None => Err(R::custom(
                span,
                "a guard compares with an object's name: a string without `{...}`".into(),
            )),
        })
        .map(|name| Operand::Object { name });
    let operand = choice((var(file).map(|name| Operand::Var { name }), object))
        .labelled("a variable or an object name in quotes");
    choice((
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
        var(file)
            .then_ignore(punct("-"))
            .then(ident(file))
            .map_with(move |(var, ty), e| Guard::IsType {
                var,
                ty,
                span: sp(e.span()),
            }),
        ident(file)
            .then_ignore(kw("in"))
            .then(ident(file))
            .map_with(move |(key, table), e| Guard::InTable {
                key,
                table,
                span: sp(e.span()),
            }),
    ))
    .labelled("a guard such as `?a != ?b`")
}

/// `=> skip`, or templates in braces and an optional `effect`; a body
/// that does not parse becomes one error node.
fn rule_body<'t, I: Tokens<'t>, R: ItemError<'t, I> + 't, T: Templates<'t, I, R>>(
    template: T,
    file: FileId,
) -> impl Parser<'t, I, RuleBody, extra::Err<R>> + Clone {
    let sp = spans(file);
    let effect = select! { Tok::Effect(f) => Some(*f), Tok::BadPddl => None }
        .labelled("a PDDL effect in parentheses");
    choice((
        punct("=>")
            .ignore_then(kw("skip"))
            .map_with(move |_, e| RuleBody::Skip { span: sp(e.span()) }),
        template
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
    ))
}

fn plan<'t, I: Tokens<'t>, R: ItemError<'t, I> + 't, T: Templates<'t, I, R>>(
    template: T,
    file: FileId,
) -> impl Parser<'t, I, Item, extra::Err<R>> + Clone {
    let sp = spans(file);
    kw("plan")
        .ignore_then(block_of(template, file))
        .map_with(move |body, e| Item::Plan {
            body,
            span: sp(e.span()),
        })
}
