//! Pictures of the tree that runs (subtree calls expanded): Graphviz DOT
//! and Mermaid. Shapes follow the usual BT notation: `→` sequence, `?`
//! fallback, `⇒` parallel; actions are boxes, conditions ovals.

use btc_ir::*;
use btc_ir::{ControlKind, DecoratorKind};

/// The vocabulary's label with the node's parameters filled in.
fn control_label(c: ControlKind) -> String {
    let values = c.params();
    let params = c.spec().params;
    c.spec().label_with(|p| {
        let i = params.iter().position(|q| q == p).unwrap_or(0);
        values.get(i).map_or_else(String::new, u32::to_string)
    })
}

fn decorator_label(d: &DecoratorKind) -> String {
    d.spec()
        .label_with(|_| d.count().map_or_else(String::new, Count::to_string))
}

fn leaf_label(id: &str, name: &Option<Label>, ports: &[Port]) -> String {
    let args: Vec<String> = ports
        .iter()
        .map(|p| format!("{}: {}", p.name, p.value.to_text()))
        .collect();
    let head = name
        .as_ref()
        .map_or_else(|| id.to_owned(), Label::to_string);
    if args.is_empty() {
        head
    } else {
        format!("{head}({})", args.join(", "))
    }
}

#[derive(Clone, Copy, PartialEq)]
enum Shape {
    Control,
    Decorator,
    Action,
    Condition,
    Step,
    SubTree,
}

/// Labelled nodes in depth-first order, and parent→child edges between them.
type Flat = (Vec<(String, Shape)>, Vec<(usize, usize)>);

/// Flattens the tree into (label, shape) nodes and parent→child edges.
fn flatten(root: &Node, ir: &TreeIr) -> Flat {
    let mut nodes = Vec::new();
    let mut edges = Vec::new();
    let mut stack: Vec<(&Node, Option<usize>)> = vec![(root, None)];
    while let Some((n, parent)) = stack.pop() {
        let id = nodes.len();
        if let Some(p) = parent {
            edges.push((p, id));
        }
        let (label, shape) = match n {
            Node::Control { control, name, .. } => {
                let l = control_label(*control);
                (
                    name.as_ref().map_or(l.clone(), |nm| format!("{l} {nm}")),
                    Shape::Control,
                )
            }
            Node::Decorator {
                decorator, name, ..
            } => {
                let l = decorator_label(decorator);
                (
                    name.as_ref().map_or(l.clone(), |nm| format!("{l} {nm}")),
                    Shape::Decorator,
                )
            }
            Node::Leaf {
                leaf,
                id,
                name,
                ports,
                ..
            } => (
                leaf_label(id, name, ports),
                if *leaf == LeafKind::Condition {
                    Shape::Condition
                } else {
                    Shape::Action
                },
            ),
            Node::SubTree { id, .. } => (id.clone(), Shape::SubTree),
            Node::Step { step, .. } => (
                ir.steps.get(*step).map_or_else(
                    || format!("step {}", step + 1),
                    |s| format!("step {}: {}", step + 1, s.display()),
                ),
                Shape::Step,
            ),
        };
        nodes.push((label, shape));
        let children: Vec<&Node> = match n {
            Node::Control { children, .. } => children.iter().collect(),
            Node::Decorator { child, .. } => vec![child],
            Node::Step { child, .. } => vec![child],
            _ => Vec::new(),
        };
        // Reversed so the stack pops them left to right.
        for c in children.into_iter().rev() {
            stack.push((c, Some(id)));
        }
    }
    edges.sort();
    (nodes, edges)
}

fn dot_escape(s: &str) -> String {
    s.replace('\\', "\\\\")
        .replace('"', "\\\"")
        .replace('\n', "\\n")
        .replace('\r', "")
}

pub fn emit_dot(ir: &TreeIr) -> String {
    let (nodes, edges) = flatten(&ir.inlined(), ir);
    let mut out = String::from(
        "digraph behavior_tree {\n  node [fontname=\"Helvetica\"];\n  edge [arrowhead=none];\n",
    );
    for (i, (label, shape)) in nodes.iter().enumerate() {
        let style = match shape {
            Shape::Control => "shape=box",
            Shape::Decorator => "shape=hexagon",
            Shape::Action => "shape=box, style=filled, fillcolor=\"#d9d9d9\"",
            Shape::Condition => "shape=ellipse",
            Shape::Step => "shape=note, style=dashed",
            Shape::SubTree => "shape=box, style=rounded",
        };
        out.push_str(&format!(
            "  n{i} [label=\"{}\", {style}];\n",
            dot_escape(label)
        ));
    }
    for (a, b) in edges {
        out.push_str(&format!("  n{a} -> n{b};\n"));
    }
    out.push_str("}\n");
    out
}

/// Mermaid labels: quotes and angle brackets as Mermaid entities, no newlines.
fn mermaid_escape(s: &str) -> String {
    let mut out = String::new();
    for c in s.chars() {
        match c {
            '"' => out.push_str("#quot;"),
            '<' => out.push_str("#lt;"),
            '>' => out.push_str("#gt;"),
            '#' => out.push_str("#35;"),
            '\n' | '\r' => out.push(' '),
            c => out.push(c),
        }
    }
    out
}

pub fn emit_mermaid(ir: &TreeIr) -> String {
    let (nodes, edges) = flatten(&ir.inlined(), ir);
    let mut out = String::from("flowchart TD\n");
    for (i, (label, shape)) in nodes.iter().enumerate() {
        let l = mermaid_escape(label);
        let node = match shape {
            Shape::Control => format!("n{i}[\"{l}\"]"),
            Shape::Decorator => format!("n{i}{{{{\"{l}\"}}}}"),
            Shape::Action => format!("n{i}[\"{l}\"]:::action"),
            Shape::Condition => format!("n{i}([\"{l}\"])"),
            Shape::Step => format!("n{i}>\"{l}\"]"),
            Shape::SubTree => format!("n{i}[[\"{l}\"]]"),
        };
        out.push_str(&format!("  {node}\n"));
    }
    for (a, b) in edges {
        out.push_str(&format!("  n{a} --> n{b}\n"));
    }
    out.push_str("  classDef action fill:#d9d9d9\n");
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escapes_labels() {
        assert_eq!(dot_escape("a\"b\\c\nd"), "a\\\"b\\\\c\\nd");
        assert_eq!(mermaid_escape("a\"<b>#\nc"), "a#quot;#lt;b#gt;#35; c");
    }
}
