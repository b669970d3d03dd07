//! btc's C++ knowledge base (`integrations/btcpp/src/kb.cpp`) against btc's
//! own (`btc_runtime::kb`, over `btc_pddl::state`): for every example and
//! every corpus domain (STRIPS, ADL with quantifiers and conditional
//! effects, derived predicates, numeric fluents), the world is written as a
//! `.kb` file; the plan is replayed and then a seeded random walk of ground
//! action instances goes on from where it ends, asking both the same
//! questions: whether each precondition holds, the state after applying
//! each applicable effect, whether the goal holds. Every
//! answer must be the same; the harness `btc_kb_eval` answers for C++.

use btc_pddl::logic::{ActionSchema, Binding, Effect, Formula, Name, Terms};
use btc_pddl::pipeline;
use btc_pddl::state::World;
use btc_runtime::kb::Kb;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::Command;

/// A small seeded generator (splitmix64): the walk is the same every run.
struct Rng(u64);

impl Rng {
    fn below(&mut self, n: usize) -> usize {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) % n as u64) as usize
    }
}

/// One question to both knowledge bases.
enum Ask {
    Holds(Formula),
    Apply(Effect),
    Snapshot,
    Goal,
}

fn conj(parts: &[Formula]) -> Formula {
    Formula::conjunction(parts.to_vec()).unwrap_or_else(Formula::truth)
}

/// The objects that fit each type (its own and its subtypes' objects).
fn objects_by_type(world: &World) -> HashMap<String, Vec<Name>> {
    let m = world.model();
    let parents: HashMap<&str, Vec<&str>> = m
        .types
        .iter()
        .map(|t| (&*t.name, t.parents.iter().map(|p| &**p).collect()))
        .collect();
    let mut out: HashMap<String, Vec<Name>> = HashMap::new();
    for o in &m.objects {
        let mut todo: Vec<&str> = o.types.iter().map(|t| &**t).collect();
        let mut seen = vec!["object"];
        while let Some(t) = todo.pop() {
            if !seen.contains(&t) {
                seen.push(t);
                todo.extend(parents.get(t).into_iter().flatten().copied());
            }
        }
        for t in seen {
            out.entry(t.to_owned()).or_default().push(o.name.clone());
        }
    }
    out
}

fn load(domain: &Path, problem: &Path) -> (World, String, Vec<ActionSchema>) {
    let du = pipeline::domain_unit_from(&std::fs::read_to_string(domain).unwrap(), 0);
    let d = du.domain.as_ref().unwrap();
    let pu = pipeline::problem_unit_from(
        &std::fs::read_to_string(problem).unwrap(),
        1,
        Some(d),
        &du.index,
    );
    let p = pu.problem.as_ref().unwrap();
    let kb = btc_emit::kb::emit(d, &du.index, p, &pu.index);
    let world = World::of_checked(d, &du.index, p, &pu.index).unwrap();
    let schemas = d.actions.iter().map(ActionSchema::from_ast).collect();
    (world, kb, schemas)
}

/// A plan's steps as action names and objects.
fn plan_steps(plan: &Path) -> Vec<(Name, Vec<Name>)> {
    let text = std::fs::read_to_string(plan).unwrap();
    let (plan, _) = btc_pddl::plan::parse::parse_plan(&text, 2);
    let n = |x: &btc_pddl::ast::Name| btc_pddl::logic::name(&x.name);
    plan.steps
        .iter()
        .map(|s| (n(&s.action()), s.args().map(|a| n(&a)).collect()))
        .collect()
}

/// The walk: the plan's steps, then `steps` random ground actions, each precondition asked and,
/// where btc says it holds, its effect applied; snapshots along the way.
/// Returns the questions and btc's answers, one line per answer as the
/// harness prints them.
fn walk(
    world: &World,
    schemas: &[ActionSchema],
    plan: &[(Name, Vec<Name>)],
    steps: usize,
    seed: u64,
) -> (Vec<Ask>, Vec<String>) {
    let fits = objects_by_type(world);
    let mut rng = Rng(seed);
    let mut kb = Kb::new(world);
    let mut asks = Vec::new();
    let mut answers = Vec::new();
    for i in 0..plan.len() + steps {
        let (a, objects) = match plan.get(i) {
            Some((action, args)) => (
                schemas.iter().find(|s| s.name == *action).unwrap(),
                args.clone(),
            ),
            None => {
                let a = &schemas[rng.below(schemas.len())];
                let mut objects = Vec::new();
                for p in &a.params {
                    let ty = p.types.first().map_or("object", |t| &**t);
                    let Some(pool) = fits.get(ty).filter(|v| !v.is_empty()) else {
                        break;
                    };
                    objects.push(pool[rng.below(pool.len())].clone());
                }
                (a, objects)
            }
        };
        if objects.len() < a.params.len() {
            continue;
        }
        let params = a.param_names();
        let b = Binding {
            params: &params,
            objects: &objects,
        };
        let pre: Vec<Formula> = a
            .pre_start
            .iter()
            .chain(&a.pre_over_all)
            .chain(&a.pre_end)
            .map(|f| f.ground(&b))
            .collect();
        let pre = conj(&pre);
        let id = kb.formula(&pre).unwrap();
        let holds = kb.holds(id);
        answers.push(holds.to_string());
        asks.push(Ask::Holds(pre));
        if holds {
            for e in a.eff_start.iter().chain(&a.eff_end) {
                let e = e.ground(&b);
                let id = kb.effect(&e).unwrap();
                kb.apply(id);
                answers.push("ok".into());
                asks.push(Ask::Apply(e));
            }
        }
        if i + 1 == plan.len() {
            // The plan reaches its goal.
            let (goal, why) = kb.goal();
            assert!(goal, "the plan does not reach the goal: {why:?}");
            answers.push("true".into());
            asks.push(Ask::Goal);
        }
        if i % 25 == 24 {
            answers.extend(kb.snapshot());
            answers.push("end".into());
            asks.push(Ask::Snapshot);
        }
    }
    answers.extend(kb.snapshot());
    answers.push("end".into());
    asks.push(Ask::Snapshot);
    answers.push(kb.goal().0.to_string());
    asks.push(Ask::Goal);
    (asks, answers)
}

fn commands(asks: &[Ask]) -> String {
    let mut out = String::new();
    for a in asks {
        let line = match a {
            Ask::Holds(f) => format!("holds {f}"),
            Ask::Apply(e) => format!("apply {e}"),
            Ask::Snapshot => "snapshot".into(),
            Ask::Goal => "goal".into(),
        };
        out.push_str(&line);
        out.push('\n');
    }
    out
}

/// Name, domain, problem, plan.
type Case = (String, PathBuf, PathBuf, PathBuf);

fn worlds() -> Vec<Case> {
    let repo = btc_testkit::repo();
    let mut out: Vec<Case> = [
        ("ariac", "plan.txt"),
        ("nist_kitting", "plan.plan"),
        ("p3_assembler", "plan.tplan"),
        ("two_robots", "plan.plan"),
    ]
    .iter()
    .map(|(ex, plan)| {
        let d = repo.join("examples").join(ex);
        (
            ex.to_string(),
            d.join("domain.pddl"),
            d.join("problem.pddl"),
            d.join(plan),
        )
    })
    .collect();
    if let Some(ipc) = btc_testkit::corpus() {
        let mut dirs: Vec<PathBuf> = std::fs::read_dir(&ipc)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| {
                ["domain.pddl", "p01.pddl", "p01.plan"]
                    .iter()
                    .all(|f| p.join(f).is_file())
            })
            .collect();
        dirs.sort();
        for d in dirs {
            let name = d.file_name().unwrap().to_string_lossy().into_owned();
            out.push((
                name,
                d.join("domain.pddl"),
                d.join("p01.pddl"),
                d.join("p01.plan"),
            ));
        }
    }
    out
}

#[test]
fn the_cpp_kb_answers_every_question_as_btcs_kb_does() {
    let Some(harness) = btc_testkit::btcpp_harness() else {
        return;
    };
    let exe = harness.join("btc_kb_eval");
    let work = btc_testkit::target_dir("btcpp/kb");
    std::fs::create_dir_all(&work).unwrap();
    let mut checked = 0;
    let mut applied = 0;
    for (name, domain, problem, plan) in worlds() {
        let (world, kb_text, schemas) = load(&domain, &problem);
        let kb_file = work.join(format!("{name}.kb"));
        std::fs::write(&kb_file, kb_text).unwrap();
        let (asks, want) = walk(
            &world,
            &schemas,
            &plan_steps(&plan),
            300,
            0x6b62 ^ name.len() as u64,
        );
        let cmd_file = work.join(format!("{name}.cmds"));
        std::fs::write(&cmd_file, commands(&asks)).unwrap();
        let out = Command::new(&exe)
            .arg(&kb_file)
            .arg(&cmd_file)
            .output()
            .unwrap();
        assert_eq!(
            out.status.code(),
            Some(0),
            "{name}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let got: Vec<String> = String::from_utf8_lossy(&out.stdout)
            .lines()
            .map(str::to_owned)
            .collect();
        for (k, (g, w)) in got.iter().zip(&want).enumerate() {
            assert_eq!(
                g,
                w,
                "{name}: answer {k} differs (C++ left, btc right); commands in {}",
                cmd_file.display()
            );
        }
        assert_eq!(got.len(), want.len(), "{name}: answer count");
        checked += asks.len();
        applied += asks.iter().filter(|a| matches!(a, Ask::Apply(_))).count();
    }
    // The walk is not idle: questions were asked and effects applied.
    assert!(
        checked >= 4 * 300 && applied > 20,
        "{checked} asked, {applied} applied"
    );
}
