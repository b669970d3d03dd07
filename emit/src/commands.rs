//! Canonical robot commands (the NIST executor): the action leaves in the
//! order a nominal run executes them, one JSON object per line. Conditions
//! and btc's KB nodes issue no command; a fallback runs its first child
//! that issues any; a
//! `repeat(n)` repeats its child's commands n times.

use btc_ir::*;
use btc_ir::{ControlKind, DecoratorKind};
use serde_json::{json, Map, Value};

const KB_NODES: &[&str] = &["KbHolds", "KbApply", "WaitForStep"];

fn port_json(v: &PortValue) -> Value {
    match v {
        PortValue::Text(s) => json!(s),
        PortValue::Int(n) => json!(n),
        PortValue::Float(f) => json!(f),
        PortValue::Bool(b) => json!(b),
        PortValue::Param(_) | PortValue::Formula(_) | PortValue::Effect(_) => json!(v.to_text()),
    }
}

fn walk(n: &Node, step: Option<usize>, ir: &TreeIr, out: &mut Vec<Value>) {
    match n {
        Node::Control {
            control, children, ..
        } => match control {
            // Nominally a fallback's first child that does anything runs
            // (in a backchained step, the "done?" check fails first).
            ControlKind::Fallback | ControlKind::ReactiveFallback => {
                for c in children {
                    let before = out.len();
                    walk(c, step, ir, out);
                    if out.len() > before {
                        break;
                    }
                }
            }
            _ => children.iter().for_each(|c| walk(c, step, ir, out)),
        },
        Node::Decorator {
            decorator, child, ..
        } => {
            // A count left as a port (a call btc could not inline) runs once.
            let times = match decorator {
                DecoratorKind::Repeat { times } => times.fixed().unwrap_or(1),
                _ => 1,
            };
            for _ in 0..times {
                walk(child, step, ir, out);
            }
        }
        Node::Leaf {
            leaf: LeafKind::Action,
            id,
            ports,
            ..
        } if !KB_NODES.contains(&id.as_str()) => {
            let mut args = Map::new();
            for p in ports {
                args.insert(p.name.clone(), port_json(&p.value));
            }
            let info = step.and_then(|s| ir.steps.get(s));
            out.push(json!({
                "seq": out.len() + 1,
                "command": id,
                "args": args,
                "step": step.map(|s| s + 1),
                "action": info.map(StepInfo::display),
                "line": info.map(|s| s.line),
            }));
        }
        Node::Leaf { .. } | Node::SubTree { .. } => {}
        Node::Step { step, child } => walk(child, Some(*step), ir, out),
    }
}

pub fn emit(ir: &TreeIr) -> String {
    let mut cmds = Vec::new();
    walk(&ir.inlined(), None, ir, &mut cmds);
    let mut out = String::new();
    for c in cmds {
        out.push_str(&serde_json::to_string(&c).expect("json"));
        out.push('\n');
    }
    out
}
