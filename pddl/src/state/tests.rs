use super::*;
use crate::logic::{decode, name};

const DOMAIN: &str = "(define (domain d) (:requirements :adl :derived-predicates :fluents)
  (:types block table - object)
  (:constants t0 - table)
  (:predicates (on ?x - block ?y - object) (clear ?x - object) (above ?x - block ?y - object))
  (:functions (moves))
  (:derived (above ?x - block ?y - object)
     (or (on ?x ?y) (exists (?z - block) (and (on ?x ?z) (above ?z ?y))))))";

const PROBLEM: &str = "(define (problem p) (:domain d)
  (:objects a b c - block)
  (:init (on a b) (on b c) (on c t0) (clear a) (= (moves) 0))
  (:goal (and (above a t0) (clear a))))";

fn world() -> World {
    let du = crate::pipeline::domain_unit_from(DOMAIN, 0);
    let pu = crate::pipeline::problem_unit_from(PROBLEM, 1, du.domain.as_ref(), &du.index);
    assert!(du.diagnostics.is_empty(), "{:?}", du.diagnostics);
    assert!(pu.diagnostics.is_empty(), "{:?}", pu.diagnostics);
    World::of_checked(
        du.domain.as_ref().unwrap(),
        &du.index,
        pu.problem.as_ref().unwrap(),
        &pu.index,
    )
    .unwrap()
}

fn holds(w: &World, s: &State, text: &str) -> bool {
    let c = w.compile(&decode::formula(text).unwrap(), &[]).unwrap();
    w.holds(s, &c, &mut Vec::new(), None)
}

#[test]
fn the_initial_state_closes_derived_predicates() {
    let w = world();
    let s = w.initial_state();
    assert!(holds(&w, &s, "(above a t0)"));
    assert!(holds(&w, &s, "(above a c)"));
    assert!(!holds(&w, &s, "(above c a)"));
    assert!(w.holds(&s, w.goal().unwrap(), &mut Vec::new(), None));
    assert!(holds(&w, &s, "(= (moves) 0)"));
}

#[test]
fn quantifiers_range_over_the_type_hierarchy() {
    let w = world();
    let s = w.initial_state();
    // `object` includes the constant t0; `block` does not.
    assert!(holds(&w, &s, "(exists (?y - object) (on c ?y))"));
    assert!(!holds(&w, &s, "(exists (?y - block) (on c ?y))"));
    assert!(holds(&w, &s, "(forall (?x - block) (above ?x t0))"));
}

#[test]
fn why_not_names_the_literal_and_the_path_to_it() {
    let w = world();
    let s = w.initial_state();
    let c = w
        .compile(
            &decode::formula("(and (clear a) (forall (?x - block) (clear ?x)))").unwrap(),
            &[],
        )
        .unwrap();
    let (why, path) = w.why_not(&s, &c, &mut Vec::new(), None);
    assert_eq!(why, "for ?x = b: `(clear b)` is false");
    assert_eq!(path, [1, 0]);
}

#[test]
fn compiling_refuses_what_the_world_does_not_have() {
    let w = world();
    let err = |t: &str| w.compile(&decode::formula(t).unwrap(), &[]).unwrap_err();
    assert_eq!(
        err("(is_broken a)"),
        "predicate `is_broken` is not declared in the domain"
    );
    assert_eq!(
        err("(on a)"),
        "predicate `on` takes 2 arguments, but 1 is given"
    );
    assert_eq!(
        err("(on t0 a)"),
        "`t0` has type `table`, but argument 1 of `on` must be `block`"
    );
    assert_eq!(
        err("(clear zz)"),
        "`zz` is not an object of the problem or a constant of the domain"
    );
    assert_eq!(err("(clear ?x)"), "variable `?x` is not bound here");
    let e = decode::effect("(above a b)").unwrap();
    assert!(w.compile_effect(&e, &[]).unwrap_err().contains("derived"));
}

#[test]
fn effects_with_slots_apply_deletes_before_adds() {
    let w = world();
    let mut s = w.initial_state();
    let vars = [name("x"), name("from"), name("to")];
    let e = decode::effect(
        "(and (not (on ?x ?from)) (on ?x ?to) (not (clear ?to)) (clear ?from) (increase (moves) 1))",
    )
    .unwrap();
    let e = w.compile_effect(&e, &vars).unwrap();
    let mut b = vec![
        w.object_id("a").unwrap(),
        w.object_id("b").unwrap(),
        w.object_id("t0").unwrap(),
    ];
    let mut ch = Changes::default();
    w.collect(&s, &e, &mut b, None, &mut ch);
    w.apply(&mut s, ch);
    assert!(holds(&w, &s, "(and (on a t0) (clear b) (= (moves) 1))"));
    assert!(
        !holds(&w, &s, "(above a b)"),
        "derived atoms are recomputed"
    );
}

#[test]
fn a_model_that_does_not_fit_is_refused_with_the_reason() {
    let mut m = world().model().clone();
    m.init.push(decode::init_fact("(clear nobody)").unwrap());
    assert_eq!(
        World::new(m).err().unwrap(),
        "initial fact `(clear nobody)`: `nobody` is not an object of the problem or a constant of the domain"
    );
    let mut m = world().model().clone();
    m.objects[0].types = vec![name("robot")];
    assert!(World::new(m)
        .err()
        .unwrap()
        .contains("type `robot` is not declared"));
}

#[test]
fn keys_agree_with_the_checked_indexes() {
    let du = crate::pipeline::domain_unit_from(DOMAIN, 0);
    let pu = crate::pipeline::problem_unit_from(PROBLEM, 1, du.domain.as_ref(), &du.index);
    let w = world();
    for (n, sig) in &du.index.predicates {
        assert_eq!(w.predicate_id(n), Some(sig.index as u32));
    }
    for (n, o) in &pu.index.objects {
        assert_eq!(w.object_id(n), Some(o.id));
    }
}
