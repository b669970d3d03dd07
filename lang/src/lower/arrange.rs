//! How the plan's steps are put together for `steps parallel` and `steps
//! scheduled` (plain `steps` is the steps in order; `steps backchained` is
//! in [`super::backchain`]). Both read each step's ground conditions and
//! effects from its [`StepInfo`], so a rule's `effect` orders and guards
//! steps exactly as it changes the KB.

use btc_ir::*;
use btc_pddl::logic::{Formula, Literal};
use std::collections::BTreeSet;
use std::sync::Arc;

/// A KB leaf: `KbHolds(formula)` or `KbApply(effect)`.
pub(super) fn kb_holds(f: Arc<Formula>, name: Option<String>) -> Node {
    Node::Leaf {
        scripts: Default::default(),
        leaf: LeafKind::Condition,
        id: "KbHolds".into(),
        name: name.map(Label::text),
        ports: vec![Port {
            name: "formula".into(),
            value: PortValue::Formula(f),
        }],
    }
}

/// A step's conditions and effects as literals, when they are plain
/// conjunctions; `None` otherwise (such a step is ordered conservatively).
fn step_literals(info: &StepInfo) -> Option<(Vec<Literal>, Vec<Literal>)> {
    let mut pre = Vec::new();
    for f in [
        &info.logic.pre_start,
        &info.logic.pre_over_all,
        &info.logic.pre_end,
    ]
    .into_iter()
    .flatten()
    {
        pre.extend(f.literals()?);
    }
    let mut eff = Vec::new();
    for e in [&info.logic.eff_start, &info.logic.eff_end]
        .into_iter()
        .flatten()
    {
        eff.extend(e.literals()?);
    }
    Some((pre, eff))
}

/// Orders steps by causal links and threats: step j comes after step i
/// (i < j) when i's effects touch j's conditions or effects, or j's effects
/// touch i's conditions. Steps whose conditions or effects are not plain
/// conjunctions are ordered after everything before them.
pub(super) fn order_steps(infos: &mut [StepInfo]) {
    let per_step: Vec<Option<(Vec<Literal>, Vec<Literal>)>> =
        infos.iter().map(step_literals).collect();
    let touches =
        |a: &[Literal], b: &[Literal]| a.iter().any(|x| b.iter().any(|y| x.atom == y.atom));
    for j in 0..infos.len() {
        if infos[j].skipped {
            continue;
        }
        let mut after = Vec::new();
        for i in 0..j {
            if infos[i].skipped {
                continue;
            }
            let dep = match (&per_step[i], &per_step[j]) {
                (Some((pi, ei)), Some((pj, ej))) => {
                    touches(ei, pj) || touches(ei, ej) || touches(ej, pi)
                }
                _ => true,
            };
            if dep {
                after.push(i);
            }
        }
        infos[j].after = after.into();
    }
}

/// Orders steps by the timed plan's schedule, as PlanSys2's executor does:
/// step j comes after an earlier step i when i ends before j starts
/// (`end_i <= start_j`, events less than a tenth of `epsilon` apart being
/// one happening, as the validator has them; among steps of one happening
/// the plan's order decides). Only the direct predecessors are kept: i is
/// left out when it also ends before a later predecessor k of j starts,
/// since k's wait covers it. A plan without times is a sequence: each step
/// after the one before. Skipped steps neither wait nor are waited for.
pub(super) fn schedule_steps(infos: &mut [StepInfo], epsilon: f64) {
    let live: Vec<usize> = (0..infos.len()).filter(|&i| !infos[i].skipped).collect();
    if !live.iter().all(|&i| infos[i].time.is_some()) {
        for (k, &j) in live.iter().enumerate() {
            infos[j].after = live[..k].last().copied().into_iter().collect();
        }
        return;
    }
    let tol = epsilon / 10.0;
    let start = |s: &StepInfo| s.time.unwrap_or(0.0);
    let end = |s: &StepInfo| start(s) + s.duration.unwrap_or(0.0);
    for (n, &j) in live.iter().enumerate() {
        let sj = start(&infos[j]);
        let before: Vec<usize> = live[..n]
            .iter()
            .copied()
            .filter(|&i| end(&infos[i]) <= sj + tol)
            .collect();
        // The latest start among the predecessors after each one.
        let mut latest_after = vec![f64::NEG_INFINITY; before.len()];
        for m in (0..before.len().saturating_sub(1)).rev() {
            latest_after[m] = latest_after[m + 1].max(start(&infos[before[m + 1]]));
        }
        let direct: Vec<usize> = before
            .iter()
            .zip(&latest_after)
            .filter(|&(&i, &later)| end(&infos[i]) > later + tol)
            .map(|(&i, _)| i)
            .collect();
        infos[j].after = direct.into();
    }
}

/// Independent chains of steps under one Parallel node; a step that waits
/// for a step of another chain starts with `WaitForStep`.
pub(super) fn parallel(step_nodes: &[Option<Node>], infos: &[StepInfo]) -> Node {
    // Transitive "must precede" closure over the `after` lists.
    let n = infos.len();
    let mut precedes: Vec<BTreeSet<usize>> = vec![BTreeSet::new(); n];
    for j in 0..n {
        let mut set = BTreeSet::new();
        for &i in &infos[j].after {
            set.insert(i);
            set.extend(precedes[i].iter().copied());
        }
        precedes[j] = set;
    }
    let mut chains: Vec<Vec<usize>> = Vec::new();
    for j in (0..n).filter(|&j| step_nodes[j].is_some()) {
        // Extend a chain whose last step must precede j anyway.
        match chains
            .iter_mut()
            .find(|c| precedes[j].contains(c.last().expect("non-empty")))
        {
            Some(c) => c.push(j),
            None => chains.push(vec![j]),
        }
    }
    let branches: Vec<Node> = chains
        .iter()
        .map(|chain| {
            let mut seq = Vec::new();
            for (k, &j) in chain.iter().enumerate() {
                let prev = if k > 0 { Some(chain[k - 1]) } else { None };
                // Direct predecessors outside this chain (others are implied).
                for &i in &infos[j].after {
                    let implied = prev.is_some_and(|p| p == i || precedes[p].contains(&i));
                    if !implied && !chain[..k].contains(&i) {
                        seq.push(Node::Leaf {
                            scripts: Default::default(),
                            leaf: LeafKind::Action,
                            id: "WaitForStep".into(),
                            name: Some(format!("wait for step {}", i + 1).into()),
                            ports: vec![Port {
                                name: "step".into(),
                                value: PortValue::Int(i as i64 + 1),
                            }],
                        });
                    }
                }
                seq.push(step_nodes[j].clone().expect("filtered"));
            }
            Node::Control {
                scripts: Default::default(),
                control: ControlKind::Sequence,
                name: None,
                children: seq,
            }
        })
        .collect();
    let count = branches.len().max(1) as u32;
    Node::Control {
        scripts: Default::default(),
        control: ControlKind::Parallel {
            success: count,
            failure: 1,
        },
        name: Some("plan".into()),
        children: branches,
    }
}
