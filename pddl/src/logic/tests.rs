use super::*;

const ACTION: &str = "(define (domain d) (:predicates (p ?x) (q) (r ?x ?y)) (:functions (c))
  (:action a :parameters (?x ?y)
   :precondition (and (p ?x) (not (= ?x k)) (forall (?y - t) (imply (p ?y) (q))) (>= (c) 1))
   :effect (and (not (p ?x)) (r ?x ?y) (forall (?z) (when (q) (r ?z ?x))) (increase (c) (* 2 (c))))))";

fn schema() -> ActionSchema {
    let (d, diags) = crate::parse::parse_domain(ACTION, 0);
    assert!(diags.is_empty(), "{diags:?}");
    ActionSchema::from_ast(&d.unwrap().actions[0])
}

#[test]
fn prints_what_the_ast_prints() {
    let (d, _) = crate::parse::parse_domain(ACTION, 0);
    let a = &d.unwrap().actions[0];
    let s = schema();
    assert_eq!(s.pre_start[0].to_string(), a.pre_start[0].to_string());
    assert_eq!(s.eff_end[0].to_string(), a.eff_end[0].to_string());
}

#[test]
fn decoding_what_was_printed_gives_the_same_value() {
    let s = schema();
    for f in &s.pre_start {
        assert_eq!(&decode::formula(&f.to_string()).unwrap(), f);
    }
    for e in &s.eff_end {
        assert_eq!(&decode::effect(&e.to_string()).unwrap(), e);
    }
    let sig = decode::signature("(at ?r - robot ?l - (either bin tray) ?x)").unwrap();
    assert_eq!(sig.to_string(), "(at ?r - robot ?l - (either bin tray) ?x)");
    assert_eq!(
        decode::init_fact("(= (Cost A) 2.5)").unwrap(),
        InitFact::Value(Atom::ground("cost", &["a"]), 2.5)
    );
}

#[test]
fn decoding_refuses_what_is_not_one_expression() {
    assert!(decode::formula("(on a b) (on b c)").is_err());
    assert!(decode::formula("(on a").is_err());
    assert!(decode::formula("").is_err());
    assert!(decode::atom("(and (on a b))").is_err());
    assert!(decode::effect("(or (a) (b))").is_err());
}

#[test]
fn grounding_replaces_free_variables_only() {
    let s = schema();
    let params = s.param_names();
    let objects = [name("o1"), name("o2")];
    let b = Binding {
        params: &params,
        objects: &objects,
    };
    assert_eq!(
        s.pre_start[0].ground(&b).to_string(),
        "(and (p o1) (not (= o1 k)) (forall (?y - t) (imply (p ?y) (q))) (>= (c) 1))"
    );
    assert_eq!(
        s.eff_end[0].ground(&b).to_string(),
        "(and (not (p o1)) (r o1 o2) (forall (?z) (when (q) (r ?z o1))) (increase (c) (* 2 (c))))"
    );
}

#[test]
fn renaming_swaps_at_once_and_never_captures() {
    let s = schema();
    let swap = [(name("x"), name("y")), (name("y"), name("x"))];
    let r = Renaming { pairs: &swap };
    assert_eq!(
        s.eff_end[0].rename(&r).to_string(),
        "(and (not (p ?y)) (r ?y ?x) (forall (?z) (when (q) (r ?z ?y))) (increase (c) (* 2 (c))))"
    );
    // `?x` becomes `?z`: the quantifier's own `?z` is renamed out of the way.
    let onto_z = [(name("x"), name("z"))];
    let r = Renaming { pairs: &onto_z };
    assert_eq!(
        s.eff_end[0].rename(&r).to_string(),
        "(and (not (p ?z)) (r ?z ?y) (forall (?z_1) (when (q) (r ?z_1 ?z))) (increase (c) (* 2 (c))))"
    );
}

#[test]
fn literals_and_outcomes_of_plain_effects() {
    let e = decode::effect("(and (not (a)) (b) (a) (increase (total-cost) 2))").unwrap();
    let shown: Vec<String> = e
        .literals()
        .unwrap()
        .iter()
        .map(|l| l.to_string())
        .collect();
    assert_eq!(shown, ["(not (a))", "(b)", "(a)"]);
    let out: Vec<String> = e.outcome().unwrap().iter().map(|l| l.to_string()).collect();
    assert_eq!(out, ["(a)", "(b)"], "an atom deleted and added stays true");
    assert!(decode::effect("(forall (?x) (a ?x))")
        .unwrap()
        .literals()
        .is_none());
}

#[test]
fn serde_writes_pddl_text() {
    let f = decode::formula("(and (on a b) (not (clear b)))").unwrap();
    let json = serde_json::to_string(&f).unwrap();
    assert_eq!(json, "\"(and (on a b) (not (clear b)))\"");
    let back: Formula = serde_json::from_str(&json).unwrap();
    assert_eq!(back, f);
    let bad = serde_json::from_str::<Formula>("\"(and (on a b)\"");
    assert!(bad.unwrap_err().to_string().contains("(and (on a b)"));
}

#[test]
fn to_ast_and_back_is_the_same_value() {
    let s = schema();
    let span = crate::source::Span::new(0, 3, 9);
    for f in &s.pre_start {
        let a = f.to_ast(span);
        assert_eq!(a.span(), span);
        assert_eq!(&Formula::from_ast(&a), f);
    }
}
