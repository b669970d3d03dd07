//! Durations simulated in ticks (`btc run --ticks-per-time-unit`): on the
//! 3-robot timed plan run on its schedule, each step lasts its duration
//! times the ticks per unit (its actions take a tick or two), starts once
//! what it waits for has ended, and the plan's order is kept; without it
//! the steps take only their actions' ticks.

mod common;

use btc_runtime::engine::TickEvent;
use btc_runtime::{Options, TreeDoc};
use common::{events, root, traced};
use std::collections::BTreeMap;

/// Each step's (start tick, end tick), 1-based steps.
fn spans(ticks_per_unit: u32) -> BTreeMap<usize, (u64, u64)> {
    let dir = root().join("runtime/tests/fixtures/three_way/timed");
    let ex = common::load(
        &dir.join("scheduled.btrules"),
        &dir.join("plan.tplan"),
        &dir.join("problem.pddl"),
    );
    let w = ex.world();
    let mut e = traced(ex.engine(&w, &TreeDoc::from_ir(&ex.ir), Options::default()));
    e.simulate_durations(ticks_per_unit);
    let status = e.run(1_000_000, |_| {});
    assert_eq!(status.name(), "SUCCESS");
    assert!(e.goal().is_none_or(|(ok, _)| ok));
    let mut out = BTreeMap::new();
    for t in events(&e) {
        match t {
            TickEvent::StepStarted { tick, step } => {
                out.insert(*step as usize + 1, (*tick, 0));
            }
            TickEvent::StepFinished { tick, step } => {
                out.get_mut(&(*step as usize + 1)).expect("started").1 = *tick;
            }
            _ => {}
        }
    }
    out
}

#[test]
fn a_step_lasts_its_duration_in_ticks() {
    let per_unit = 10;
    let s = spans(per_unit);
    assert_eq!(s.len(), 22);
    // Moves and transports take 5 units, the inspection (step 8) 2.
    for (step, &(start, end)) in &s {
        let want = if *step == 8 { 20 } else { 50 };
        assert_eq!(end - start, want, "step {step}: {start}..{end}");
    }
    // The three first moves start at once; r2d2's transport (step 4) when
    // its move (step 1) and c3po's (step 2, ending at the same time) have
    // ended: at that tick or the next (a branch ticked before the one whose
    // step ends sees it end on the next tick).
    assert_eq!((s[&1].0, s[&2].0, s[&3].0), (1, 1, 1));
    let ended = s[&1].1.max(s[&2].1);
    assert!((ended..=ended + 1).contains(&s[&4].0), "{:?}", s[&4]);
    // The makespan follows the plan's (about 37 units): far below the
    // sum of the durations (107 units) the steps one after another take.
    let makespan = s.values().map(|&(_, e)| e).max().unwrap();
    assert!((300..=420).contains(&makespan), "makespan {makespan} ticks");
}

#[test]
fn without_durations_steps_take_their_actions_ticks() {
    let s = spans(0);
    for (step, &(start, end)) in &s {
        assert!(end - start <= 2, "step {step}: {start}..{end}");
    }
}
