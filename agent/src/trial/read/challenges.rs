//! When things happen (conditions) and the challenges: faulty and dropped
//! parts, robot malfunctions, sensor blackouts, humans.

use super::*;

impl Reader {
    /// A condition: in `f` directly (challenges) or under `announcement`.
    pub(super) fn condition(&mut self, f: &mut Fields<'_>, what: &str) -> Option<Condition> {
        let given: Vec<&str> = CONDITION_FIELDS
            .iter()
            .copied()
            .filter(|k| f.has(k))
            .collect();
        if given.len() > 1 {
            let n = f.get(given[1]).expect("present");
            self.error(
                codes::TRIAL_VALUE,
                n.range,
                format!(
                    "{what} has more than one condition ({}); give one",
                    quote_all(&given)
                ),
            );
        }
        let Some(first) = given.first() else {
            self.missing(f.node, format!("{what} has no condition: give `time_condition`, `part_place_condition` or `submission_condition`"));
            return None;
        };
        let n = f.get(first).expect("present");
        match *first {
            "time_condition" => self.seconds(n, "`time_condition`").map(Condition::Time),
            "part_place_condition" => {
                let mut pf = self.fields(n, "`part_place_condition`")?;
                let kind = self.kind(&mut pf);
                let agv = self
                    .need(&mut pf, "agv")
                    .and_then(|n| self.int(n, "an AGV number", 1, 4));
                self.done(pf, &["agv", "type", "color"]);
                Some(Condition::PartPlace {
                    agv: agv? as u8,
                    kind: kind?,
                })
            }
            _ => {
                let mut sf = self.fields(n, "`submission_condition`")?;
                let id = self
                    .need(&mut sf, "order_id")
                    .and_then(|n| self.text(n, "an order id"))
                    .map(str::to_owned);
                self.done(sf, &["order_id"]);
                id.map(Condition::Submission)
            }
        }
    }

    pub(super) fn robot(&mut self, node: &Node) -> Option<Robot> {
        let n = self.choice(node, "a robot", &["floor_robot", "ceiling_robot"])?;
        Robot::ALL.into_iter().find(|r| r.name() == n)
    }

    pub(super) fn challenges(&mut self, node: &Node) -> Vec<Challenge> {
        let Some(list) = self.list(node, "`challenges`") else {
            return Vec::new();
        };
        let mut out = Vec::new();
        let names = [
            "faulty_part",
            "dropped_part",
            "robot_malfunction",
            "sensor_blackout",
            "human",
        ];
        for item in list {
            let Some(items) = item.as_map() else {
                self.wrong(
                    item,
                    "a challenge",
                    "a mapping with one challenge, e.g. `- robot_malfunction: {...}`",
                );
                continue;
            };
            for (k, v) in items {
                let name = k.as_text().unwrap_or("");
                let Some(kind) = names.iter().find(|n| **n == name) else {
                    let hint = did_you_mean(name, names.iter().copied()).unwrap_or_else(|| {
                        format!(
                            "the challenges a trial file sets are {}; high-priority orders are orders with `priority: true` and insufficient parts are a trial without enough parts",
                            quote_all(&names)
                        )
                    });
                    self.error(
                        codes::TRIAL_VALUE,
                        k.range,
                        format!("`{name}` is not an ARIAC 2023 challenge"),
                    )
                    .hint = Some(hint);
                    continue;
                };
                let what = format!("the `{kind}` challenge");
                let Some(f) = self.fields(v, &what) else {
                    continue;
                };
                let c = match *kind {
                    "faulty_part" => self.faulty_part(f),
                    "dropped_part" => self.dropped_part(f),
                    "robot_malfunction" => self.robot_malfunction(f, &what),
                    "sensor_blackout" => self.sensor_blackout(f, &what),
                    _ => self.human(f, &what),
                };
                if let Some(kind) = c {
                    out.push(Challenge {
                        kind,
                        range: item.range,
                    });
                }
            }
        }
        out
    }

    pub(super) fn faulty_part(&mut self, mut f: Fields<'_>) -> Option<ChallengeKind> {
        let id = self
            .need(&mut f, "order_id")
            .and_then(|n| self.text(n, "an order id"))
            .map(str::to_owned);
        let mut q = [false; 4];
        for (k, slot) in q.iter_mut().enumerate() {
            if let Some(n) = f.get(&format!("quadrant{}", k + 1)) {
                *slot = self.boolean(n, "a quadrant flag").unwrap_or(false);
            }
        }
        self.done(
            f,
            &[
                "order_id",
                "quadrant1",
                "quadrant2",
                "quadrant3",
                "quadrant4",
            ],
        );
        Some(ChallengeKind::FaultyPart {
            order_id: id?,
            quadrants: q,
        })
    }

    pub(super) fn dropped_part(&mut self, mut f: Fields<'_>) -> Option<ChallengeKind> {
        let robot = self.need(&mut f, "robot").and_then(|n| self.robot(n));
        let kind = self.kind(&mut f);
        let after = self
            .need(&mut f, "drop_after")
            .and_then(|n| self.int(n, "`drop_after`", 0, 1000));
        let delay = self
            .need(&mut f, "delay")
            .and_then(|n| self.seconds(n, "`delay`"));
        self.done(f, &["robot", "type", "color", "drop_after", "delay"]);
        Some(ChallengeKind::DroppedPart {
            robot: robot?,
            kind: kind?,
            drop_after: after? as u32,
            delay: delay?,
        })
    }

    pub(super) fn robot_malfunction(
        &mut self,
        mut f: Fields<'_>,
        what: &str,
    ) -> Option<ChallengeKind> {
        let duration = self.duration(&mut f);
        let robots = self.distinct(&mut f, "robots_to_disable", |r, n| r.robot(n));
        let condition = self.condition(&mut f, what);
        self.done_conditional(f, &["duration", "robots_to_disable"]);
        Some(ChallengeKind::RobotMalfunction {
            duration: duration?,
            robots,
            condition: condition?,
        })
    }

    pub(super) fn sensor_blackout(
        &mut self,
        mut f: Fields<'_>,
        what: &str,
    ) -> Option<ChallengeKind> {
        let duration = self.duration(&mut f);
        let sensors = self.distinct(&mut f, "sensors_to_disable", |r, n| {
            r.choice(n, "a sensor type", &SENSOR_TYPES)
                .map(str::to_owned)
        });
        let condition = self.condition(&mut f, what);
        self.done_conditional(f, &["duration", "sensors_to_disable"]);
        Some(ChallengeKind::SensorBlackout {
            duration: duration?,
            sensors,
            condition: condition?,
        })
    }

    pub(super) fn human(&mut self, mut f: Fields<'_>, what: &str) -> Option<ChallengeKind> {
        let behavior = self
            .need(&mut f, "behavior")
            .and_then(|n| {
                self.choice(
                    n,
                    "a human behavior",
                    &["indifferent", "antagonistic", "helpful"],
                )
            })
            .map(|b| match b {
                "antagonistic" => Behavior::Antagonistic,
                "helpful" => Behavior::Helpful,
                _ => Behavior::Indifferent,
            });
        let condition = self.condition(&mut f, what);
        self.done_conditional(f, &["behavior"]);
        Some(ChallengeKind::Human {
            behavior: behavior?,
            condition: condition?,
        })
    }

    pub(super) fn duration(&mut self, f: &mut Fields<'_>) -> Option<f64> {
        self.need(f, "duration")
            .and_then(|n| self.seconds(n, "`duration`"))
    }

    /// The distinct values of the list under `key`, in order; a repeated
    /// value counts once (the competition's reader does the same).
    pub(super) fn distinct<T: PartialEq>(
        &mut self,
        f: &mut Fields<'_>,
        key: &str,
        mut each: impl FnMut(&mut Self, &Node) -> Option<T>,
    ) -> Vec<T> {
        let mut out = Vec::new();
        let what = format!("`{key}`");
        if let Some(list) = self.need(f, key).and_then(|n| self.list(n, &what)) {
            for n in list {
                if let Some(v) = each(self, n) {
                    if !out.contains(&v) {
                        out.push(v);
                    }
                }
            }
        }
        out
    }

    /// `done` for a challenge that starts on a condition: `known` plus the
    /// three condition fields.
    pub(super) fn done_conditional(&mut self, f: Fields<'_>, known: &[&str]) {
        let mut all = known.to_vec();
        all.extend(CONDITION_FIELDS);
        self.done(f, &all);
    }
}
