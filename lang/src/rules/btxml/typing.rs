//! An imported file's trees as `tree` declarations of the importing rules:
//! named (by the import's `as` name, or by their IDs), their `<SubTree>`
//! calls pointed at those names, their ports found and typed from the
//! declarations the importing file sees.

use super::super::ast::*;
use super::super::decls::Decls;
use super::{XmlTrees, AUTOREMAP, SUBTREE_PREFIX};
use std::collections::BTreeMap;

/// What each tree of the file is called in the importing rules: with an
/// `as` name, the main tree takes it and the others `NAME::ID` (which no
/// rule can call: they are the main tree's parts); without, each its ID.
/// `Err` says why an `as` name picks no tree.
pub fn tree_names(x: &XmlTrees, alias: Option<&Ident>) -> Result<Vec<String>, String> {
    let Some(alias) = alias else {
        return Ok(x.trees.iter().map(|t| t.id.text.clone()).collect());
    };
    let Some(main) = x.main_tree() else {
        return Err(if x.trees.is_empty() {
            "this file has no <BehaviorTree> for `as` to name".to_owned()
        } else {
            format!(
                "this file has {} trees and no `main_tree_to_execute`, so `as {}` names none of them",
                x.trees.len(),
                alias.text
            )
        });
    };
    Ok(x.trees
        .iter()
        .map(|t| {
            if t.id.text == main.id.text {
                alias.text.clone()
            } else {
                format!("{}::{}", alias.text, t.id.text)
            }
        })
        .collect())
}

/// The file's trees as declarations under `names` (from [`tree_names`]),
/// each after the trees it calls. A tree's ports are the blackboard keys
/// its nodes' ports are bound to (`{arg2}` is the port `arg2`), in the
/// order they first appear, typed by the first port each is bound to; a
/// key bound only to output ports is an output port (a call may leave it
/// out). A key only undeclared nodes read is a `string`.
pub fn imported_trees(x: &XmlTrees, names: &[String], decls: &Decls) -> Vec<TreeDecl> {
    let by_id: BTreeMap<&str, usize> = x
        .trees
        .iter()
        .enumerate()
        .map(|(k, t)| (t.id.text.as_str(), k))
        .collect();
    let mut typed: Vec<Option<TreeDecl>> = vec![None; x.trees.len()];
    for k in callee_first(x, &by_id) {
        let t = &x.trees[k];
        let mut ports = Ports::default();
        let body = t
            .body
            .iter()
            .map(|b| retype(b, decls, &by_id, names, &typed, &mut ports))
            .collect();
        typed[k] = Some(TreeDecl {
            name: Ident::new(names[k].clone(), t.id.span),
            ports: ports.decls,
            body,
            span: t.span,
        });
    }
    typed.into_iter().flatten().collect()
}

/// Trees in an order where each comes after the trees it calls (a tree
/// in a cycle, reported by the reader, after the ones it could).
fn callee_first(x: &XmlTrees, by_id: &BTreeMap<&str, usize>) -> Vec<usize> {
    let calls: Vec<Vec<usize>> = x
        .trees
        .iter()
        .map(|t| {
            let mut c = Vec::new();
            Template::walk_all(&t.body, &mut |t| {
                if let Template::Call { name, .. } = t {
                    if let Some(k) = name
                        .text
                        .strip_prefix(SUBTREE_PREFIX)
                        .and_then(|id| by_id.get(id))
                    {
                        c.push(*k);
                    }
                }
            });
            c
        })
        .collect();
    // 0: not seen, 1: on the path, 2: placed.
    let mut state = vec![0u8; x.trees.len()];
    let mut order = Vec::new();
    for root in 0..x.trees.len() {
        if state[root] != 0 {
            continue;
        }
        let mut stack = vec![(root, 0usize)];
        state[root] = 1;
        while let Some((k, next)) = stack.pop() {
            if let Some(&c) = calls[k].get(next) {
                stack.push((k, next + 1));
                if state[c] == 0 {
                    state[c] = 1;
                    stack.push((c, 0));
                }
            } else {
                state[k] = 2;
                order.push(k);
            }
        }
    }
    order
}

/// A tree's ports as they are found.
#[derive(Default)]
struct Ports {
    decls: Vec<PortDecl>,
}

impl Ports {
    /// `key` is bound to a port of type `ty` (an output port when `out`).
    fn bound(&mut self, key: &Ident, ty: &str, out: bool) {
        match self.decls.iter_mut().find(|p| p.name.text == key.text) {
            Some(p) => p.out &= out,
            None => self.decls.push(PortDecl {
                out,
                name: key.clone(),
                ty: Ident::new(ty.to_owned(), key.span),
                span: key.span,
            }),
        }
    }
}

/// A template of an imported tree with its `<SubTree>` calls named,
/// `_autoremap` spelt out and literal texts read as the numbers and
/// booleans their ports take; the keys it binds recorded as ports.
fn retype(
    t: &Template,
    decls: &Decls,
    by_id: &BTreeMap<&str, usize>,
    names: &[String],
    typed: &[Option<TreeDecl>],
    ports: &mut Ports,
) -> Template {
    match t {
        Template::Control {
            control,
            name,
            children,
            span,
        } => Template::Control {
            control: *control,
            name: name.clone(),
            children: children
                .iter()
                .map(|c| retype(c, decls, by_id, names, typed, ports))
                .collect(),
            span: *span,
        },
        Template::Decorator {
            decorator,
            args,
            name,
            child,
            span,
        } => {
            for a in args {
                if let Value::Var { name } = &a.value {
                    ports.bound(name, "int", false);
                }
            }
            Template::Decorator {
                decorator: *decorator,
                args: args.clone(),
                name: name.clone(),
                child: Box::new(retype(child, decls, by_id, names, typed, ports)),
                span: *span,
            }
        }
        Template::Call {
            name,
            args,
            scripts,
            label,
            span,
        } => {
            let (called, callee_ports): (Ident, Vec<PortDecl>) =
                match name.text.strip_prefix(SUBTREE_PREFIX) {
                    Some(id) => match by_id.get(id) {
                        Some(&k) => (
                            Ident::new(names[k].clone(), name.span),
                            typed[k]
                                .as_ref()
                                .map(|d| d.ports.clone())
                                .unwrap_or_default(),
                        ),
                        // Reported by the reader (R073); left as written.
                        None => (name.clone(), Vec::new()),
                    },
                    None => (
                        name.clone(),
                        decls
                            .ports(&name.text)
                            .map(<[_]>::to_vec)
                            .unwrap_or_default(),
                    ),
                };
            let mut out_args = Vec::new();
            let mut autoremap = false;
            for a in args {
                if a.port.text == AUTOREMAP {
                    autoremap = true;
                    continue;
                }
                let port = callee_ports.iter().find(|p| p.name.text == a.port.text);
                let value = match (&a.value, port) {
                    (Value::Var { name: key }, Some(p)) => {
                        ports.bound(key, &p.ty.text, p.out);
                        a.value.clone()
                    }
                    (Value::Var { name: key }, None) => {
                        ports.bound(key, "string", false);
                        a.value.clone()
                    }
                    (Value::Str { value }, Some(p)) => typed_literal(value, &p.ty.text),
                    _ => a.value.clone(),
                };
                out_args.push(Arg {
                    port: a.port.clone(),
                    value,
                });
            }
            if autoremap {
                // BT.CPP's `_autoremap`: each port of the called tree not
                // remapped reads the caller's entry of the same name.
                for p in &callee_ports {
                    if !out_args.iter().any(|a| a.port.text == p.name.text) {
                        let key = Ident::new(p.name.text.clone(), *span);
                        ports.bound(&key, &p.ty.text, p.out);
                        out_args.push(Arg {
                            port: key.clone(),
                            value: Value::Var { name: key },
                        });
                    }
                }
            }
            Template::Call {
                name: called,
                args: out_args,
                scripts: scripts.clone(),
                label: label.clone(),
                span: *span,
            }
        }
        other => other.clone(),
    }
}

/// The text of an XML attribute as the value its port's type reads, as
/// BT.CPP converts it; a text that is no such value stays text, which the
/// checker then refuses (R004) at the attribute.
fn typed_literal(s: &StrLit, ty: &str) -> Value {
    let text = s.plain().unwrap_or_default();
    let t = text.trim();
    let span = s.span;
    match ty {
        "int" => t.parse().ok().map(|value| Value::Int { value, span }),
        "float" => t.parse().ok().map(|value| Value::Float { value, span }),
        "bool" => match t {
            "true" => Some(Value::Bool { value: true, span }),
            "false" => Some(Value::Bool { value: false, span }),
            _ => None,
        },
        _ => None,
    }
    .unwrap_or_else(|| Value::Str { value: s.clone() })
}
