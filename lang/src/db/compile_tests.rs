use super::*;

/// Loads an example folder (rules, domain, problem, the first plan).
pub fn example_job(db: &mut Database, dir: &str) -> CompileJob {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut plan = None;
    let mut rules = None;
    for e in std::fs::read_dir(root.join(dir)).unwrap() {
        let p = e.unwrap().path();
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        if !p.is_file() {
            continue;
        }
        let f = db.set_file(
            &format!("{dir}/{name}"),
            std::fs::read_to_string(&p).unwrap(),
        );
        if name.starts_with("plan.") && plan.is_none() {
            plan = Some(f);
        }
        if name == "rules.btrules" {
            rules = Some(f);
        }
    }
    let problem = db.file(&format!("{dir}/problem.pddl"));
    CompileJob::new(db, rules.unwrap(), plan.unwrap(), problem, None)
}

#[test]
fn the_examples_compile() {
    for dir in ["examples/ariac", "examples/p3_assembler"] {
        let mut db = Database::new();
        let job = example_job(&mut db, dir);
        let ir = compile(&db, job)
            .as_ref()
            .unwrap_or_else(|e| panic!("{dir}: {e:#?}"));
        assert!(!ir.steps.is_empty());
        if std::env::var_os("BTC_PRINT_IR").is_some() {
            println!("{}", serde_json::to_string_pretty(ir).unwrap());
        }
    }
}

/// The compiled IR outlives the database without a copy: `btc
/// compile` frees the database (a long plan's text, parse and replay)
/// before it emits.
#[test]
fn the_ir_outlives_its_database() {
    let mut db = Database::new();
    let job = example_job(&mut db, "examples/p3_assembler");
    let ir = compile(&db, job).as_ref().expect("compiles").clone();
    let steps = ir.steps.len();
    drop(db);
    assert_eq!(Arc::strong_count(&ir), 1);
    assert_eq!(ir.steps.len(), steps);
}

/// A long plan repeats few ground actions: lowering grounds each once
/// and its steps share the result, so the IR's logic grows with the
/// distinct ground actions, not with the steps.
#[test]
fn repeated_ground_actions_share_their_logic() {
    use std::collections::{HashMap, HashSet};
    use std::sync::Arc;
    let mut db = Database::new();
    let job = example_job(&mut db, "examples/p3_assembler");
    job.plan(&db)
        .set_text(&mut db)
        .to(btc_testkit::long_p3_plan(600));
    let ir = compile(&db, job).as_ref().expect("the long plan compiles");
    assert_eq!(ir.steps.len(), 600);
    fn same<T>(a: &Option<Arc<T>>, b: &Option<Arc<T>>) -> bool {
        match (a, b) {
            (Some(a), Some(b)) => Arc::ptr_eq(a, b),
            (None, None) => true,
            _ => false,
        }
    }
    let mut first: HashMap<(&str, &[String]), &btc_ir::StepInfo> = HashMap::new();
    let mut effects = HashSet::new();
    for s in &ir.steps {
        let f = first
            .entry((&*s.logic.action, s.logic.args.as_ref()))
            .or_insert(s);
        assert!(
            same(&f.logic.pre_start, &s.logic.pre_start)
                && same(&f.logic.pre_over_all, &s.logic.pre_over_all)
        );
        assert!(
            same(&f.logic.pre_end, &s.logic.pre_end)
                && same(&f.logic.eff_start, &s.logic.eff_start)
        );
        assert!(same(&f.logic.eff_end, &s.logic.eff_end));
        // The step's whole logic is one value.
        assert!(Arc::ptr_eq(&f.logic, &s.logic));
        effects.extend(s.logic.eff_end.as_ref().map(Arc::as_ptr));
    }
    // Every P3 action but WAIT changes something at its end.
    assert_eq!(effects.len(), first.len() - 1);
    // And their nodes below the step boundary are one node each.
    let mut children = HashSet::new();
    ir.root.walk(&mut |n| {
        if let btc_ir::Node::Step { child, .. } = n {
            children.insert(Arc::as_ptr(child));
        }
    });
    let skipped: HashSet<_> = ir
        .steps
        .iter()
        .filter(|s| s.skipped)
        .map(|s| (&*s.logic.action, s.logic.args.as_ref()))
        .collect();
    assert_eq!(children.len(), first.len() - skipped.len());
    assert!(first.len() < 20, "{} distinct ground actions", first.len());
}

/// A plan given as a value compiles to the tree its text compiles to,
/// and what is wrong with it is reported in its text, as for a file.
#[test]
fn a_plan_value_compiles_as_its_text_does() {
    let mut db = Database::new();
    let job = example_job(&mut db, "examples/ariac");
    let from_text = compile(&db, job).as_ref().expect("compiles").clone();
    let steps = &typed_plan(&db, job).plan.steps;
    let mut w = btc_pddl::plan::PlanWriter::new();
    for s in steps {
        w.step(&s.call.action, &s.call.args, s.time, s.duration);
    }
    let path = job.plan(&db).path(&db).clone();
    let f = db.set_plan(&path, w.finish());
    assert_eq!(f, job.plan(&db));
    let from_value = compile(&db, job).as_ref().expect("compiles").clone();
    // The same steps (the file has a header, so they sit on other lines).
    let logic = |ir: &btc_ir::TreeIr| ir.steps.iter().map(|s| s.logic.clone()).collect::<Vec<_>>();
    assert_eq!(logic(&from_text), logic(&from_value));
    assert_eq!(from_text.root, from_value.root);
    // An action the domain does not have, reported where its text has it.
    let mut w = btc_pddl::plan::PlanWriter::new();
    w.step(
        "move",
        &["floor_robot", "curr_position", "bin1"],
        None,
        None,
    )
    .step("fly", &["floor_robot"], None, None);
    db.set_plan(&path, w.finish());
    let errors = compile(&db, job).as_ref().expect_err("refused").clone();
    let e = &errors[0];
    let text = job.plan(&db).text(&db);
    assert_eq!(
        &text[e.span.start as usize..e.span.end as usize],
        "fly",
        "{e:?}"
    );
    // Text set again replaces the value.
    db.set_file(&path, "(fly floor_robot)\n".to_owned());
    assert!(job.plan(&db).value(&db).is_none());
}

/// A problem given as a value compiles as its text does, and what is
/// wrong with it is reported in its text, as for a file.
#[test]
fn a_problem_value_compiles_as_its_text_does() {
    use btc_pddl::ast::{InitFact, TypeSpec};
    let mut db = Database::new();
    let job = example_job(&mut db, "examples/ariac");
    let from_text = compile(&db, job).as_ref().expect("compiles").clone();
    let (pf, df) = (
        job_problem(&db, job).unwrap(),
        job_domain(&db, job).unwrap(),
    );
    let read = checked_problem(&db, ProblemOf::new(&db, pf, df))
        .problem
        .clone()
        .expect("parses");
    let written = |extra: Option<(&str, &[&str])>| {
        let mut w = btc_pddl::written_problem::ProblemWriter::new(
            "a test's",
            &read.name.name,
            &read.domain.name,
        );
        for o in &read.objects {
            let TypeSpec::Named { name } = &o.ty else {
                panic!("the example's objects have one type each")
            };
            w.objects(&name.name, &[&o.name.name]);
        }
        for f in &read.init {
            let InitFact::Atom { atom } = f else {
                panic!("the example's facts are atoms")
            };
            let args: Vec<String> = atom.args.iter().map(|a| a.to_string()).collect();
            w.fact(&atom.pred.name, &args);
        }
        if let Some((pred, args)) = extra {
            w.fact(pred, args);
        }
        w.finish()
    };
    let (path, original) = (pf.path(&db).clone(), pf.text(&db).clone());
    assert_eq!(db.set_problem(&path, written(None)), pf);
    let from_value = compile(&db, job).as_ref().expect("compiles").clone();
    let logic = |ir: &btc_ir::TreeIr| ir.steps.iter().map(|s| s.logic.clone()).collect::<Vec<_>>();
    assert_eq!(logic(&from_text), logic(&from_value));
    assert_eq!(from_text.root, from_value.root);
    // A fact about an object the problem does not have, reported where
    // its text has it.
    db.set_problem(&path, written(Some(("is_enabled", &["nobody"]))));
    let errors = compile(&db, job).as_ref().expect_err("refused").clone();
    let e = &errors[0];
    let text = pf.text(&db);
    assert_eq!(
        &text[e.span.start as usize..e.span.end as usize],
        "nobody",
        "{e:?}"
    );
    // Text set again replaces the value.
    db.set_file(&path, original);
    assert!(pf.value(&db).is_none());
}
