//! A template checked against the declarations and the variables and
//! captures in scope: calls and their ports, decorators, scripts, `steps`.

use super::unknown_name;
use super::values::Tcx;
use crate::rules::ast::*;
use btc_ir::NodeScripts;
use btc_pddl::diagnostic::{closest, codes, Diagnostic};
use btc_pddl::source::Span;
use std::collections::BTreeSet;

impl Tcx<'_> {
    /// A template and every template inside it.
    pub(super) fn template(&mut self, t: &Template) {
        t.walk(&mut |t| self.one_template(t));
    }

    /// One template's own parts (the walk goes inside it).
    fn one_template(&mut self, t: &Template) {
        match t {
            Template::Control {
                control,
                name,
                children,
                span,
            } => {
                if let Some(n) = name {
                    self.string(n);
                }
                if let ControlKind::Parallel { success, failure } = control {
                    let n = children.len() as u32;
                    if *success > n || *failure > n || *success == 0 {
                        self.err(
                            Diagnostic::error(
                                codes::R_BAD_ARGUMENT,
                                *span,
                                format!("`parallel(success: {success}, failure: {failure})` has {n} children: the thresholds must be between 1 and {n}"),
                            )
                            .with_hint("success: how many children must succeed; failure: how many may fail before the node fails"),
                        );
                    }
                }
            }
            Template::Decorator {
                decorator,
                args,
                name,
                span,
                ..
            } => {
                if let Some(n) = name {
                    self.string(n);
                }
                self.decorator_args(*decorator, args, *span);
            }
            Template::Call {
                name,
                args,
                scripts,
                span,
                ..
            } => {
                self.call(name, args, *span);
                self.script_attrs(scripts);
            }
            Template::Script { code, .. } => self.script_text(code),
            Template::Steps { span, .. } => {
                if !self.in_plan {
                    self.err(
                        Diagnostic::error(
                            codes::R_PLAN_BLOCK,
                            *span,
                            "`steps` stands only in the `plan { ... }` block",
                        )
                        .with_hint(
                            "rules and trees describe one step; the plan block arranges them",
                        ),
                    );
                }
            }
            Template::Error { .. } => {}
        }
    }

    /// A call's `[key: "script", ...]`: BT.CPP's attributes, each once.
    pub(super) fn script_attrs(&mut self, scripts: &[ScriptAttr]) {
        let mut seen: Vec<&str> = Vec::new();
        for a in scripts {
            let key = a.key.text.as_str();
            if NodeScripts::key_index(key).is_none() {
                let mut d = Diagnostic::error(
                    codes::R_SCRIPT_KEY,
                    a.key.span,
                    format!("`{key}` is not a pre- or post-condition BT.CPP runs around a node"),
                );
                d = match closest(key, NodeScripts::KEYS.iter().copied()) {
                    Some(c) => d.with_hint(format!("did you mean `{c}`?")),
                    None => d.with_hint(format!(
                        "a node takes {}",
                        NodeScripts::KEYS.map(|k| format!("`{k}`")).join(", ")
                    )),
                };
                self.err(d);
            } else if seen.contains(&key) {
                self.err(
                    Diagnostic::error(
                        codes::R_SCRIPT_TWICE,
                        a.key.span,
                        format!("this node gives `{key}` twice"),
                    )
                    .with_hint("join the two scripts with `;` in one string"),
                );
            }
            seen.push(key);
            self.script_text(&a.code);
        }
    }

    /// A script is BT.CPP code, passed through as written: `{...}` in it
    /// would be a btc interpolation BT.CPP never sees. Its syntax is
    /// checked here, so that a script BT.CPP (and `btc run`) would refuse
    /// when it loads the tree is shown at the token in the string.
    pub(super) fn script_text(&mut self, code: &StrLit) {
        if let Some(text) = code.plain() {
            if let Err(e) = btc_script::parse(&text) {
                self.err(script_syntax(code, &text, &e));
            }
        } else {
            self.err(
                Diagnostic::error(
                    codes::R_SCRIPT_TEXT,
                    code.span,
                    "a script cannot interpolate `{...}`: it is BT.CPP code, run as written",
                )
                .with_hint(
                    "read values from blackboard entries in the script, or write `\\{` for a brace",
                ),
            );
        }
    }

    pub(super) fn call(&mut self, name: &Ident, args: &[Arg], span: Span) {
        let Some(ports) = self.decls.ports(&name.text) else {
            if self.imported && name.text.starts_with(crate::rules::btxml::SUBTREE_PREFIX) {
                // A <SubTree> naming no tree of its file: R073 already.
                return;
            }
            if self.imported {
                self.err(unknown_name(
                    Diagnostic::error(
                        codes::R_XML_NODE,
                        name.span,
                        format!("no palette and no declaration of the rules has the node `{}`", name.text),
                    ),
                    &name.text,
                    self.decls.nodes.keys().map(String::as_str),
                    str::to_owned,
                    || format!("declare it in the rules (`action {}(...)`), or import a palette that has it (`import \"nodes.xml\"`)", name.text),
                ));
                return;
            }
            self.err(unknown_name(
                Diagnostic::error(
                    codes::R_UNKNOWN_NODE,
                    name.span,
                    format!("no node or tree is called `{}`", name.text),
                ),
                &name.text,
                self.decls.callables(),
                str::to_owned,
                || format!("declare it: `action {}(...)`", name.text),
            ));
            for a in args {
                self.value(&a.value);
            }
            return;
        };
        let ports = ports.to_vec();
        let mut given = BTreeSet::new();
        for a in args {
            let vt = self.value(&a.value);
            let Some(port) = ports.iter().find(|p| p.name.text == a.port.text) else {
                let otherwise = || {
                    let names: Vec<String> =
                        ports.iter().map(|p| format!("`{}`", p.name.text)).collect();
                    if names.is_empty() {
                        format!("`{}` has no ports", name.text)
                    } else {
                        format!("its ports are {}", names.join(", "))
                    }
                };
                self.err(unknown_name(
                    Diagnostic::error(
                        codes::R_UNKNOWN_PORT,
                        a.port.span,
                        format!("`{}` has no port `{}`", name.text, a.port.text),
                    ),
                    &a.port.text,
                    ports.iter().map(|p| p.name.text.as_str()),
                    str::to_owned,
                    otherwise,
                ));
                continue;
            };
            if !given.insert(a.port.text.clone()) {
                self.err(Diagnostic::error(
                    codes::R_DUPLICATE,
                    a.port.span,
                    format!("port `{}` is given twice", a.port.text),
                ));
            }
            self.port_fit(port, &a.value, vt);
        }
        let missing: Vec<&PortDecl> = ports
            .iter()
            .filter(|p| !p.out && !given.contains(&p.name.text))
            .collect();
        if !missing.is_empty() {
            let names: Vec<String> = missing
                .iter()
                .map(|p| format!("`{}: {}`", p.name.text, p.ty.text))
                .collect();
            self.err(
                Diagnostic::error(
                    codes::R_MISSING_PORT,
                    span,
                    format!(
                        "`{}` needs {} {}",
                        name.text,
                        if missing.len() == 1 {
                            "the port"
                        } else {
                            "the ports"
                        },
                        names.join(", ")
                    ),
                )
                .with_hint(format!(
                    "add {}",
                    missing
                        .iter()
                        .map(|p| format!("{}: ...", p.name.text))
                        .collect::<Vec<_>>()
                        .join(", ")
                )),
            );
        }
    }
}

/// R123 for a plain script literal `code` (whose text is `text`) that does
/// not parse: the span is the bad token's in the file, through the
/// literal's escapes; at the end of the script, the closing quote.
fn script_syntax(code: &StrLit, text: &str, e: &btc_script::SyntaxError) -> Diagnostic {
    let span = if e.problem == btc_script::Problem::Empty {
        code.span
    } else if e.span.is_empty() {
        let at = code.source_offset(text.len());
        Span::new(code.span.file, at, at + 1)
    } else {
        Span::new(
            code.span.file,
            code.source_offset(e.span.start),
            code.source_offset(e.span.end),
        )
    };
    Diagnostic::error(
        codes::R_SCRIPT_SYNTAX,
        span,
        format!("this script does not parse: {}", e.describe()),
    )
    .with_hint(
        "the script is BT.CPP's scripting language, described in docs/runtime.md (*Scripts*)",
    )
}
