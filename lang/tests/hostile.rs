//! Rules files written to break btc: nesting far past the limit (parsed,
//! checked and formatted on a small stack), runs of bad characters, long
//! lines of comments, bad escapes, names in other alphabets, empty files.

use btc_lang::db::{rules_diagnostics, Database};
use btc_lang::rules::parse::{parse_rules, MAX_ITEM_DEPTH};
use btc_testkit::hostile::{assert_linear, on_small_stack};

fn codes(text: &str) -> Vec<&'static str> {
    parse_rules(text, 0)
        .diagnostics
        .iter()
        .map(|d| d.code)
        .collect()
}

fn check(text: &str) -> Vec<String> {
    let mut db = Database::new();
    let f = db.set_file("/r/rules.btrules", text.to_owned());
    rules_diagnostics(&db, f)
        .iter()
        .map(|d| format!("{} {}", d.code, d.message))
        .collect()
}

/// Parse, check (through the database) and format, all on a small stack.
fn everything(text: String) -> (Vec<String>, bool) {
    on_small_stack(move || {
        let diags = check(&text);
        let formatted = btc_lang::rules::fmt::format(&text).is_ok();
        (diags, formatted)
    })
}

#[test]
fn chained_decorators_ten_times_the_limit_are_refused() {
    for n in [10 * MAX_ITEM_DEPTH, 5000] {
        let text = format!(
            "domain \"d.pddl\"\ntree T() {{ {} steps }}\nrule (a) {{ {}A() }}\n",
            "inverter ".repeat(n),
            "retry(3) force_success ".repeat(n / 2)
        );
        let (diags, formatted) = everything(text);
        assert!(
            diags.iter().filter(|d| d.starts_with("R060")).count() == 2,
            "{diags:#?}"
        );
        assert!(!formatted);
    }
}

#[test]
fn decorators_and_blocks_mixed_ten_times_the_limit_are_refused() {
    let n = 10 * MAX_ITEM_DEPTH;
    let text = format!(
        "tree T() {{ {} A() {} }}",
        "inverter inverter parallel(success: 1, failure: 1) { ".repeat(n / 3),
        "}".repeat(n / 3)
    );
    let (diags, _) = everything(text);
    assert!(diags.iter().any(|d| d.starts_with("R060")), "{diags:#?}");
}

#[test]
fn formulas_ten_times_the_limit_are_refused() {
    let n = 10 * btc_pddl::limits::MAX_NESTING;
    let text = format!(
        "condition C() = {}(p){}\nrule (a) {{ A() effect {}(p){} }}",
        "(not ".repeat(n),
        ")".repeat(n),
        "(and ".repeat(n),
        ")".repeat(n)
    );
    let (diags, _) = everything(text);
    assert!(
        diags.iter().filter(|d| d.starts_with("P004")).count() >= 2,
        "{diags:#?}"
    );
}

#[test]
fn nesting_at_the_limit_still_parses() {
    let depth = MAX_ITEM_DEPTH - 2;
    let text = format!(
        "tree T() {{ {} A() {} }}",
        "inverter sequence { ".repeat(depth / 2),
        "}".repeat(depth / 2)
    );
    let c = on_small_stack(move || codes(&text));
    assert!(c.is_empty(), "{c:?}");
}

#[test]
fn a_run_of_bad_characters_is_one_diagnostic() {
    let text = format!("action A()\n{}\n", "\0".repeat(10_000));
    let p = parse_rules(&text, 0);
    let bad: Vec<_> = p
        .diagnostics
        .iter()
        .filter(|d| d.message.contains("cannot start anything"))
        .collect();
    assert_eq!(bad.len(), 1, "{:#?}", p.diagnostics.len());
    assert!(bad[0].message.contains("9999"), "{}", bad[0].message);
    assert_eq!(bad[0].span.end - bad[0].span.start, 10_000);
}

#[test]
fn lexical_errors_are_capped_per_file() {
    let text = "\0 ".repeat(100_000);
    let p = parse_rules(&text, 0);
    let max = btc_pddl::limits::MAX_DIAGNOSTICS_PER_FILE;
    let lexical = p
        .diagnostics
        .iter()
        .filter(|d| d.message.contains("cannot start") || d.message.contains("more lexical"))
        .count();
    assert_eq!(lexical, max + 1);
    assert!(p
        .diagnostics
        .iter()
        .any(|d| d.message.contains("99900 more lexical errors")));
}

/// Lexing is linear: ten times the text takes about ten times as long,
/// not a hundred (each comment used to search back for its line's start).
#[test]
fn comments_on_one_long_line_lex_in_linear_time() {
    assert_linear(
        "lexing comments on one line",
        20_000,
        30.0,
        |n| "/* c */ x ".repeat(n),
        |t| {
            btc_lang::rules::lexer::lex(t, 0);
        },
    );
}

/// Many rules for one action (a generated file, a file pasted twice) are
/// checked in time linear in their number: items with equal heads used to
/// share one salsa identity hash, and finding each one's tracked struct
/// walked all the others (a 6.5 MB file spent 60% of its check there).
#[test]
fn many_rules_with_one_head_check_in_linear_time() {
    assert_linear(
        "checking rules with one head",
        2_000,
        30.0,
        |n| format!("action A()\n{}", "rule (a) { A() }\n".repeat(n)),
        |t| {
            check(t);
        },
    );
}

#[test]
fn a_bad_escape_is_named() {
    let c = parse_rules("tree T() { sequence \"a\\rb\" { } }", 0);
    let msgs: Vec<&str> = c.diagnostics.iter().map(|d| d.message.as_str()).collect();
    assert_eq!(msgs.len(), 1, "{msgs:?}");
    assert!(msgs[0].contains("`\\r` is not an escape"), "{msgs:?}");
    assert!(!msgs[0].contains("found a string"), "{msgs:?}");
}

#[test]
fn names_in_other_alphabets_read_as_in_pddl() {
    let c = codes("condition Enabled() = (İs_enabled)\naction Çek(ağırlık: int)\n");
    assert!(c.is_empty(), "{c:?}");
}

#[test]
fn an_empty_rules_file_says_it_has_no_domain() {
    for text in ["", "\n\n", "// only a comment\n"] {
        let d = check(text);
        assert!(d.iter().any(|d| d.starts_with("R017")), "{text:?}: {d:?}");
    }
}
