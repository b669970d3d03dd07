//! The value rules, case by case, from BT.CPP's own tests and operators.

use super::super::{parse, ErrorClass};
use super::Env;
use crate::engine::Value;

/// Entries by variable name, for scripts parsed alone.
struct Vars {
    names: Vec<String>,
    values: Vec<Option<Value>>,
}

impl Env for Vars {
    fn get(&self, var: u32) -> Option<&Value> {
        self.values[var as usize].as_ref()
    }
    fn entry(&mut self, var: u32, create: bool) -> Option<&mut Value> {
        let v = &mut self.values[var as usize];
        if v.is_none() && create {
            *v = Some(Value::Empty);
        }
        v.as_mut()
    }
}

fn run(src: &str, given: &[(&str, Value)]) -> Result<Value, ErrorClass> {
    let s = parse(src).map_err(|e| e.class)?;
    let mut vars = Vars {
        values: s
            .vars
            .iter()
            .map(|n| given.iter().find(|(k, _)| k == n).map(|(_, v)| v.clone()))
            .collect(),
        names: s.vars.clone(),
    };
    assert_eq!(vars.names, s.vars);
    s.run(&mut vars).map_err(|e| e.class)
}

fn f(x: f64) -> Result<Value, ErrorClass> {
    Ok(Value::Float(x))
}

#[test]
fn arithmetic_computes_in_doubles_with_precedence() {
    assert_eq!(run("1 + 2 * 3", &[]), f(7.0));
    assert_eq!(run("(1 + 2) * 3", &[]), f(9.0));
    assert_eq!(run("7 / 2", &[]), f(3.5));
    assert_eq!(run("-2 * -3", &[]), f(6.0));
    assert_eq!(run("42", &[]), Ok(Value::Int(42)));
    assert_eq!(run("0x1F", &[]), Ok(Value::Int(31)));
    assert_eq!(run("1e3", &[]), f(1000.0));
    assert_eq!(run("10 - 2 - 3", &[]), f(5.0));
}

#[test]
fn comparisons_chain_and_give_one_or_zero() {
    assert_eq!(run("1 < 2 < 3", &[]), f(1.0));
    assert_eq!(run("1 < 3 < 2", &[]), f(0.0));
    assert_eq!(run("0.1 + 0.2 == 0.3", &[]), f(1.0));
    assert_eq!(run("'a' < 'b'", &[]), f(1.0));
    assert_eq!(run("'3' == 3", &[]), f(1.0));
    assert_eq!(run("'x' == 3", &[]), Err(ErrorClass::Type));
    // A string is read up to the end of its number, as BT.CPP does.
    assert_eq!(run("'3a' == 3", &[]), f(1.0));
    assert_eq!(run("true == 1", &[]), f(1.0));
    assert_eq!(run("0 / 0 > 7", &[]), f(1.0));
    assert_eq!(run("0 / 0 == 0 / 0", &[]), f(0.0));
}

#[test]
fn logic_and_bitwise_operators_take_their_kinds_of_number() {
    assert_eq!(run("true && false", &[]), f(0.0));
    assert_eq!(run("true || false", &[]), f(1.0));
    // An integer must be 0 or 1; a double (any arithmetic) may be anything.
    assert_eq!(run("2 && 1", &[]), Err(ErrorClass::Type));
    assert_eq!(run("2.5 && 1", &[]), f(1.0));
    assert_eq!(run("-2.5 && 1", &[]), Err(ErrorClass::Type));
    assert_eq!(run("6 & 3", &[]), f(2.0));
    assert_eq!(run("6 | 3 ^ 1", &[]), f(6.0));
    assert_eq!(run("1.5 & 1", &[]), Err(ErrorClass::Type));
    assert_eq!(run("!0", &[]), f(1.0));
    assert_eq!(run("~0", &[]), f(-1.0));
}

#[test]
fn strings_add_and_concatenate() {
    let t = |s: &str| Ok(Value::Text(s.into()));
    assert_eq!(run("'ab' + 'cd'", &[]), t("abcd"));
    assert_eq!(run("'n=' .. 3", &[]), t("n=3"));
    assert_eq!(run("'a' - 'b'", &[]), Err(ErrorClass::Type));
    assert_eq!(run("'a' + 1", &[]), Err(ErrorClass::Type));
    assert_eq!(run("1 .. 2", &[]), Ok(Value::Empty));
}

#[test]
fn the_ternary_tests_strings_and_numbers() {
    assert_eq!(run("1 ? 'y' : 'n'", &[]), Ok(Value::Text("y".into())));
    assert_eq!(run("0 ? 'y' : 'n'", &[]), Ok(Value::Text("n".into())));
    assert_eq!(run("'3' ? 2 : 3", &[]), Ok(Value::Int(2)));
    assert_eq!(run("'s' ? 2 : 3", &[]), Err(ErrorClass::Type));
    assert_eq!(run("y := y ? 1 : 0", &[]), Err(ErrorClass::Type));
}

#[test]
fn assignments_create_update_and_convert() {
    assert_eq!(run("a := 1; a += 2; a", &[]), Ok(Value::Int(3)));
    assert_eq!(run("a = 1", &[]), Err(ErrorClass::NotFound));
    assert_eq!(run("a = 5; a", &[("a", Value::Int(1))]), Ok(Value::Int(5)));
    assert_eq!(
        run("a = 2.5", &[("a", Value::Int(1))]),
        Err(ErrorClass::Type)
    );
    assert_eq!(run("a := 'x'; a += 'y'", &[]), Ok(Value::Text("xy".into())));
    assert_eq!(run("a := 'x'; a -= 'y'", &[]), Err(ErrorClass::Type));
    assert_eq!(run("a := 0; a += '3'", &[]), Err(ErrorClass::Type));
    // A string into a number entry is read as a double (BT.CPP: `num 7`).
    assert_eq!(run("a := 2; a = '7'", &[]), Ok(Value::Float(7.0)));
    assert_eq!(
        run("a += 1", &[("a", Value::Empty)]),
        Err(ErrorClass::NotInitialized)
    );
    assert_eq!(run("1 = 2", &[]), Err(ErrorClass::Type));
}

#[test]
fn unknown_and_empty_variables_are_errors_of_their_own() {
    assert_eq!(run("x + 1", &[]), Err(ErrorClass::NotFound));
    assert_eq!(
        run("x + 1", &[("x", Value::Empty)]),
        Err(ErrorClass::NotInitialized)
    );
    assert_eq!(
        run("x + 1", &[("x", Value::Text("2".into()))]),
        Err(ErrorClass::Type)
    );
}

#[test]
fn malformed_scripts_are_syntax_errors() {
    for s in [
        "", "1 +", "(1", "3foo", "65.", "'open", "1 ? 2", "a :=", "#", "1 2 )",
    ] {
        assert_eq!(run(s, &[]), Err(ErrorClass::Syntax), "{s}");
    }
    let deep = format!("{}1{}", "(".repeat(1000), ")".repeat(1000));
    assert_eq!(run(&deep, &[]), Err(ErrorClass::Syntax));
}
