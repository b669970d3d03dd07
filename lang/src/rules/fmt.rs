//! The `.btrules` formatter (`btc fmt`). Prints the syntax tree in one
//! canonical layout and puts every comment back: own-line comments before
//! the next element at its indentation, trailing comments at the end of the
//! line they followed. Idempotent; refuses text that does not parse.

use super::ast::*;
use super::lexer::Comment;
use super::parse::{parse_rules, ParsedRules};
use btc_ir::format_float;
use btc_pddl::diagnostic::Diagnostic;

const INDENT: &str = "    ";
/// Rules whose body is one node call stay on one line up to this width.
const ONE_LINE: usize = 100;

pub fn format(text: &str) -> Result<String, Vec<Diagnostic>> {
    format_parsed(text, &parse_rules(text, 0))
}

/// [`format`] of a text parsed already (the language server's database
/// holds it parsed: parsing it again cost most of a formatting request).
pub fn format_parsed(text: &str, parsed: &ParsedRules) -> Result<String, Vec<Diagnostic>> {
    if !parsed.diagnostics.is_empty() {
        return Err(parsed.diagnostics.clone());
    }
    let mut f = Formatter {
        text,
        comments: &parsed.comments,
        next_comment: 0,
        lines: Vec::new(),
        offset: 0,
    };
    let mut prev_end: Option<usize> = None;
    for node in &parsed.items {
        let start = node.offset as usize;
        // A blank line in the source before this item (or its comments) is kept.
        let first = f
            .comments
            .get(f.next_comment)
            .map_or(start, |c| (c.span.start as usize).min(start));
        if let Some(end) = prev_end {
            if f.text[end..first].matches('\n').count() >= 2 {
                f.lines.push(String::new());
            }
        }
        f.offset = node.offset;
        f.flush(start, 0);
        f.item(&node.item);
        prev_end = Some(node.offset as usize + node.item.span().end as usize);
    }
    if let Some(end) = prev_end {
        if f.next_comment < f.comments.len()
            && f.text[end..f.comments[f.next_comment].span.start as usize]
                .matches('\n')
                .count()
                >= 2
        {
            f.lines.push(String::new());
        }
    }
    f.flush(text.len() + 1, 0);
    let mut out = f.lines.join("\n");
    out.push('\n');
    Ok(out)
}

struct Formatter<'a> {
    text: &'a str,
    comments: &'a [Comment],
    next_comment: usize,
    lines: Vec<String>,
    /// Offset of the item being printed (its spans are relative to it).
    offset: u32,
}

impl Formatter<'_> {
    /// Emits the comments that start before `pos` (absolute).
    fn flush(&mut self, pos: usize, depth: usize) {
        let comments = self.comments;
        while let Some(c) = comments.get(self.next_comment) {
            if c.span.start as usize >= pos {
                break;
            }
            let text = &c.text;
            match (c.trailing, self.lines.last_mut()) {
                (true, Some(last)) if !last.is_empty() => {
                    last.push_str("  ");
                    last.push_str(text);
                }
                _ => {
                    for (i, l) in text.lines().enumerate() {
                        // Block comments keep their inner lines as written.
                        let line = if i == 0 {
                            format!("{}{}", INDENT.repeat(depth), l)
                        } else {
                            l.to_owned()
                        };
                        self.lines.push(line);
                    }
                }
            }
            self.next_comment += 1;
        }
    }

    fn abs(&self, rel: u32) -> usize {
        (self.offset + rel) as usize
    }

    /// Whether the source wrote this span on one line: simple bodies keep
    /// the author's choice between one line and several.
    fn was_one_line(&self, span: btc_pddl::source::Span) -> bool {
        !self.text[self.abs(span.start)..self.abs(span.end).min(self.text.len())].contains('\n')
    }

    fn has_comment_before(&self, pos: usize) -> bool {
        self.comments
            .get(self.next_comment)
            .is_some_and(|c| (c.span.start as usize) < pos)
    }

    fn push(&mut self, depth: usize, line: String) {
        self.lines.push(format!("{}{line}", INDENT.repeat(depth)));
    }

    fn item(&mut self, item: &Item) {
        match item {
            Item::Domain { path, .. } => self.push(0, format!("domain {}", string(path))),
            Item::Problem { path, .. } => self.push(0, format!("problem {}", string(path))),
            Item::Import { target, .. } => match target {
                ImportTarget::Path { path, alias } => self.push(
                    0,
                    match alias {
                        Some(a) => format!("import {} as {}", string(path), a.text),
                        None => format!("import {}", string(path)),
                    },
                ),
                ImportTarget::Std { module } => {
                    self.push(0, format!("import std::{}", module.text))
                }
            },
            Item::Node(n) => {
                let kw = match n.kind {
                    NodeKind::Action => "action",
                    NodeKind::Condition => "condition",
                };
                let mut line = format!("{kw} {}({})", n.name.text, ports(&n.ports));
                if let Some(f) = &n.formula {
                    line.push_str(&format!(" = {f}"));
                }
                self.push(0, line);
            }
            Item::Tree(t) => {
                self.push(0, format!("tree {}({}) {{", t.name.text, ports(&t.ports)));
                self.templates(&t.body, 1);
                self.flush(self.abs(t.span.end), 1);
                self.push(0, "}".into());
            }
            Item::Table(t) => {
                let entries: Vec<String> = t
                    .entries
                    .iter()
                    .map(|e| format!("{}: {}", e.key.text, literal(&e.value)))
                    .collect();
                let one = format!("table {} {{ {} }}", t.name.text, entries.join(", "));
                if one.len() <= ONE_LINE && !self.has_comment_before(self.abs(t.span.end)) {
                    self.push(0, one);
                } else {
                    self.push(0, format!("table {} {{", t.name.text));
                    for (e, s) in t.entries.iter().zip(entries) {
                        self.flush(self.abs(e.key.span.start), 1);
                        self.push(1, format!("{s},"));
                    }
                    self.flush(self.abs(t.span.end), 1);
                    self.push(0, "}".into());
                }
            }
            Item::Rule(r) => self.rule(r),
            Item::Plan { body, span } => {
                self.push(0, "plan {".into());
                self.templates(body, 1);
                self.flush(self.abs(span.end), 1);
                self.push(0, "}".into());
            }
            Item::Error { .. } => unreachable!("format refuses text with errors"),
        }
    }

    fn rule(&mut self, r: &Rule) {
        let mut head = format!("rule {}", pattern(&r.pattern));
        if !r.guards.is_empty() {
            head.push_str(" where ");
            head.push_str(&r.guards.iter().map(guard).collect::<Vec<_>>().join(", "));
        }
        match &r.body {
            RuleBody::Skip { .. } => self.push(0, format!("{head} => skip")),
            RuleBody::Template { body, effect } => {
                let end = self.abs(r.span.end);
                if let ([Template::Call { .. }], None) = (body.as_slice(), effect) {
                    let one = format!("{head} {{ {} }}", template_line(&body[0]));
                    if one.len() <= ONE_LINE
                        && self.was_one_line(r.span)
                        && !self.has_comment_before(end)
                    {
                        self.push(0, one);
                        return;
                    }
                }
                self.push(0, format!("{head} {{"));
                self.templates(body, 1);
                if let Some(e) = effect {
                    self.flush(self.abs(e.span().start), 1);
                    self.push(1, format!("effect {e}"));
                }
                self.flush(end, 1);
                self.push(0, "}".into());
            }
        }
    }

    fn templates(&mut self, ts: &[Template], depth: usize) {
        for t in ts {
            self.flush(self.abs(t.span().start), depth);
            self.template(t, depth, String::new());
        }
    }

    /// Prints a template; `prefix` holds decorators written before it on
    /// the same line.
    fn template(&mut self, t: &Template, depth: usize, prefix: String) {
        match t {
            Template::Control {
                control,
                name,
                children,
                span,
            } => {
                let mut head = format!("{prefix}{}", control_head(*control));
                if let Some(n) = name {
                    head.push(' ');
                    head.push_str(&string(n));
                }
                if children.is_empty() && !self.has_comment_before(self.abs(span.end)) {
                    self.push(depth, format!("{head} {{ }}"));
                    return;
                }
                if let [only @ (Template::Call { .. } | Template::Steps { .. })] =
                    children.as_slice()
                {
                    let one = format!("{head} {{ {} }}", template_line(only));
                    if self.was_one_line(*span)
                        && one.len() + depth * INDENT.len() <= ONE_LINE
                        && !self.has_comment_before(self.abs(span.end))
                    {
                        self.push(depth, one);
                        return;
                    }
                }
                self.push(depth, format!("{head} {{"));
                self.templates(children, depth + 1);
                self.flush(self.abs(span.end), depth + 1);
                self.push(depth, "}".into());
            }
            Template::Decorator {
                decorator,
                args,
                name,
                child,
                ..
            } => {
                let mut p = format!("{prefix}{}", decorator_head(*decorator, args));
                if let Some(n) = name {
                    p.push(' ');
                    p.push_str(&string(n));
                }
                p.push(' ');
                self.template(child, depth, p);
            }
            other => self.push(depth, format!("{prefix}{}", template_line(other))),
        }
    }
}

/// `sequence`, `parallel(success: 2, failure: 1)`: every parameter by name.
fn control_head(c: ControlKind) -> String {
    let spec = c.spec();
    if spec.params.is_empty() {
        return spec.keyword.to_owned();
    }
    let a: Vec<String> = spec
        .params
        .iter()
        .zip(c.params())
        .map(|(p, v)| format!("{}: {v}", p.name))
        .collect();
    format!("{}({})", spec.keyword, a.join(", "))
}

/// `retry(3)`, `timeout(msec: ?t)`: arguments as written.
fn decorator_head(d: DecoratorName, args: &[DecoratorArg]) -> String {
    if args.is_empty() {
        return d.keyword().to_owned();
    }
    let a: Vec<String> = args
        .iter()
        .map(|a| match &a.param {
            Some(p) => format!("{}: {}", p.text, value(&a.value)),
            None => value(&a.value),
        })
        .collect();
    format!("{}({})", d.keyword(), a.join(", "))
}

/// A template that fits on one line: a call or `steps`.
fn template_line(t: &Template) -> String {
    match t {
        Template::Call {
            name,
            args,
            scripts,
            ..
        } => {
            let a: Vec<String> = args
                .iter()
                .map(|a| format!("{}: {}", a.port.text, value(&a.value)))
                .collect();
            let mut line = format!("{}({})", name.text, a.join(", "));
            if !scripts.is_empty() {
                let s: Vec<String> = scripts
                    .iter()
                    .map(|s| format!("{}: {}", s.key.text, string(&s.code)))
                    .collect();
                line.push_str(&format!(" [{}]", s.join(", ")));
            }
            line
        }
        Template::Script {
            condition, code, ..
        } => {
            let kw = if *condition {
                "script_condition"
            } else {
                "script"
            };
            format!("{kw} {}", string(code))
        }
        Template::Steps { mode, .. } => match mode {
            StepsMode::InOrder => "steps".into(),
            StepsMode::Parallel => "steps parallel".into(),
            StepsMode::Backchained => "steps backchained".into(),
            StepsMode::Scheduled => "steps scheduled".into(),
        },
        _ => unreachable!("controls and decorators are printed by `template`"),
    }
}

/// A port declaration as written: `out name: type`.
pub fn port(p: &PortDecl) -> String {
    format!(
        "{}{}: {}",
        if p.out { "out " } else { "" },
        p.name.text,
        p.ty.text
    )
}

/// A declaration's port list, without the parentheses.
pub fn ports(ps: &[PortDecl]) -> String {
    ps.iter().map(port).collect::<Vec<_>>().join(", ")
}

fn pattern(p: &Pattern) -> String {
    let mut s = format!("({}", p.name_text());
    for param in &p.params {
        if param.optional {
            s.push_str(&format!(" [?{}]", param.var.text));
        } else {
            s.push_str(&format!(" ?{}", param.var.text));
        }
    }
    s.push(')');
    s
}

fn operand(o: &Operand) -> String {
    match o {
        Operand::Var { name } => format!("?{}", name.text),
        Operand::Object { name } => string(&StrLit {
            parts: vec![StrPart::Text {
                text: name.text.clone(),
            }],
            span: name.span,
            escapes: Vec::new(),
        }),
    }
}

fn guard(g: &Guard) -> String {
    match g {
        Guard::Ne { left, right, .. } => format!("{} != {}", operand(left), operand(right)),
        Guard::Eq { left, right, .. } => format!("{} == {}", operand(left), operand(right)),
        Guard::IsType { var, ty, .. } => format!("?{} - {}", var.text, ty.text),
        Guard::InTable { key, table, .. } => format!("{} in {}", key.text, table.text),
    }
}

pub fn string(s: &StrLit) -> String {
    let mut out = String::from("\"");
    for p in &s.parts {
        match p {
            StrPart::Text { text } => {
                for c in text.chars() {
                    match c {
                        '"' => out.push_str("\\\""),
                        '\\' => out.push_str("\\\\"),
                        '{' => out.push_str("\\{"),
                        '}' => out.push_str("\\}"),
                        '\n' => out.push_str("\\n"),
                        '\t' => out.push_str("\\t"),
                        c => out.push(c),
                    }
                }
            }
            StrPart::Var { name } => out.push_str(&format!("{{?{}}}", name.text)),
            StrPart::Capture { name } => out.push_str(&format!("{{{}}}", name.text)),
            StrPart::Value { value: v } => out.push_str(&format!("{{{}}}", value(v))),
        }
    }
    out.push('"');
    out
}

fn literal(l: &Literal) -> String {
    match l {
        Literal::Int { value, .. } => value.to_string(),
        Literal::Float { value, .. } => format_float(*value),
        Literal::Str { value } => string(value),
        Literal::Bool { value, .. } => value.to_string(),
        Literal::Name { name } => name.text.clone(),
    }
}

fn value(v: &Value) -> String {
    match v {
        Value::Var { name } => format!("?{}", name.text),
        Value::Str { value } => string(value),
        Value::Int { value, .. } => value.to_string(),
        Value::Float { value, .. } => format_float(*value),
        Value::Bool { value, .. } => value.to_string(),
        Value::Lookup { table, key, .. } => format!("{}[{}]", table.text, self::value(key)),
        Value::Name { name } => name.text.clone(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_examples_are_formatted_and_formatting_is_idempotent() {
        for text in [
            include_str!("../../../examples/ariac/rules.btrules"),
            include_str!("../../../examples/p3_assembler/rules.btrules"),
        ] {
            let once = format(text).unwrap();
            assert_eq!(format(&once).unwrap(), once);
            // Every comment survives.
            for c in text
                .lines()
                .filter_map(|l| l.find("//").map(|i| l[i..].trim_end()))
            {
                assert!(once.contains(c), "lost comment {c}");
            }
            // The design examples are canonical but for column alignment.
            let squash = |s: &str| {
                s.split(' ')
                    .filter(|w| !w.is_empty())
                    .collect::<Vec<_>>()
                    .join(" ")
            };
            assert_eq!(squash(&once), squash(text));
        }
    }

    #[test]
    fn normalizes_layout_and_keeps_trailing_comments() {
        let messy = "rule (move ?r ?a ?b)   where ?a!=?b {  // go\n sequence{MoveTo(robot:?r,target:?b)\n/* then */ Done()}\n}\n";
        let out = format(messy).unwrap();
        assert_eq!(
            out,
            "rule (move ?r ?a ?b) where ?a != ?b {  // go\n    sequence {\n        MoveTo(robot: ?r, target: ?b)\n        /* then */\n        Done()\n    }\n}\n"
        );
        assert_eq!(format(&out).unwrap(), out);
    }

    #[test]
    fn refuses_text_that_does_not_parse() {
        assert!(format("rule (x {").is_err());
    }
}
