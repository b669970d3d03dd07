//! Where a syntax error is, and how it reads with and without its position.

use super::{parse, Expr, Literal, Problem};

fn error(src: &str) -> (Problem, std::ops::Range<usize>, String, String) {
    let e = parse(src).expect_err(src);
    (
        e.problem.clone(),
        e.span.clone(),
        e.describe(),
        e.to_string(),
    )
}

#[test]
fn the_span_covers_the_bad_token() {
    let (p, span, describe, message) = error("a := (1 + ) * 2");
    assert_eq!(span, 10..11);
    assert_eq!(
        p,
        Problem::Unexpected {
            expected: "expected an operand",
            got: Some(")".into())
        }
    );
    assert_eq!(describe, "expected an operand, got `)`");
    assert_eq!(message, "expected an operand at position 10, got `)`");

    let (_, span, describe, message) = error("x := 3foo");
    assert_eq!(span, 5..9);
    assert_eq!(
        describe,
        "`3foo` is not a token of BT.CPP's scripting language"
    );
    assert_eq!(message, "invalid token `3foo` at position 5");

    let (_, span, _, _) = error("x == 65.");
    assert_eq!(span, 5..8);
    // A character of several bytes is one token.
    let (_, span, _, _) = error("x := é");
    assert_eq!(span, 5..7);
}

#[test]
fn the_end_and_unterminated_strings() {
    let (_, span, describe, message) = error("x := (1");
    assert_eq!(span, 7..7);
    assert_eq!(describe, "expected `)`, but the script ends here");
    assert_eq!(message, "expected `)` at position 7, got the end");

    let (p, span, describe, message) = error("s := 'abc");
    assert_eq!(p, Problem::Unterminated("'abc".into()));
    assert_eq!(span, 5..9);
    assert_eq!(describe, "this string has no closing `'`");
    assert_eq!(message, "invalid token `'abc` at position 5");

    let (p, span, _, message) = error("  \n ");
    assert_eq!((p, span), (Problem::Empty, 0..0));
    assert_eq!(message, "the script is empty");
}

#[test]
fn too_deep_is_refused_at_the_token_that_goes_too_far() {
    let src = format!("{}1", "(".repeat(100));
    let (p, span, _, _) = error(&src);
    assert_eq!(p, Problem::TooDeep);
    assert_eq!(span, 65..66);
}

#[test]
fn literals_and_variables() {
    let s = parse("x := 'a'; y = true; z += 0x1F").unwrap();
    assert_eq!(s.vars, ["x", "y", "z"]);
    let Expr::Assign(_, _, right) = &s.statements[0] else {
        panic!()
    };
    assert_eq!(**right, Expr::Lit(Literal::Text("a".into())));
    let Expr::Assign(_, _, right) = &s.statements[1] else {
        panic!()
    };
    assert_eq!(**right, Expr::Lit(Literal::Float(1.0)));
    let Expr::Assign(_, _, right) = &s.statements[2] else {
        panic!()
    };
    assert_eq!(**right, Expr::Lit(Literal::Int(31)));
}
