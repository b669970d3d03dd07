//! A BT.CPP v4 file's `<BehaviorTree>` elements as templates, read
//! iteratively (nesting capped as the rules' own templates are).

use super::super::ast::*;
use super::super::palette::{attrs, get, Attr};
use super::{XmlTree, XmlTrees, AUTOREMAP, SUBTREE_PREFIX};
use btc_ir::vocab::{Arity, NodeName, NodeSpec, NODES};
use btc_ir::NodeScripts;
use btc_pddl::diagnostic::{closest, codes, Diagnostic};
use btc_pddl::source::{FileId, Span};
use quick_xml::events::Event;
use quick_xml::Reader;

/// Attributes BT.CPP writes for its editors and logs; they change nothing
/// a tree does.
const METADATA: &[&str] = &["_description", "_uid", "_fullpath"];

/// Whether the text has a `<BehaviorTree>` element (a tree file, rather
/// than only a palette).
pub fn has_trees(text: &str) -> bool {
    text.contains("<BehaviorTree")
}

/// An element being read: its tag, where the tag's name is, its
/// attributes, and the templates of its children so far.
struct Open {
    tag: String,
    tag_span: Span,
    attrs: Vec<Attr>,
    children: Vec<Template>,
}

/// The trees of a BT.CPP file. Malformed XML is the palette reader's to
/// report (R070, one report per file): this stops there with what it has.
pub fn read_trees(text: &str, file: FileId) -> XmlTrees {
    let mut out = XmlTrees::default();
    let mut r = Reader::from_str(text);
    r.config_mut().trim_text(true);
    // Elements from `<root>` down; `skip` counts the levels of an element
    // that is no tree (a palette, an `<include>`) being passed over.
    let mut stack: Vec<Open> = Vec::new();
    let mut skip = 0usize;
    let mut main: Option<Attr> = None;
    loop {
        let before = r.buffer_position() as usize;
        let Ok(ev) = r.read_event() else {
            // What the file names cannot be judged from part of it.
            return out;
        };
        let (e, empty) = match &ev {
            Event::Start(e) => (e.clone(), false),
            Event::Empty(e) => (e.clone(), true),
            Event::End(_) => {
                if skip > 0 {
                    skip -= 1;
                } else if let Some(open) = stack.pop() {
                    close(open, &mut stack, &mut out);
                }
                continue;
            }
            Event::Eof if stack.is_empty() && skip == 0 => break,
            // Unclosed: the palette reader reports it (R070).
            Event::Eof => return out,
            _ => continue,
        };
        let at = text[before..].find('<').map_or(before, |k| before + k);
        if skip > 0 {
            if !empty {
                skip += 1;
            }
            continue;
        }
        let tag = String::from_utf8_lossy(e.name().as_ref()).into_owned();
        let tag_span = Span::new(file, at + 1, at + 1 + tag.len());
        let a = attrs(&e, &r, text, at, file);
        match stack.len() {
            0 => {
                if tag == "root" {
                    main = a
                        .iter()
                        .position(|a| a.key == "main_tree_to_execute")
                        .map(|k| {
                            let m = &a[k];
                            Attr {
                                key: m.key.clone(),
                                value: m.value.clone(),
                                span: m.span,
                            }
                        });
                } else {
                    skip = usize::from(!empty);
                    continue;
                }
            }
            1 if tag == "include" => {
                out.diagnostics.push(
                    Diagnostic::error(
                        codes::R_XML_CONSTRUCT,
                        tag_span,
                        "btc does not follow an <include> of an imported tree file",
                    )
                    .with_hint("import the included file too: `import \"other.xml\"`"),
                );
                skip = usize::from(!empty);
                continue;
            }
            1 if tag != "BehaviorTree" => {
                // A <TreeNodesModel> (the palette reader's) or editor data.
                skip = usize::from(!empty);
                continue;
            }
            n if n > MAX_DEPTH => {
                out.diagnostics.push(Diagnostic::error(
                    codes::R_XML_CONSTRUCT,
                    tag_span,
                    format!(
                        "this tree nests deeper than {MAX_DEPTH} elements, more than btc supports"
                    ),
                ));
                skip = usize::from(!empty);
                continue;
            }
            _ => {}
        }
        let open = Open {
            tag,
            tag_span,
            attrs: a,
            children: Vec::new(),
        };
        if empty {
            close(open, &mut stack, &mut out);
        } else {
            stack.push(open);
        }
    }
    if let Some(m) = main {
        if out.trees.iter().any(|t| t.id.text == m.value) {
            out.main = Some(m.value);
        } else {
            let d = Diagnostic::error(
                codes::R_XML_TREE_NAME,
                m.span,
                format!(
                    "`main_tree_to_execute` names `{}`, which is no <BehaviorTree> of this file",
                    m.value
                ),
            );
            out.diagnostics.push(d.suggest(
                closest(&m.value, out.trees.iter().map(|t| t.id.text.as_str())).map(str::to_owned),
                || "it names the `ID` of one of the file's <BehaviorTree> elements".to_owned(),
            ));
        }
    }
    check_subtrees(&mut out);
    out
}

/// Elements below `<root>` a tree may nest: as deep as a rules template.
const MAX_DEPTH: usize = crate::rules::parse::MAX_ITEM_DEPTH;

/// An element ends: a `<BehaviorTree>` becomes a tree of the file, any
/// other element a template of its parent.
fn close(open: Open, stack: &mut [Open], out: &mut XmlTrees) {
    match stack.len() {
        // `<root>` itself.
        0 => {}
        1 => {
            if open.children.len() != 1 {
                out.diagnostics.push(
                    Diagnostic::error(
                        codes::R_XML_CONSTRUCT,
                        open.tag_span,
                        format!(
                            "a <BehaviorTree> has one root node; this one has {}",
                            open.children.len()
                        ),
                    )
                    .with_hint("BT.CPP refuses it too: wrap the nodes in a <Sequence>"),
                );
            }
            match get(&open.attrs, "ID") {
                Some(id) => out.trees.push(XmlTree {
                    id: Ident::new(id.value.clone(), id.span),
                    body: open.children,
                    span: open.tag_span,
                }),
                None => out.diagnostics.push(Diagnostic::error(
                    codes::R_XML_CONSTRUCT,
                    open.tag_span,
                    "this <BehaviorTree> has no `ID`, so nothing can call it",
                )),
            }
        }
        _ => {
            let span = open.tag_span;
            // An element btc cannot carry stays in its parent as an error
            // (reported), so the parent's children are still counted right.
            let t = element(open, &mut out.diagnostics).unwrap_or(Template::Error { span });
            if let Some(parent) = stack.last_mut() {
                parent.children.push(t);
            }
        }
    }
}

fn construct(span: Span, message: String, hint: &str) -> Diagnostic {
    Diagnostic::error(codes::R_XML_CONSTRUCT, span, message).with_hint(hint.to_owned())
}

/// One element below a `<BehaviorTree>` as a template (`None` when btc
/// cannot carry it, with the diagnostic that says why).
fn element(open: Open, diags: &mut Vec<Diagnostic>) -> Option<Template> {
    let Open {
        tag,
        tag_span,
        attrs,
        children,
    } = open;
    if let Some(spec) = NodeSpec::by_tag(&tag) {
        return vocab_node(spec, tag_span, &attrs, children, diags);
    }
    match tag.as_str() {
        "Script" | "ScriptCondition" => {
            let Some(code) = get(&attrs, "code") else {
                diags.push(construct(
                    tag_span,
                    format!("this <{tag}> has no `code`"),
                    "BT.CPP refuses it too",
                ));
                return None;
            };
            unexpected_attrs(&attrs, &["code", "name"], &tag, diags);
            Some(Template::Script {
                condition: tag == "ScriptCondition",
                code: literal(code),
                span: tag_span,
            })
        }
        _ if !children.is_empty() => {
            let known: Vec<&str> = NODES.iter().map(|n| n.tag).collect();
            let d = construct(
                tag_span,
                format!("btc cannot carry <{tag}>: it is no control node or decorator btc runs in every output"),
                "",
            );
            diags.push(d.suggest(
                closest(&tag, known.iter().copied()).map(str::to_owned),
                || format!("btc carries {}", known.join(", ")),
            ));
            None
        }
        "SubTree" => {
            let Some(id) = get(&attrs, "ID") else {
                diags.push(construct(
                    tag_span,
                    "this <SubTree> has no `ID`".to_owned(),
                    "BT.CPP refuses it too: `ID` names the <BehaviorTree> it calls",
                ));
                return None;
            };
            let mut args = Vec::new();
            for a in &attrs {
                match a.key.as_str() {
                    "ID" | "name" => {}
                    AUTOREMAP => match a.value.as_str() {
                        "true" | "1" => args.push(Arg {
                            port: Ident::new(AUTOREMAP.to_owned(), a.span),
                            value: Value::Bool {
                                value: true,
                                span: a.span,
                            },
                        }),
                        "false" | "0" => {}
                        _ => diags.push(construct(
                            a.span,
                            format!("`_autoremap` is `true` or `false`, not `{}`", a.value),
                            "BT.CPP reads it as a bool",
                        )),
                    },
                    k if k.starts_with('_') => unknown_attr(a, &tag, diags),
                    _ => {
                        if let Some(value) = attr_value(a, diags) {
                            args.push(Arg {
                                port: Ident::new(a.key.clone(), key_span(a)),
                                value,
                            });
                        }
                    }
                }
            }
            Some(Template::Call {
                name: Ident::new(format!("{SUBTREE_PREFIX}{}", id.value), id.span),
                args,
                scripts: Vec::new(),
                label: None,
                span: tag_span,
            })
        }
        _ => {
            let mut args = Vec::new();
            let mut scripts = Vec::new();
            let mut label = None;
            for a in &attrs {
                if a.key == "name" {
                    label = Some(literal(a));
                } else if let Some(k) = NodeScripts::ATTRIBUTES.iter().position(|x| *x == a.key) {
                    scripts.push(ScriptAttr {
                        key: Ident::new(NodeScripts::KEYS[k].to_owned(), key_span(a)),
                        code: literal(a),
                        span: a.span,
                    });
                } else if METADATA.contains(&a.key.as_str()) {
                } else if a.key.starts_with('_') {
                    unknown_attr(a, &tag, diags);
                } else if let Some(value) = attr_value(a, diags) {
                    args.push(Arg {
                        port: Ident::new(a.key.clone(), key_span(a)),
                        value,
                    });
                }
            }
            Some(Template::Call {
                name: Ident::new(tag, tag_span),
                args,
                scripts,
                label,
                span: tag_span,
            })
        }
    }
}

/// A control node or decorator of the vocabulary, its parameters read
/// from their BT.CPP ports.
fn vocab_node(
    spec: &NodeSpec,
    tag_span: Span,
    attrs: &[Attr],
    mut children: Vec<Template>,
    diags: &mut Vec<Diagnostic>,
) -> Option<Template> {
    let tag = spec.tag;
    let mut allowed: Vec<&str> = spec.params.iter().map(|p| p.port).collect();
    allowed.push("name");
    unexpected_attrs(attrs, &allowed, tag, diags);
    let name = get(attrs, "name").map(literal);
    match spec.arity {
        Arity::AtLeast(n) if children.len() < n.max(1) => {
            diags.push(construct(
                tag_span,
                format!("this <{tag}> has no children"),
                "BT.CPP refuses it too",
            ));
            return None;
        }
        Arity::One if children.len() != 1 => {
            diags.push(construct(
                tag_span,
                format!(
                    "a <{tag}> decorates one child; this one has {}",
                    children.len()
                ),
                "BT.CPP refuses it too: wrap the children in a <Sequence>",
            ));
            return None;
        }
        _ => {}
    }
    match spec.name {
        NodeName::Control(c) => {
            let mut params = Vec::new();
            for p in spec.params {
                let Some(a) = get(attrs, p.port) else {
                    diags.push(construct(
                        tag_span,
                        format!("this <{tag}> does not give `{}`", p.port),
                        "btc reads the thresholds from the file; give both",
                    ));
                    return None;
                };
                match a.value.trim().parse::<u32>() {
                    Ok(v) => params.push(v),
                    Err(_) => {
                        diags.push(construct(
                            a.span,
                            format!("`{}` is `{}`, not a whole number", p.port, a.value),
                            "btc needs the thresholds as numbers in the file, not blackboard entries",
                        ));
                        return None;
                    }
                }
            }
            Some(Template::Control {
                control: ControlKind::new(c, &params),
                name,
                children,
                span: tag_span,
            })
        }
        NodeName::Decorator(d) => {
            let mut args = Vec::new();
            for p in spec.params {
                if let Some(a) = get(attrs, p.port) {
                    let value = match attr_value(a, diags)? {
                        Value::Str { value } => {
                            match value.plain().and_then(|v| v.trim().parse::<i64>().ok()) {
                                Some(v) => Value::Int {
                                    value: v,
                                    span: a.span,
                                },
                                None => Value::Str { value },
                            }
                        }
                        v => v,
                    };
                    args.push(DecoratorArg {
                        param: Some(Ident::new(p.name.to_owned(), key_span(a))),
                        value,
                        span: a.span,
                    });
                }
            }
            Some(Template::Decorator {
                decorator: d,
                args,
                name,
                child: Box::new(children.pop()?),
                span: tag_span,
            })
        }
    }
}

/// An attribute's value: `{key}` reads the blackboard entry `key` (`{=}`:
/// the entry named as the port), anything else is the literal text.
fn attr_value(a: &Attr, diags: &mut Vec<Diagnostic>) -> Option<Value> {
    let v = a.value.trim();
    if let Some(key) = v.strip_prefix('{').and_then(|k| k.strip_suffix('}')) {
        let key = if key == "=" { a.key.as_str() } else { key };
        if key.starts_with('@') {
            diags.push(construct(
                a.span,
                format!("`{v}` reads the root blackboard, which btc's outputs do not share with an imported tree"),
                "pass the value in through a port of the tree instead",
            ));
            return None;
        }
        if key.is_empty() || !key.chars().all(|c| c.is_alphanumeric() || c == '_') {
            diags.push(construct(
                a.span,
                format!("`{v}` is no blackboard entry btc can make a port of"),
                "a port's entry is a name of letters, digits and `_`",
            ));
            return None;
        }
        return Some(Value::Var {
            name: Ident::new(key.to_owned(), a.span),
        });
    }
    if v.contains('{') {
        diags.push(construct(
            a.span,
            format!(
                "`{}` mixes text and a blackboard entry, which BT.CPP does not fill in",
                a.value
            ),
            "BT.CPP reads `{key}` only as a whole value",
        ));
        return None;
    }
    Some(Value::Str { value: literal(a) })
}

/// An attribute's text as a string literal whose span, as a rules
/// string's, takes in the quotes.
fn literal(a: &Attr) -> StrLit {
    StrLit {
        parts: vec![StrPart::Text {
            text: a.value.clone(),
        }],
        span: Span::new(
            a.span.file,
            (a.span.start as usize).saturating_sub(1),
            a.span.end as usize + 1,
        ),
        escapes: Vec::new(),
    }
}

/// Where an attribute's name is: before `="` and its value.
fn key_span(a: &Attr) -> Span {
    let start = (a.span.start as usize).saturating_sub(a.key.len() + 2);
    Span::new(a.span.file, start, start + a.key.len())
}

fn unexpected_attrs(attrs: &[Attr], allowed: &[&str], tag: &str, diags: &mut Vec<Diagnostic>) {
    for a in attrs {
        if !allowed.contains(&a.key.as_str()) && !METADATA.contains(&a.key.as_str()) {
            unknown_attr(a, tag, diags);
        }
    }
}

fn unknown_attr(a: &Attr, tag: &str, diags: &mut Vec<Diagnostic>) {
    diags.push(construct(
        key_span(a),
        format!("btc cannot carry `{}` on this <{tag}>", a.key),
        "btc carries a leaf's ports, `name` and pre- and post-conditions, a <SubTree>'s remapping and `_autoremap`, and the parameters of the control nodes and decorators it knows",
    ));
}

/// Every `<SubTree ID>` names a tree of the file, and no tree calls itself.
fn check_subtrees(out: &mut XmlTrees) {
    let ids: Vec<String> = out.trees.iter().map(|t| t.id.text.clone()).collect();
    let calls = |t: &XmlTree| -> Vec<Ident> {
        let mut c = Vec::new();
        Template::walk_all(&t.body, &mut |t| {
            if let Template::Call { name, .. } = t {
                if let Some(id) = name.text.strip_prefix(SUBTREE_PREFIX) {
                    c.push(Ident::new(id.to_owned(), name.span));
                }
            }
        });
        c
    };
    let edges: Vec<Vec<Ident>> = out.trees.iter().map(calls).collect();
    for e in edges.iter().flatten() {
        if !ids.contains(&e.text) {
            let d = Diagnostic::error(
                codes::R_XML_SUBTREE,
                e.span,
                format!("this file has no <BehaviorTree ID=\"{}\">", e.text),
            );
            out.diagnostics.push(d.suggest(
                closest(&e.text, ids.iter().map(String::as_str)).map(str::to_owned),
                || {
                    format!(
                        "its trees are {}",
                        ids.iter()
                            .map(|i| format!("`{i}`"))
                            .collect::<Vec<_>>()
                            .join(", ")
                    )
                },
            ));
        }
    }
    // A call that reaches its own tree again: BT.CPP would expand forever.
    for (k, tree) in out.trees.iter().enumerate() {
        let mut seen = vec![false; ids.len()];
        let mut todo: Vec<usize> = vec![k];
        let mut cycle = false;
        while let Some(i) = todo.pop() {
            for e in &edges[i] {
                if let Some(j) = ids.iter().position(|x| *x == e.text) {
                    if j == k {
                        cycle = true;
                    } else if !seen[j] {
                        seen[j] = true;
                        todo.push(j);
                    }
                }
            }
        }
        if cycle {
            out.diagnostics.push(
                Diagnostic::error(
                    codes::R_XML_SUBTREE,
                    tree.id.span,
                    format!(
                        "the tree `{}` calls itself through its <SubTree>s",
                        tree.id.text
                    ),
                )
                .with_hint("BT.CPP would expand it forever; break the cycle"),
            );
        }
    }
}
