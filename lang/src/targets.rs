//! What an output target cannot express, found where the rules say it:
//! compiling for that target is refused with a diagnostic at each place,
//! never approximated. Emitters only see the IR, which has no spans, so
//! the refusals are found here, from the compiled tree and the rules.

use crate::db::{self, CompileJob, Db};
use crate::rules::ast::{Item, RuleBody, Template};
use crate::rules::name::Key;
use crate::rules::parse::shift;
use btc_ir::vocab::{DecoratorName, PyTrees};
use btc_ir::{Node, NodeScripts, TreeIr};
use btc_pddl::diagnostic::{codes, Diagnostic};
use btc_pddl::source::Span;

/// An output format with something it cannot express.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Target {
    /// A py_trees module (`--emit pytrees`).
    Pytrees,
}

/// A leaf btc's engine gives a meaning that a py_trees module has no
/// counterpart of, and why.
struct Unsupported {
    id: &'static str,
    why: &'static str,
    hint: &'static str,
}

/// `std::btcpp` leaves the py_trees runtime does not implement: as plain
/// simulated actions they would take ticks and skip what btc's engine does.
const NOT_IN_PYTREES: &[Unsupported] = &[
    Unsupported {
        id: "SetBlackboard",
        why: "writes a blackboard entry that later ports read as `{key}`; a py_trees module fills its ports in when the tree is built, so nothing would read the value",
        hint: "pass the value to the nodes that need it as a port, or emit BT.CPP XML (`--emit btcpp`)",
    },
    Unsupported {
        id: "Script",
        why: "runs BT.CPP script code; py_trees has no scripting language",
        hint: "write the script's work as a behaviour of your own, or emit BT.CPP XML (`--emit btcpp`)",
    },
    Unsupported {
        id: "ScriptCondition",
        why: "evaluates BT.CPP script code; py_trees has no scripting language",
        hint: "declare a `condition` defined by a PDDL formula instead, or emit BT.CPP XML (`--emit btcpp`)",
    },
];

/// A node's pre- and post-condition scripts (`[skip_if: "..."]`): the
/// py_trees runtime runs no scripts around its behaviours.
const SCRIPT_ATTRIBUTE: Unsupported = Unsupported {
    id: "",
    why: "is a BT.CPP script run around the node's tick; py_trees has no scripting language",
    hint: "emit BT.CPP XML (`--emit btcpp`), or express the condition as a `condition` node in a `fallback` or `sequence`",
};

/// Why `target` cannot express the tree `ir` compiled from `job`: one
/// diagnostic per place in the rules that uses something the target lacks
/// (none when it can express all of it).
pub fn refusals(db: &dyn Db, job: CompileJob, ir: &TreeIr, target: Target) -> Vec<Diagnostic> {
    let Target::Pytrees = target;
    let TreeUses {
        leaves: used,
        scripted,
        decorators: nodes,
    } = tree_uses(ir);
    if used.is_empty() && nodes.is_empty() && !scripted {
        return Vec::new();
    }
    let mut out = Vec::new();
    let (files, _) = db::import_closure(db, job.rules(db));
    for &file in files {
        if matches!(file.path(db), crate::path::FilePath::Std(_)) {
            continue;
        }
        let id = db::file_id(db, file);
        for node in db::own_items(db, file) {
            let mut found = Vec::new();
            for t in templates(&node.item) {
                calls(t, &mut found);
            }
            let mut decorators = Vec::new();
            for t in templates(&node.item) {
                decorators_in(t, &mut decorators);
            }
            for (d, span) in decorators {
                if let (true, PyTrees::NotExpressible { why }) =
                    (nodes.contains(&d), d.spec().pytrees)
                {
                    let d = Diagnostic::error(
                        codes::E_PYTREES_NODE,
                        span,
                        format!(
                            "a py_trees module cannot run `{}`, which {why}",
                            d.keyword()
                        ),
                    )
                    .with_hint("emit BT.CPP XML (`--emit btcpp`) or run it with `btc run`");
                    out.push(shift(d, id, node.offset));
                }
            }
            for (what, span) in found {
                let (what, u) = match what {
                    Use::Script(key) if scripted => (key, &SCRIPT_ATTRIBUTE),
                    Use::Call(name) => match used.iter().find(|u| name == Key::new(u.id)) {
                        Some(u) => (u.id, *u),
                        None => continue,
                    },
                    Use::Script(_) => continue,
                };
                let d = Diagnostic::error(
                    codes::E_PYTREES_NODE,
                    span,
                    format!("a py_trees module cannot run `{what}`, which {}", u.why),
                )
                .with_hint(u.hint);
                out.push(shift(d, id, node.offset));
            }
        }
    }
    out.sort_by_key(|d| (d.span.file, d.span.start));
    out
}

/// What the compiled tree (the main tree and the rules') uses that py_trees
/// lacks.
struct TreeUses {
    /// The leaves of [`NOT_IN_PYTREES`] it uses.
    leaves: Vec<&'static Unsupported>,
    /// Whether a node has pre- or post-condition scripts.
    scripted: bool,
    /// The decorators the vocabulary marks as not expressible in py_trees.
    decorators: Vec<DecoratorName>,
}

/// [`TreeUses`], in one walk: a long plan's main tree has a node a step.
fn tree_uses(ir: &TreeIr) -> TreeUses {
    let mut uses = TreeUses {
        leaves: Vec::new(),
        scripted: false,
        decorators: Vec::new(),
    };
    let mut look = |n: &Node| {
        uses.scripted |= match n {
            Node::Control { scripts, .. }
            | Node::Decorator { scripts, .. }
            | Node::Leaf { scripts, .. }
            | Node::SubTree { scripts, .. } => !scripts.is_empty(),
            Node::Step { .. } => false,
        };
        match n {
            Node::Leaf { id, .. } => {
                for u in NOT_IN_PYTREES.iter().filter(|u| u.id == id) {
                    if !uses.leaves.iter().any(|l| l.id == u.id) {
                        uses.leaves.push(u);
                    }
                }
            }
            Node::Decorator { decorator, .. } => {
                let name = decorator.name();
                if matches!(name.spec().pytrees, PyTrees::NotExpressible { .. })
                    && !uses.decorators.contains(&name)
                {
                    uses.decorators.push(name);
                }
            }
            _ => {}
        }
    };
    ir.root.walk_distinct(&mut look);
    for t in &ir.trees {
        t.root.walk(&mut look);
    }
    // In the order of NOT_IN_PYTREES, as the hints are looked up.
    uses.leaves
        .sort_by_key(|u| NOT_IN_PYTREES.iter().position(|n| n.id == u.id));
    uses
}

/// Every decorator in a template, with the span of its keyword.
fn decorators_in(t: &Template, out: &mut Vec<(DecoratorName, Span)>) {
    t.walk(&mut |t| {
        if let Template::Decorator {
            decorator, span, ..
        } = t
        {
            let word = decorator.keyword().len() as u32;
            out.push((
                *decorator,
                Span {
                    end: span.start + word,
                    ..*span
                },
            ));
        }
    });
}

/// The templates of an item: a rule's body, a tree's, the plan's.
fn templates(item: &Item) -> &[Template] {
    match item {
        Item::Rule(r) => match &r.body {
            RuleBody::Template { body, .. } => body,
            RuleBody::Skip { .. } => &[],
        },
        Item::Tree(t) => &t.body,
        Item::Plan { body, .. } => body,
        _ => &[],
    }
}

/// What a template uses that a target may lack.
enum Use {
    /// A leaf or tree, by name (`script` leaves as BT.CPP's `Script`).
    Call(Key),
    /// A pre- or post-condition, by its `.btrules` key.
    Script(&'static str),
}

/// Every call and script attribute in a template, with the span of its
/// name or attribute.
fn calls(t: &Template, out: &mut Vec<(Use, Span)>) {
    t.walk(&mut |t| match t {
        Template::Call { name, scripts, .. } => {
            out.push((Use::Call(name.key.clone()), name.span));
            for a in scripts {
                if let Some(k) = NodeScripts::key_index(&a.key.text) {
                    out.push((Use::Script(NodeScripts::KEYS[k]), a.span));
                }
            }
        }
        Template::Script {
            condition, span, ..
        } => {
            let id = if *condition {
                "ScriptCondition"
            } else {
                "Script"
            };
            out.push((Use::Call(Key::new(id)), *span));
        }
        Template::Control { .. }
        | Template::Decorator { .. }
        | Template::Steps { .. }
        | Template::Error { .. } => {}
    });
}
