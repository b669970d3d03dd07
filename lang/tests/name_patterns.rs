//! The conformance suite of action-name patterns
//! (`fixtures/name_patterns.txt`): each pattern, parsed as a rule head,
//! matches each action name as the file says. And the matcher agrees with
//! a plain backtracking matcher written from the reference's words ("from
//! left to right, each capture the shortest part that lets the rest
//! match") on every pattern and name over a small alphabet.

use btc_lang::rules::matching::{match_name, Captures};
use btc_lang::rules::{parse_rules, Item, NamePart};

fn parts(pattern: &str) -> Vec<NamePart> {
    let parsed = parse_rules(&format!("rule ({pattern} ?x) => skip"), 0);
    assert!(
        parsed.diagnostics.is_empty(),
        "{pattern}: {:#?}",
        parsed.diagnostics
    );
    match &*parsed.items[0].item {
        Item::Rule(r) => r.pattern.name.clone(),
        other => panic!("{pattern}: {other:?}"),
    }
}

fn show(m: &Option<Captures>) -> String {
    match m {
        None => "-".into(),
        Some(c) if c.is_empty() => "()".into(),
        Some(c) => c
            .iter()
            .map(|(n, v)| format!("{n}={v}"))
            .collect::<Vec<_>>()
            .join(","),
    }
}

#[test]
fn the_conformance_suite() {
    let text = include_str!("fixtures/name_patterns.txt");
    let mut cases = 0;
    for (no, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let cols: Vec<&str> = line.split_whitespace().collect();
        assert_eq!(cols.len(), 3, "line {}: {line}", no + 1);
        let got = show(&match_name(&parts(cols[0]), cols[1]));
        assert_eq!(
            got,
            cols[2],
            "line {}: `{}` on `{}`",
            no + 1,
            cols[0],
            cols[1]
        );
        cases += 1;
    }
    assert!(cases >= 50, "{cases} cases");
}

/// The reference's rule, by backtracking: literals fold, each capture
/// takes at least one character, shortest first.
fn reference(parts: &[NamePart], rest: &str, caps: &mut Captures) -> bool {
    let Some((first, more)) = parts.split_first() else {
        return rest.is_empty();
    };
    match first {
        NamePart::Lit { key, .. } => rest
            .strip_prefix(key.as_str())
            .is_some_and(|r| reference(more, r, caps)),
        NamePart::Capture { name } => {
            let ends = rest.char_indices().skip(1).map(|(i, _)| i);
            for i in ends.chain([rest.len()]).filter(|&i| i > 0) {
                caps.push((name.text.clone(), rest[..i].to_owned()));
                if reference(more, &rest[i..], caps) {
                    return true;
                }
                caps.pop();
            }
            false
        }
    }
}

#[test]
fn agrees_with_backtracking_on_every_small_case() {
    // Patterns of up to four parts over `a`, `-`, `_` and captures; names
    // of up to six characters over `a`, `b`, `-`, `_`.
    let pieces = ["a", "-", "_", "a-", "{x}", "{y}"];
    let mut patterns: Vec<String> = pieces.iter().map(|p| p.to_string()).collect();
    for _ in 0..3 {
        let longer: Vec<String> = patterns
            .iter()
            .flat_map(|p| pieces.iter().map(move |q| format!("{p}{q}")))
            .filter(|p| p.matches("{x}").count() <= 1 && p.matches("{y}").count() <= 1)
            .collect();
        patterns.extend(longer);
    }
    patterns.sort();
    patterns.dedup();
    // A name must start with a letter or a capture to be a rule head.
    patterns.retain(|p| p.starts_with('a') || p.starts_with('{'));
    let mut names = vec![String::new()];
    for _ in 0..5 {
        let longer: Vec<String> = names
            .iter()
            .flat_map(|n| ["a", "b", "-", "_"].iter().map(move |c| format!("{n}{c}")))
            .collect();
        names.extend(longer);
    }
    names.retain(|n| !n.is_empty());
    let mut compared = 0;
    for p in &patterns {
        let ps = parts(p);
        for n in &names {
            let mut caps = Vec::new();
            let want = reference(&ps, n, &mut caps).then_some(caps);
            assert_eq!(match_name(&ps, n), want, "`{p}` on `{n}`");
            compared += 1;
        }
    }
    assert!(compared > 100_000, "{compared}");
}
