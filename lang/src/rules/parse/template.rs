//! Templates: a control with its block, a decorator and the template it
//! decorates, `steps`, a script, and a call with its arguments and scripts.

use super::grammar::{
    block_of, count, ident, kw, listed, punct, spans, strlit, value, ItemError, Templates, Tokens,
};
use super::*;

/// A template, recursive through blocks and decorators.
pub(super) fn template<'t, I: Tokens<'t>, R: ItemError<'t, I> + 't>(
    file: FileId,
) -> impl Parser<'t, I, Template, extra::Err<R>> + Clone {
    recursive(move |template| {
        choice((
            steps(file),
            control(template.clone(), file),
            decorator(template, file),
            script(file),
            call(file),
        ))
        .labelled("a node, a control such as `sequence`, or a decorator")
    })
}

/// A control keyword of the vocabulary, and its parameters by name
/// (`parallel(success: 2, failure: 1)`), all of them, in its order; then
/// its name and its block.
fn control<'t, I: Tokens<'t>, R: ItemError<'t, I> + 't, T: Templates<'t, I, R>>(
    template: T,
    file: FileId,
) -> impl Parser<'t, I, Template, extra::Err<R>> + Clone {
    let sp = spans(file);
    let block = block_of(template, file);
    let control_name = select! {
        Tok::Ident(s) if ControlName::from_keyword(&s).is_some() => s,
    }
    .map(|s| ControlName::from_keyword(&s).expect("selected"));
    let control_args = select! { Tok::Ident(s) => s }
        .then_ignore(punct(":"))
        .then(count())
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
    control_kind
        .then(strlit(file).or_not())
        .then(block)
        .map_with(move |((control, name), children), e| Template::Control {
            control,
            name,
            children,
            span: sp(e.span()),
        })
}

/// A decorator, its arguments, its name and the template it decorates.
/// Arguments are read for every decorator and checked against its
/// parameter by the checker, which can say what is wrong.
fn decorator<'t, I: Tokens<'t>, R: ItemError<'t, I> + 't, T: Templates<'t, I, R>>(
    template: T,
    file: FileId,
) -> impl Parser<'t, I, Template, extra::Err<R>> + Clone {
    let sp = spans(file);
    let decorator_arg = ident(file)
        .then_ignore(punct(":"))
        .or_not()
        .then(value(file))
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
    decorator_name
        .then(listed(decorator_arg, "(", ")").or_not())
        .then(strlit(file).or_not())
        .then(template)
        .map_with(
            move |(((decorator, args), name), child), e| Template::Decorator {
                decorator,
                args: args.unwrap_or_default(),
                name,
                child: Box::new(child),
                span: sp(e.span()),
            },
        )
}

/// `steps`, `steps parallel`, `steps backchained`, `steps scheduled`.
fn steps<'t, I: Tokens<'t>, R: ItemError<'t, I> + 't>(
    file: FileId,
) -> impl Parser<'t, I, Template, extra::Err<R>> + Clone {
    let sp = spans(file);
    kw("steps")
        .ignore_then(
            choice((
                kw("parallel")
                    .then_ignore(punct("(").not().rewind())
                    .to(StepsMode::Parallel),
                kw("backchained").to(StepsMode::Backchained),
                kw("scheduled").to(StepsMode::Scheduled),
            ))
            .or_not(),
        )
        .map_with(move |mode, e| Template::Steps {
            mode: mode.unwrap_or(StepsMode::InOrder),
            span: sp(e.span()),
        })
}

/// A call of a node or tree: `name(port: value, ...)` and its scripts
/// `[key: "script", ...]`.
fn call<'t, I: Tokens<'t>, R: ItemError<'t, I> + 't>(
    file: FileId,
) -> impl Parser<'t, I, Template, extra::Err<R>> + Clone {
    let sp = spans(file);
    let arg = ident(file)
        .then_ignore(punct(":"))
        .then(value(file))
        .map(|(port, value)| Arg { port, value });
    let script_attr = ident(file)
        .then_ignore(punct(":"))
        .then(strlit(file))
        .map_with(move |(key, code), e| ScriptAttr {
            key,
            code,
            span: sp(e.span()),
        });
    let script_attrs =
        listed(script_attr, "[", "]").labelled("scripts such as `[skip_if: \"done == true\"]`");
    ident(file)
        .then(listed(arg, "(", ")"))
        .then(script_attrs.or_not())
        .map_with(move |((name, args), scripts), e| Template::Call {
            name,
            args,
            scripts: scripts.unwrap_or_default(),
            label: None,
            span: sp(e.span()),
        })
}

/// A node called `script(...)` is still a call: the leaf is the keyword
/// followed by a string.
fn script<'t, I: Tokens<'t>, R: ItemError<'t, I> + 't>(
    file: FileId,
) -> impl Parser<'t, I, Template, extra::Err<R>> + Clone {
    let sp = spans(file);
    choice((kw("script").to(false), kw("script_condition").to(true)))
        .then(strlit(file))
        .map_with(move |(condition, code), e| Template::Script {
            condition,
            code,
            span: sp(e.span()),
        })
}
