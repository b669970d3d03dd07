use super::*;

fn rules_files(dir: &std::path::Path, out: &mut Vec<std::path::PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("a readable folder") {
        let path = entry.expect("a folder entry").path();
        if path.is_dir() {
            rules_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "btrules") {
            out.push(path);
        }
    }
}

/// The quick parse (no error messages) is only sound if it fails
/// exactly where the rich one reports errors, and reads what the rich
/// one reads elsewhere: checked on every item of every rules file in
/// the repository, the diagnostics fixtures' broken items included.
#[test]
fn quick_and_rich_parses_agree_on_every_item() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut files = Vec::new();
    for dir in ["examples", "tests", "lang/tests", "stdlib", "lsp/tests"] {
        rules_files(&root.join(dir), &mut files);
    }
    let (mut items, mut broken) = (0, 0);
    for path in &files {
        let text = std::fs::read_to_string(path).expect("a UTF-8 rules file");
        let parsed = parse_rules(&text, 0);
        items += parsed.items.len();
        broken += usize::from(!parsed.diagnostics.is_empty());
        if let Some(d) = quick_and_rich_disagree(&text) {
            panic!("{}: {d}", path.display());
        }
    }
    assert!(
        files.len() > 50 && items > 500 && broken > 20,
        "{} files, {items} items, {broken} with errors",
        files.len()
    );
}

fn parse(text: &str) -> ParsedRules {
    parse_rules(text, 0)
}

fn codes(p: &ParsedRules) -> Vec<(&'static str, u32)> {
    p.diagnostics
        .iter()
        .map(|d| (d.code, d.span.start))
        .collect()
}

#[test]
fn the_design_examples_parse_without_errors() {
    for text in [
        include_str!("../../../../examples/ariac/rules.btrules"),
        include_str!("../../../../examples/p3_assembler/rules.btrules"),
    ] {
        let p = parse(text);
        assert!(p.diagnostics.is_empty(), "{:#?}", p.diagnostics);
        assert!(p
            .items
            .iter()
            .all(|i| !matches!(*i.item, Item::Error { .. })));
    }
}

#[test]
fn reads_patterns_guards_and_effects() {
    let p = parse("rule (PICK_{op} ?a [?loc]) where op in markers, ?a != ?loc {\n  Pick(agent: ?A, marker: markers[op])\n  effect (and (holding ?a) (not (free ?a)))\n}");
    assert!(p.diagnostics.is_empty(), "{:#?}", p.diagnostics);
    let Item::Rule(r) = &*p.items[0].item else {
        panic!()
    };
    assert_eq!(r.pattern.name_text(), "PICK_{op}");
    assert!(r.pattern.params[1].optional);
    assert_eq!(r.guards.len(), 2);
    let RuleBody::Template { body, effect } = &r.body else {
        panic!()
    };
    assert!(effect.is_some());
    let Template::Call { args, .. } = &body[0] else {
        panic!()
    };
    assert!(matches!(&args[0].value, Value::Var { name } if name.text == "a"));
    assert!(matches!(&args[1].value, Value::Lookup { .. }));
}

#[test]
fn spans_are_relative_to_their_item() {
    let p = parse("action A()\n\naction B(x: int)");
    assert_eq!(p.items[1].offset, 12);
    let Item::Node(n) = &*p.items[1].item else {
        panic!()
    };
    assert_eq!(n.name.span, Span::new(0, 7, 8));
}

#[test]
fn a_broken_item_does_not_hide_the_next_ones() {
    let text = "rule (move ?r ?a ?b) {\n  MoveTo(robot: ?r, target: )\n}\nrule (pick ?r) {\n  Pick(robot ?r)\n}\naction Pick(robot: robot)\n";
    let p = parse(text);
    assert_eq!(codes(&p).len(), 2, "{:#?}", p.diagnostics);
    assert_eq!(p.items.len(), 3);
    assert!(matches!(*p.items[2].item, Item::Node(_)));
}

#[test]
fn a_missing_brace_is_recovered_at_the_next_line_start_keyword() {
    let text = "rule (move ?r ?a ?b) {\n  MoveTo(robot: ?r)\nrule (pick ?r) { Pick(robot: ?r) }\n";
    let p = parse(text);
    assert_eq!(p.items.len(), 2);
    assert_eq!(p.diagnostics.len(), 1, "{:#?}", p.diagnostics);
    assert!(matches!(*p.items[1].item, Item::Rule(_)));
}

#[test]
fn interpolation_and_escapes() {
    let p = parse("tree T() { sequence \"move {?Robot} to {op} \\{x\\}\" { } }");
    assert!(p.diagnostics.is_empty(), "{:#?}", p.diagnostics);
    let Item::Tree(t) = &*p.items[0].item else {
        panic!()
    };
    let Template::Control { name: Some(s), .. } = &t.body[0] else {
        panic!()
    };
    assert_eq!(s.parts.len(), 5);
    assert!(matches!(&s.parts[1], StrPart::Var { name } if name.text == "robot"));
    assert!(matches!(&s.parts[4], StrPart::Text { text } if text == " {x}"));
}

#[test]
fn escapes_map_offsets_in_the_text_back_into_the_file() {
    let src = r#"tree T() { sequence "a\"b\\c\n{?x}d" { } }"#;
    let p = parse(src);
    assert!(p.diagnostics.is_empty(), "{:#?}", p.diagnostics);
    let Item::Tree(t) = &*p.items[0].item else {
        panic!()
    };
    let Template::Control { name: Some(s), .. } = &t.body[0] else {
        panic!()
    };
    // a " b \ c \n: the escapes are the text's bytes 1, 3 and 5.
    assert_eq!(s.escapes, [1, 3, 5]);
    let open = src.find('"').unwrap();
    assert_eq!(s.span.start as usize, open);
    assert_eq!(s.source_offset(0), open + 1);
    // `b` comes after `\"`, `c` after two escapes, the newline is at its `\`.
    assert_eq!(&src[s.source_offset(2)..][..1], "b");
    assert_eq!(&src[s.source_offset(4)..][..1], "c");
    assert_eq!(&src[s.source_offset(5)..][..2], "\\n");
}

#[test]
fn deep_nesting_is_refused_not_overflowed() {
    let text = format!(
        "plan {{ {} steps {} }}",
        "sequence { ".repeat(5000),
        "} ".repeat(5000)
    );
    let p = parse(&text);
    assert!(p.diagnostics.iter().any(|d| d.message.contains("nested")));
    let formula = format!(
        "condition C() = {}(p){}",
        "(not ".repeat(5000),
        ")".repeat(5000)
    );
    let p = parse(&formula);
    assert!(p.diagnostics.iter().any(|d| d.code == "P004"));
}
