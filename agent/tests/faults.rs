//! Each ARIAC fault kind has a scenario under `examples/ariac/faults/`,
//! run here on the ARIAC example with its expected outcome.

use btc_agent::faults::{FaultKind, FaultsOnEngine, Scenario};
use btc_ir::TreeIr;
use btc_lang::db::{self, CompileJob, Database, JobWorld};
use btc_pddl::state::World;
use btc_runtime::observers::JsonlTrace;
use btc_runtime::{Engine, Kb, Options, Status, TreeDoc, Value};
use btc_testkit::repo as root;

/// The ARIAC example compiled: its rules, domain, problem and plan.
struct Ariac {
    db: Database,
    job: CompileJob,
    ir: TreeIr,
}

fn ariac() -> Ariac {
    let dir = root().join("examples/ariac");
    let mut db = Database::new();
    let mut load = |name: &str| {
        let p = dir.join(name);
        db.set_file(&p, std::fs::read_to_string(&p).unwrap())
    };
    let (rules, domain) = (load("rules.btrules"), load("domain.pddl"));
    let (problem, plan) = (load("problem.pddl"), load("plan.txt"));
    let job = CompileJob::new(&db, rules, plan, Some(problem), Some(domain));
    let ir = db::compile(&db, job).as_ref().unwrap().as_ref().clone();
    Ariac { db, job, ir }
}

impl Ariac {
    fn world(&self) -> World {
        JobWorld::of(&self.db, self.job).unwrap().world().unwrap()
    }

    /// An engine over `w` for the example's tree, with a JSON Lines trace.
    fn engine<'w>(&self, w: &'w World) -> Engine<'w> {
        let doc = TreeDoc::from_ir(&self.ir);
        let mut e = Engine::build(&doc, Some(Kb::new(w)), Options::default()).unwrap();
        e.observe(JsonlTrace::default());
        e
    }
}

fn jsonl(e: &Engine<'_>) -> String {
    e.observer::<JsonlTrace>().unwrap().text().to_owned()
}

fn fixture(name: &str) -> String {
    let p = root().join("agent/tests/fixtures").join(name);
    std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

enum Expect {
    /// The tree recovers: success, the goal holds, later than the plain run
    /// (or with a record of the fault the tree absorbed).
    Recovered { slower: bool, record: bool },
    /// The run fails; the last record names `cause` and the fault.
    Failed {
        node: &'static str,
        cause: &'static str,
    },
}

fn expected(kind: FaultKind) -> Expect {
    use Expect::*;
    match kind {
        FaultKind::RobotMalfunction => Failed {
            node: "RobotNormal",
            cause: "`(is_enabled floor_robot)` is false",
        },
        FaultKind::FaultyGripper => Recovered {
            slower: false,
            record: true,
        },
        FaultKind::FaultyPart | FaultKind::FlippedPart | FaultKind::InsufficientParts => Failed {
            node: "Grasp",
            cause: "`(on battery_red bin1)` is false",
        },
        FaultKind::SensorBlackout | FaultKind::HighPriorityOrder | FaultKind::HumanTooClose => {
            Recovered {
                slower: true,
                record: false,
            }
        }
    }
}

fn scenario(kind: FaultKind) -> Scenario {
    let path = root()
        .join("examples/ariac/faults")
        .join(format!("{}.toml", kind.name()));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    Scenario::parse(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

#[test]
fn every_fault_kind_has_a_scenario_with_its_outcome() {
    let ex = ariac();
    let w = ex.world();
    let mut plain = ex.engine(&w);
    let s = plain.run(10_000, |_| {});
    assert_eq!(s, Status::Success);
    let baseline = plain.tick;

    for kind in FaultKind::ALL {
        let sc = scenario(kind);
        assert_eq!(sc.faults.len(), 1, "{kind:?}");
        assert_eq!(sc.faults[0].kind, kind);
        let mut e = ex.engine(&w);
        e.add_faults(&sc).unwrap();
        let s = e.run(10_000, |_| {});
        let sum = e.summary(s);
        let trace = jsonl(&e);
        assert!(trace.contains("\"event\":\"fault_triggered\""), "{kind:?}");
        assert!(
            sum.faults[0].met_at.is_some(),
            "{kind:?}: the fault was not met"
        );
        match expected(kind) {
            Expect::Recovered { slower, record } => {
                assert!(sum.success(), "{kind:?}: {sum:#?}");
                assert_eq!(sum.faults[0].ended, "recovered", "{kind:?}");
                if slower {
                    assert!(sum.ticks > baseline, "{kind:?}: {} ticks", sum.ticks);
                }
                assert_eq!(
                    !sum.records.is_empty(),
                    record,
                    "{kind:?}: {:#?}",
                    sum.records
                );
                for r in &sum.records {
                    assert!(
                        r.faults.contains(&kind.name().to_owned()),
                        "{kind:?}: {r:#?}"
                    );
                }
            }
            Expect::Failed { node, cause } => {
                assert_eq!(s, Status::Failure, "{kind:?}");
                assert!(!sum.success());
                let r = sum.records.last().expect("a fault record");
                assert_eq!(r.node_id, node, "{kind:?}: {r:#?}");
                assert!(r.reason.contains(cause), "{kind:?}: {}", r.reason);
                assert_eq!(r.faults, vec![kind.name().to_owned()], "{kind:?}");
                assert_eq!(r.step, Some(2), "{kind:?}");
                assert!(!r.kb.is_empty());
                assert!(sum.faults[0].ended.starts_with("not recovered"), "{kind:?}");
                // Written to the blackboard and the trace too.
                assert_eq!(
                    e.blackboard("MainTree/fault_reason"),
                    Some(&Value::Text(r.reason.as_str().into()))
                );
                assert_eq!(e.blackboard("MainTree/fault_step"), Some(&Value::Int(2)));
                assert!(trace.contains("\"event\":\"fault_record\""), "{kind:?}");
            }
        }
    }
}

#[test]
fn a_malfunction_is_repaired_after_its_duration() {
    let ex = ariac();
    let w = ex.world();
    let mut e = ex.engine(&w);
    e.add_faults(&scenario(FaultKind::RobotMalfunction))
        .unwrap();
    e.run(10_000, |_| {});
    // The run failed at tick 2; ticking on past the duration brings the
    // retracted fact back.
    let kb = e.kb.as_mut().unwrap();
    let key = kb
        .atom_key(&btc_pddl::logic::Atom::ground(
            "is_enabled",
            &["floor_robot"],
        ))
        .unwrap();
    assert!(!kb.state.facts.contains(&key));
    for _ in 0..6 {
        e.tick_once();
    }
    let kb = e.kb.as_ref().unwrap();
    assert!(kb.state.facts.contains(&key));
    assert!(jsonl(&e).contains("\"event\":\"fault_ended\""));
}

#[test]
fn a_blackout_that_fails_conditions_fails_the_monitor() {
    let ex = ariac();
    let w = ex.world();
    let mut e = ex.engine(&w);
    let sc = Scenario::parse(&fixture("faults/blackout_failure.toml")).unwrap();
    e.add_faults(&sc).unwrap();
    let s = e.run(10_000, |_| {});
    assert_eq!(s, Status::Failure);
    let r = e.records.last().unwrap();
    assert_eq!(r.node_id, "RobotNormal");
    assert!(r.reason.contains("sensor blackout"), "{}", r.reason);
}

#[test]
fn bad_scenarios_are_refused_with_a_code() {
    for (file, needle) in [
        ("faults/bad_kind.toml", "is not a fault kind"),
        ("faults/two_triggers.toml", "exactly one trigger"),
        ("faults/not_toml.toml", "not valid"),
        ("faults/missing_robot.toml", "needs `robot`"),
    ] {
        let e = Scenario::parse(&fixture(file)).unwrap_err();
        assert_eq!(e.code.id, "X006", "{file}");
        assert!(e.message.contains(needle), "{file}: {}", e.message);
    }
    // Facts are checked against the problem.
    let ex = ariac();
    let w = ex.world();
    let mut eng = ex.engine(&w);
    let sc = Scenario::parse(&fixture("faults/unknown_fact.toml")).unwrap();
    let err = eng.add_faults(&sc).unwrap_err();
    assert_eq!(err.code.id, "X006");
    assert!(err.message.contains("is_broken"), "{}", err.message);
}
