//! Checks across the file once it is read: references between orders and
//! challenges, the ARIAC 2023 rules for when things may happen, and
//! whether the cell holds the parts the orders ask for.

use super::*;

/// Checks across the file: references between orders and challenges, and
/// the ARIAC 2023 rules for when things may happen.
pub(super) fn check_rules(t: &Trial, r: &mut Reader) {
    let ids: Vec<&str> = t.orders.iter().map(|o| o.id.as_str()).collect();
    let refer = |r: &mut Reader, id: &str, at: Range, what: &str| {
        if !ids.contains(&id) {
            let hint = did_you_mean(id, ids.iter().copied())
                .unwrap_or_else(|| format!("the trial's orders are {}", quote_all(&ids)));
            r.error(
                codes::TRIAL_UNKNOWN_ORDER,
                at,
                format!("{what} names order `{id}`, which this trial does not have"),
            )
            .hint = Some(hint);
        }
    };
    for o in &t.orders {
        if let Condition::Submission(id) = &o.announcement {
            refer(
                r,
                id,
                o.range,
                &format!("the announcement of order `{}`", o.id),
            );
            if *id == o.id {
                r.error(
                    codes::TRIAL_RULE,
                    o.range,
                    format!("order `{}` is announced when it is itself submitted", o.id),
                );
            }
            if o.priority {
                r.warn(
                    codes::TRIAL_RULE,
                    o.range,
                    format!(
                        "high-priority order `{}` is announced on a submission; ARIAC 2023 announces high-priority orders on time or part placement only",
                        o.id
                    ),
                );
            }
        }
    }
    let mut humans = 0;
    for c in &t.challenges {
        let cond = match &c.kind {
            ChallengeKind::FaultyPart { order_id, .. } => {
                refer(r, order_id, c.range, "a `faulty_part` challenge");
                if let Some(o) = t.orders.iter().find(|o| o.id == *order_id) {
                    if o.task.order_type() == OrderType::Assembly {
                        r.warn(
                            codes::TRIAL_RULE,
                            c.range,
                            format!(
                                "order `{order_id}` is an assembly order: its parts start on AGVs and are never placed in a kit, so this faulty-part challenge cannot happen"
                            ),
                        );
                    }
                }
                None
            }
            ChallengeKind::RobotMalfunction { condition, .. }
            | ChallengeKind::SensorBlackout { condition, .. } => Some(condition),
            ChallengeKind::Human { condition, .. } => {
                humans += 1;
                if humans == 2 {
                    r.error(
                        codes::TRIAL_RULE,
                        c.range,
                        "a second `human` challenge: ARIAC 2023 has one human in a trial",
                    );
                }
                Some(condition)
            }
            ChallengeKind::DroppedPart { .. } => None,
        };
        if let Some(Condition::Submission(id)) = cond {
            refer(r, id, c.range, &format!("a `{}` challenge", c.kind.name()));
        }
    }
}

/// Orders the trial's parts cannot fulfil: ARIAC's insufficient-parts
/// challenge, which has no field of its own. Reported, not refused.
pub(super) fn check_supply(t: &Trial, r: &mut Reader) {
    let mut have: BTreeMap<PartKind, usize> = BTreeMap::new();
    for b in &t.bins {
        *have.entry(b.kind).or_default() += b.slots.len();
    }
    if let Some(c) = t.conveyor.as_ref().filter(|c| c.active) {
        for l in &c.lots {
            *have.entry(l.kind).or_default() += l.number as usize;
        }
    }
    for o in &t.orders {
        let Task::Assembly { agvs, products, .. } = &o.task else {
            continue;
        };
        for p in products {
            let on = t
                .agvs
                .iter()
                .filter(|a| agvs.contains(&a.agv))
                .flat_map(|a| &a.parts)
                .any(|x| x.kind == p.kind);
            if !on {
                r.warn(
                    codes::TRIAL_SUPPLY,
                    p.range,
                    format!(
                        "order `{}` assembles a {} that no AGV it names ({}) carries; the insert will miss it (insufficient parts)",
                        o.id,
                        p.kind,
                        agvs.iter().map(|a| format!("agv{a}")).collect::<Vec<_>>().join(", ")
                    ),
                );
            }
        }
    }
    let mut need: BTreeMap<PartKind, (usize, Vec<&str>, Range)> = BTreeMap::new();
    for o in &t.orders {
        if o.task.order_type() == OrderType::Assembly {
            continue;
        }
        for k in o.task.kinds() {
            let e = need.entry(k).or_insert((0, Vec::new(), o.range));
            e.0 += 1;
            if !e.1.contains(&o.id.as_str()) {
                e.1.push(&o.id);
            }
        }
    }
    for (k, (n, orders, at)) in need {
        let h = have.get(&k).copied().unwrap_or(0);
        if h < n {
            r.warn(
                codes::TRIAL_SUPPLY,
                at,
                format!(
                    "the trial's orders ({}) need {n} {k}{} and its bins and conveyor hold {h}: {} will be submitted incomplete (insufficient parts)",
                    quote_all(&orders),
                    if n == 1 { "" } else { "s" },
                    if orders.len() == 1 { "the order" } else { "orders" }
                ),
            );
        }
    }
}
