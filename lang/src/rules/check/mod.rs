//! Checks of `.btrules` items against their declarations and the PDDL
//! domain. [`check_item`] looks at one item (spans relative to it: the
//! incremental database calls it per item); what needs the whole file
//! (duplicates, coverage, shadowing, unused names) is in `file_checks`.

mod effect;
mod rule;
mod template;
mod values;

pub use super::actions::matched_actions;
pub use super::decls::{condition_formula, Decls, DomainCtx, BASIC_TYPES};
pub use effect::rewrite_effect;
use rule::check_rule;
pub use rule::{rule_var_types, VarTypes};

use super::ast::*;
use btc_pddl::check::check_formula_in;
use btc_pddl::diagnostic::{closest, codes, Diagnostic};
use btc_pddl::source::{FileId, Span};
use btc_pddl::types::TypeId;
use std::collections::BTreeSet;
use values::Tcx;
use values::VType;

fn scope_of(vars: &[(String, Option<Vec<TypeId>>)]) -> Vec<(String, Vec<TypeId>)> {
    vars.iter()
        .map(|(v, t)| {
            (
                v.clone(),
                t.clone().unwrap_or_else(|| vec![btc_pddl::types::OBJECT]),
            )
        })
        .collect()
}

/// Checks one item. Spans in the result are relative to the item, like its tree.
pub fn check_item(
    item: &Item,
    decls: &Decls,
    ctx: Option<DomainCtx>,
    _file: FileId,
) -> Vec<Diagnostic> {
    match item {
        Item::Rule(r) => check_rule(r, decls, ctx),
        Item::Node(n) => check_node(n, ctx),
        Item::Tree(t) => {
            let mut diags = port_type_diags(&t.ports, ctx);
            diags.extend(tree_body_diags(t, decls, ctx, false));
            diags
        }
        Item::Plan { body, span } => {
            let mut tcx = Tcx {
                decls,
                ctx,
                vars: Vec::new(),
                captures: Vec::new(),
                basic: Vec::new(),
                in_plan: true,
                imported: false,
                diags: Vec::new(),
            };
            for b in body {
                tcx.template(b);
            }
            let steps = count_steps(body);
            if steps != 1 {
                tcx.err(
                    Diagnostic::error(
                        codes::R_PLAN_BLOCK,
                        *span,
                        if steps == 0 { "the `plan` block has no `steps`".to_owned() } else { format!("the `plan` block has `steps` {steps} times") },
                    )
                    .with_hint("write `steps` exactly once where the plan's steps go, e.g. `plan { sequence { steps } }`"),
                );
            }
            tcx.diags
        }
        Item::Table(t) => {
            let mut diags = Vec::new();
            let mut seen = BTreeSet::new();
            for e in &t.entries {
                if !seen.insert(&e.key.key) {
                    diags.push(Diagnostic::error(
                        codes::R_DUPLICATE,
                        e.key.span,
                        format!("key `{}` is in table `{}` twice", e.key.text, t.name.text),
                    ));
                }
            }
            diags
        }
        Item::Domain { .. } | Item::Problem { .. } | Item::Import { .. } | Item::Error { .. } => {
            Vec::new()
        }
    }
}

/// A tree imported from BT.CPP XML, checked as a `tree` of the importing
/// rules (its spans are the XML file's).
pub fn check_imported_tree(t: &TreeDecl, decls: &Decls, ctx: Option<DomainCtx>) -> Vec<Diagnostic> {
    tree_body_diags(t, decls, ctx, true)
}

/// What checking a tree's body against its ports says.
fn tree_body_diags(
    t: &TreeDecl,
    decls: &Decls,
    ctx: Option<DomainCtx>,
    imported: bool,
) -> Vec<Diagnostic> {
    let mut tcx = Tcx {
        decls,
        ctx,
        vars: port_vars(&t.ports, ctx),
        captures: Vec::new(),
        basic: basic_ports(&t.ports),
        in_plan: false,
        imported,
        diags: Vec::new(),
    };
    for b in &t.body {
        tcx.template(b);
    }
    tcx.diags
}

fn count_steps(body: &[Template]) -> usize {
    let mut steps = 0;
    Template::walk_all(body, &mut |t| {
        if let Template::Steps { .. } = t {
            steps += 1;
        }
    });
    steps
}

fn port_vars(ports: &[PortDecl], ctx: Option<DomainCtx>) -> Vec<(String, Option<Vec<TypeId>>)> {
    ports
        .iter()
        .map(|p| {
            let ty = ctx
                .and_then(|c| c.index.types.id(p.ty.key.as_str()))
                .map(|t| vec![t]);
            (p.name.key.clone().into_string(), ty)
        })
        .collect()
}

/// Tree ports of basic types, as the variables the tree's body uses.
fn basic_ports(ports: &[PortDecl]) -> Vec<(String, VType)> {
    ports
        .iter()
        .filter_map(|p| {
            let t = match p.ty.key.as_str() {
                "int" => VType::Int,
                "float" => VType::Float,
                "bool" => VType::Bool,
                "string" => VType::Str,
                _ => return None,
            };
            Some((p.name.key.clone().into_string(), t))
        })
        .collect()
}

fn port_type_diags(ports: &[PortDecl], ctx: Option<DomainCtx>) -> Vec<Diagnostic> {
    let mut diags = Vec::new();
    let mut seen = BTreeSet::new();
    for p in ports {
        if !seen.insert(p.name.text.clone()) {
            diags.push(Diagnostic::error(
                codes::R_DUPLICATE,
                p.name.span,
                format!("port `{}` is declared twice", p.name.text),
            ));
        }
        let ty = p.ty.text.as_str();
        if BASIC_TYPES.contains(&ty) {
            continue;
        }
        if let Some(c) = ctx {
            if c.index.types.id(p.ty.key.as_str()).is_none() {
                let candidates: Vec<&str> = c
                    .index
                    .types
                    .names()
                    .chain(BASIC_TYPES.iter().copied())
                    .collect();
                diags.push(unknown_name(
                    Diagnostic::error(
                        codes::R_UNKNOWN_TYPE,
                        p.ty.span,
                        format!("`{ty}` is neither a type of the domain nor a basic type"),
                    ),
                    ty,
                    candidates.iter().copied(),
                    str::to_owned,
                    || "port types are the domain's types or string, int, float, bool".into(),
                ));
            }
        }
    }
    diags
}

fn check_node(n: &NodeDecl, ctx: Option<DomainCtx>) -> Vec<Diagnostic> {
    let mut diags = port_type_diags(&n.ports, ctx);
    if let (Some(f), Some(c)) = (&n.formula, ctx) {
        let scope = scope_of(&port_vars(&n.ports, Some(c)));
        diags.extend(check_formula_in(c.domain, c.index, c.problem, f, &scope));
    }
    diags
}

/// A name not found where it should be declared or bound: `error`, with the
/// closest of the `known` names (as `written` spells it) as "did you mean"
/// and its fix, or `otherwise` as the hint.
fn unknown_name<'k>(
    error: Diagnostic,
    name: &str,
    known: impl IntoIterator<Item = &'k str>,
    written: impl FnOnce(&str) -> String,
    otherwise: impl FnOnce() -> String,
) -> Diagnostic {
    error.suggest(closest(name, known).map(written), otherwise)
}

/// R020 at `span` for `written`, an object name that is neither the
/// problem's nor a constant of the domain; the fix writes `candidate` as a
/// string literal.
fn unknown_object(written: &str, span: Span, candidate: Option<&str>) -> Diagnostic {
    let d = Diagnostic::error(
        codes::R_UNKNOWN_OBJECT,
        span,
        format!("`{written}` is not among the problem's objects or the domain's constants"),
    );
    match candidate {
        Some(c) => d.with_hint(format!("did you mean `{c}`?")).with_fix(
            format!("change to `{c}`"),
            span,
            format!("{c:?}"),
        ),
        None => d.with_hint("it names no object of the problem and no constant of the domain"),
    }
}
