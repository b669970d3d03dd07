//! The py_trees emitter end to end: every example under `examples/` (found
//! by reading the directory) compiles, and the generated module runs under
//! `python3` to SUCCESS with the goal reached; a tree full of hostile names
//! still imports and runs, and its strings come back unchanged.
//!
//! Needs `python3` with py_trees 2.2 or later (`pip install py_trees`).

use btc_emit::pytrees::{self, PyOptions};
use btc_ir::{ControlKind, DecoratorKind};
use btc_ir::{
    Label, LabelPart, LeafKind, Node, NodeModel, Port, PortDirection, PortModel, PortValue,
    StepInfo, TreeDef, TreeIr, IR_VERSION,
};
use btc_lang::db::{compile, CompileJob, Database};
use btc_pddl::logic::{name, Atom, Effect, Formula, InitFact, Signature, Term, TypedVar};
use btc_pddl::world::{ObjectDecl, TypeDecl, WorldModel};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// A fresh directory for one test's files.
fn work_dir(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("pytrees_run")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn run_python(dir: &Path, args: &[&str]) -> Output {
    Command::new("python3")
        .args(args)
        .current_dir(dir)
        .env("PYTHONDONTWRITEBYTECODE", "1")
        .output()
        .expect("python3 runs")
}

fn show(out: &Output) -> String {
    format!(
        "exit: {:?}\n--- stdout\n{}\n--- stderr\n{}",
        out.status.code(),
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    )
}

/// Runs `module.py` in `dir`; asserts exit 0, SUCCESS and the goal reached.
fn assert_runs_to_success(dir: &Path, what: &str) {
    let out = run_python(dir, &["module.py"]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{what}: module.py failed\n{}",
        show(&out)
    );
    assert!(
        stdout.contains("final status: SUCCESS"),
        "{what}: no SUCCESS\n{}",
        show(&out)
    );
    assert!(
        stdout.contains("goal reached: True"),
        "{what}: goal not reached\n{}",
        show(&out)
    );
}

/// Every folder under `examples/` with a `rules.btrules`, sorted.
fn example_dirs() -> Vec<PathBuf> {
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(repo_root().join("examples"))
        .expect("examples/")
        .map(|e| e.unwrap().path())
        .filter(|p| p.join("rules.btrules").is_file())
        .collect();
    dirs.sort();
    dirs
}

/// Compiles `rules` (a file name in `dir`) with the folder's `problem.pddl`
/// and first `plan.*` file (by name); every file of the folder is loaded.
fn compile_dir(dir: &Path, rules: &str) -> TreeIr {
    // Paths as from the repository root, e.g. `examples/ariac/rules.btrules`.
    let root = repo_root().canonicalize().unwrap();
    let dir = dir.canonicalize().unwrap();
    let prefix = dir
        .strip_prefix(&root)
        .unwrap_or(&dir)
        .to_string_lossy()
        .into_owned();
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_file())
        .collect();
    files.sort();
    let mut db = Database::new();
    let (mut rules_file, mut plan) = (None, None);
    for p in &files {
        let file = p.file_name().unwrap().to_string_lossy().into_owned();
        let f = db.set_file(
            &format!("{prefix}/{file}"),
            std::fs::read_to_string(p).unwrap(),
        );
        if file == rules {
            rules_file = Some(f);
        } else if file.starts_with("plan.") && plan.is_none() {
            plan = Some(f);
        }
    }
    let problem = db.file(&format!("{prefix}/problem.pddl"));
    let job = CompileJob::new(
        &db,
        rules_file.unwrap_or_else(|| panic!("{prefix}: no {rules}")),
        plan.unwrap_or_else(|| panic!("{prefix}: no plan.* file")),
        problem,
        None,
    );
    compile(&db, job)
        .clone()
        .unwrap_or_else(|e| panic!("{prefix}/{rules} does not compile: {e:#?}"))
        .as_ref()
        .clone()
}

fn compile_example(dir: &Path) -> TreeIr {
    compile_dir(dir, "rules.btrules")
}

/// Emits `ir`, checks the text, and runs it to SUCCESS in a fresh directory.
fn emit_and_run(ir: &TreeIr, name: &str) -> String {
    let text = pytrees::emit(ir, &PyOptions::default());
    assert_eq!(
        text,
        pytrees::emit(ir, &PyOptions::default()),
        "{name}: not deterministic"
    );
    assert!(text.is_ascii(), "{name}: output is not ASCII");
    let work = work_dir(name);
    std::fs::write(work.join("module.py"), &text).unwrap();
    assert_runs_to_success(&work, name);
    text
}

#[test]
fn examples_run_to_success() {
    if !btc_testkit::py_trees() {
        return;
    }
    let dirs = example_dirs();
    assert!(!dirs.is_empty(), "no examples found");
    for dir in dirs {
        let name = dir.file_name().unwrap().to_string_lossy().into_owned();
        emit_and_run(&compile_example(&dir), &name);
    }
}

/// Each `*.btrules` not starting with `_` in each folder under
/// `tests/fixtures/pytrees/` is a job over that folder's problem and plan.
#[test]
fn fixtures_run_to_success() {
    if !btc_testkit::py_trees() {
        return;
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/pytrees");
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(&root)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_dir())
        .collect();
    dirs.sort();
    let mut ran = Vec::new();
    for dir in dirs {
        let mut jobs: Vec<String> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.ends_with(".btrules") && !n.starts_with('_'))
            .collect();
        jobs.sort();
        for rules in jobs {
            let name = format!(
                "{}_{}",
                dir.file_name().unwrap().to_string_lossy(),
                rules.trim_end_matches(".btrules")
            );
            let text = emit_and_run(&compile_dir(&dir, &rules), &name);
            ran.push((name, text));
        }
    }
    // The workshop jobs between them use every construct.
    let all: String = ran.iter().map(|(_, t)| t.as_str()).collect();
    for construct in [
        "(\"P\", ",
        "(\"D\", \"timeout\", ",
        "(\"D\", \"retry\", ",
        "(\"D\", \"repeat\", ",
        "(\"D\", \"inverter\", ",
        "(\"D\", \"force_success\", ",
        "(\"D\", \"force_failure\", ",
        "(\"f\", ",
        "(\"F\", ",
        "(\"KbHolds\", KbHolds)",
        "(\"WaitForStep\", WaitForStep)",
    ] {
        assert!(all.contains(construct), "no job emits {construct}");
    }
    assert!(
        ran.len() >= 3,
        "fixtures missing: {:?}",
        ran.iter().map(|r| &r.0).collect::<Vec<_>>()
    );
}

/// Leaf classes from a user module: this one makes any class asked for
/// (PEP 562 module `__getattr__`), each succeeding on its first tick.
const USER_NODES: &str = r#"
import py_trees


class _Leaf(py_trees.behaviour.Behaviour):
    def __init__(self, name, /, **ports):
        super().__init__(name=name)
        self.ports = ports

    def update(self):
        return py_trees.common.Status.SUCCESS


def __getattr__(name):
    if name.startswith("__"):
        raise AttributeError(name)
    return type(name, (_Leaf,), {})
"#;

#[test]
fn examples_run_with_a_node_module() {
    if !btc_testkit::py_trees() {
        return;
    }
    for dir in example_dirs() {
        let name = dir.file_name().unwrap().to_string_lossy().into_owned();
        let ir = compile_example(&dir);
        let text = pytrees::emit(
            &ir,
            &PyOptions {
                node_module: Some("user_nodes"),
                ..PyOptions::default()
            },
        );
        assert!(text.contains("\nimport user_nodes\n"), "{name}");
        assert!(
            !text.contains("(Action):"),
            "{name}: simulated classes emitted"
        );
        let work = work_dir(&format!("{name}_node_module"));
        std::fs::write(work.join("module.py"), &text).unwrap();
        std::fs::write(work.join("user_nodes.py"), USER_NODES).unwrap();
        assert_runs_to_success(&work, &format!("{name} with user_nodes"));
    }
}

/// The P3 example with its own behaviours (`examples/p3_assembler/pytrees/`,
/// derived from the runtime's bases) and the runtime imported: the tree runs
/// to SUCCESS with the goal reached, and the behaviours did the work.
#[test]
fn the_p3_example_runs_with_its_own_behaviours() {
    if !btc_testkit::py_trees() {
        return;
    }
    let dir = repo_root().join("examples/p3_assembler");
    let ir = compile_example(&dir);
    let text = pytrees::emit(
        &ir,
        &PyOptions {
            runtime: pytrees::Runtime::Import,
            node_module: Some("p3_nodes"),
            source_paths: false,
        },
    );
    assert!(text.contains("\nfrom btc_runtime import (\n"));
    assert!(
        !text.contains("class KnowledgeBase"),
        "the runtime was pasted"
    );
    let work = work_dir("p3_own_behaviours");
    std::fs::write(work.join("module.py"), &text).unwrap();
    std::fs::write(work.join("btc_runtime.py"), pytrees::RUNTIME).unwrap();
    std::fs::copy(dir.join("pytrees/p3_nodes.py"), work.join("p3_nodes.py")).unwrap();
    assert_runs_to_success(&work, "p3 with p3_nodes");
    // Importing has no side effects; the behaviours log what they did.
    let check = "import module, p3_nodes\n\
                 assert p3_nodes.ROBOT.log == []\n\
                 import btc_runtime as rt\n\
                 kb = rt.KnowledgeBase(module.WORLD, module.PLAN)\n\
                 r = rt.run(module.create_behavior_tree(), kb, module.MAX_TICKS)\n\
                 assert r.success(), r.as_json()\n\
                 print(p3_nodes.ROBOT.log)\n";
    let out = run_python(&work, &["-c", check]);
    assert!(out.status.success(), "{}", show(&out));
    let log = String::from_utf8_lossy(&out.stdout);
    assert!(
        log.contains("'picked screwdriver'") && log.contains("'placed drill'"),
        "{log}"
    );
}

// ---------------------------------------------------------------------------
// Hostile names

/// Object names: PDDL tokens (no blanks, no parentheses) with everything else.
const OBJ_A: &str = "o\"1'''";
const OBJ_B: &str = "</b>\"\"\"\\ü";
const OBJ_C: &str = "日本#x\\";

fn text(s: &str) -> PortValue {
    PortValue::Text(s.into())
}

fn port(name: &str, value: PortValue) -> Port {
    Port {
        name: name.into(),
        value,
    }
}

fn leaf(kind: LeafKind, id: &str, name: Option<&str>, ports: Vec<Port>) -> Node {
    Node::Leaf {
        scripts: Default::default(),
        leaf: kind,
        id: id.into(),
        name: name.map(Into::into),
        ports,
    }
}

/// `(pred args...)` over objects (or `?variables`), whatever their names:
/// hostile names cannot be written as PDDL text, so values are built.
fn atom(pred: &str, args: &[&str]) -> Atom {
    Atom {
        pred: name(pred),
        args: args
            .iter()
            .map(|a| match a.strip_prefix('?') {
                Some(v) => Term::Var(name(v)),
                None => Term::Obj(name(a)),
            })
            .collect(),
    }
}

fn fact(pred: &str, args: &[&str]) -> Formula {
    Formula::Atom(atom(pred, args))
}

/// `?o - th"ing`
fn thing_var() -> Vec<TypedVar> {
    vec![TypedVar {
        name: name("o"),
        types: vec![name("th\"ing")],
    }]
}

fn model(id: &str, kind: LeafKind, ports: &[&str], formula: Option<Formula>) -> NodeModel {
    NodeModel {
        id: id.into(),
        kind,
        ports: ports
            .iter()
            .map(|p| PortModel {
                name: (*p).into(),
                direction: PortDirection::Input,
                ty: "string".into(),
            })
            .collect(),
        formula,
    }
}

fn step(index: usize, args: &[&str], eff_end: Effect) -> StepInfo {
    StepInfo {
        index,
        line: index as u32 + 1,
        time: None,
        duration: Some(1.0),
        skipped: false,
        after: Default::default(),
        logic: std::sync::Arc::new(btc_ir::StepLogic {
            action: "mo\"ve\n".into(),
            args: args.iter().map(|s| (*s).into()).collect(),
            rule: Some("rule \"\"\"x".into()),
            pre_start: Some(fact("at", &args[..2]).into()),
            pre_over_all: None,
            pre_end: None,
            // Step 2 starts by deleting the fact step 1 added.
            eff_start: (index == 1).then(|| Effect::Delete(atom("at", &args[..2])).into()),
            eff_end: Some(eff_end.into()),
        }),
    }
}

fn hostile_ir() -> TreeIr {
    use LeafKind::{Action, Condition};
    let evil_names = [
        "Move\"To",
        "Move'''To",
        "Move\"\"\"To\\\n</script>",
        "日本",
        "class",
        "print",
        "__name__",
        "KnowledgeBase",
        "n1",
    ];
    let mut nodes: Vec<NodeModel> = evil_names
        .iter()
        .map(|id| model(id, Action, &["target", "class", "größe", "a\"b"], None))
        .collect();
    nodes.push(model(
        "At?\"Where\n",
        Condition,
        &["who", "where"],
        Some(fact("at", &["?who", "?where"])),
    ));
    // A subtree called with hostile arguments, interpolated into a name.
    let tree = TreeDef {
        id: "rule \"'''\n".into(),
        params: vec!["x".into()],
        root: Node::Control {
            scripts: Default::default(),
            control: ControlKind::ReactiveSequence,
            name: Some(Label {
                parts: vec![
                    LabelPart::Text("go to ".into()),
                    LabelPart::Param("x".into()),
                    LabelPart::Text(" \"\"\" '''\n\\ </div>".into()),
                ]
                .into(),
            }),
            children: vec![
                leaf(
                    Condition,
                    "At?\"Where\n",
                    Some("is it \"there\"?\n'''"),
                    vec![port("who", text(OBJ_A)), port("where", text(OBJ_B))],
                ),
                leaf(
                    Action,
                    "Move\"To",
                    None,
                    vec![
                        port("target", PortValue::Param("x".into())),
                        port("class", text("\"\"\"")),
                        port("größe", PortValue::Float(1.5)),
                        port("a\"b", PortValue::Bool(true)),
                    ],
                ),
            ],
        },
    };
    let mut children = vec![Node::Step {
        step: 0,
        child: std::sync::Arc::new(Node::SubTree {
            scripts: Default::default(),
            id: tree.id.clone(),
            ports: vec![port("x", text(OBJ_C))],
        }),
    }];
    let mut others: Vec<Node> = evil_names[1..]
        .iter()
        .map(|id| {
            leaf(
                Action,
                id,
                Some(&format!("node {id} \"\"\"\n'''")),
                vec![port("target", PortValue::Int(-3))],
            )
        })
        .collect();
    others.push(leaf(
        Condition,
        "KbHolds",
        Some("kb \"holds\"\n"),
        vec![port(
            "formula",
            PortValue::Formula(std::sync::Arc::new(fact("at", &[OBJ_A, OBJ_B]))),
        )],
    ));
    children.push(Node::Step {
        step: 1,
        child: std::sync::Arc::new(Node::Decorator {
            scripts: Default::default(),
            decorator: DecoratorKind::Retry {
                times: btc_ir::Count::Fixed(2),
            },
            name: Some("retry \"'''\"".into()),
            child: Box::new(Node::Control {
                scripts: Default::default(),
                control: ControlKind::Parallel {
                    success: 2,
                    failure: 2,
                },
                name: None,
                children: others,
            }),
        }),
    });
    children.push(leaf(
        Action,
        "WaitForStep",
        Some("wait \"1\""),
        vec![port("step", PortValue::Int(1))],
    ));
    children.push(leaf(
        Action,
        "KbApply",
        None,
        vec![port(
            "effect",
            PortValue::Effect(std::sync::Arc::new(Effect::Add(atom("done", &[OBJ_B])))),
        )],
    ));
    TreeIr {
        version: IR_VERSION,
        domain: "dom\"\"\"ain\n'''\\.pddl".into(),
        problem: "prob\nimport os; os.system('false')\n#".into(),
        plan: String::new(),
        rules: String::new(),
        main_tree: "Main\"Tree".into(),
        root: Node::Control {
            scripts: Default::default(),
            control: ControlKind::Sequence,
            name: Some("root \"\"\" ''' \\ \n </root> ü 日本".into()),
            children,
        },
        trees: vec![tree],
        nodes,
        steps: vec![
            step(
                0,
                &[OBJ_A, OBJ_B, OBJ_C],
                Effect::Add(atom("at", &[OBJ_A, OBJ_C])),
            ),
            step(
                1,
                &[OBJ_A, OBJ_C, OBJ_B],
                Effect::And(vec![
                    Effect::Add(atom("at", &[OBJ_A, OBJ_B])),
                    Effect::Forall(thing_var(), Box::new(Effect::Add(atom("seen", &["?o"])))),
                ]),
            ),
        ],
        world: hostile_world(),
    }
}

fn hostile_world() -> WorldModel {
    let sig = |n: &str, arity: usize| Signature {
        name: name(n),
        params: (0..arity)
            .map(|i| TypedVar {
                name: name(&format!("x{i}")),
                types: Vec::new(),
            })
            .collect(),
    };
    let object = |n: &str, t: &str| ObjectDecl {
        name: name(n),
        types: vec![name(t)],
    };
    WorldModel {
        types: ["th\"ing", "pla'''ce"]
            .iter()
            .map(|t| TypeDecl {
                name: name(t),
                parents: Vec::new(),
            })
            .collect(),
        objects: vec![
            object(OBJ_A, "th\"ing"),
            object(OBJ_B, "th\"ing"),
            object(OBJ_C, "pla'''ce"),
        ],
        predicates: vec![sig("at", 2), sig("done", 1), sig("seen", 1)],
        functions: Vec::new(),
        derived: Vec::new(),
        init: vec![InitFact::Atom(atom("at", &[OBJ_A, OBJ_B]))],
        goal: Some(Formula::And(vec![
            fact("at", &[OBJ_A, OBJ_B]),
            fact("done", &[OBJ_B]),
            Formula::Forall(thing_var(), Box::new(fact("seen", &["?o"]))),
            Formula::Not(Box::new(fact("at", &[OBJ_A, OBJ_C]))),
        ])),
    }
}

/// Imports the module and prints what it read back, as JSON.
const DUMP: &str = r#"
import importlib.util, json, sys
spec = importlib.util.spec_from_file_location("module", "module.py")
m = importlib.util.module_from_spec(spec)
spec.loader.exec_module(m)
names = []
def walk(b):
    names.append(b.name)
    for c in b.children:
        walk(c)
walk(m.create_behavior_tree())
json.dump({
    "objects": [[o, m.WORLD.object_types[o][0]] for o in m.WORLD.objects],
    "facts": sorted(list(f) for f in m.WORLD.init),
    "classes": m.NODE_CLASS_NAMES,
    "names": names,
}, sys.stdout)
"#;

#[test]
fn hostile_names_stay_strings() {
    if !btc_testkit::py_trees() {
        return;
    }
    let ir = hostile_ir();
    for module in [None, Some("user_nodes")] {
        let text = pytrees::emit(
            &ir,
            &PyOptions {
                node_module: module,
                ..PyOptions::default()
            },
        );
        assert!(text.is_ascii());
        for line in text.lines() {
            // No user text leaks outside a literal: the only `import` lines
            // are the module's own.
            if line.trim_start().starts_with("import ") {
                assert!(
                    [
                        "import sys",
                        "import py_trees",
                        "import user_nodes",
                        "import argparse",
                        "import contextvars",
                        "import json",
                        "import time",
                        "import weakref",
                    ]
                    .contains(&line.trim()),
                    "unexpected import line: {line}"
                );
            }
        }
        let work = work_dir(if module.is_some() {
            "hostile_node_module"
        } else {
            "hostile"
        });
        std::fs::write(work.join("module.py"), &text).unwrap();
        std::fs::write(work.join("user_nodes.py"), USER_NODES).unwrap();
        let what = format!("hostile IR, node module {module:?}");
        assert_runs_to_success(&work, &what);

        let out = run_python(&work, &["-c", DUMP]);
        assert!(out.status.success(), "{what}: dump failed\n{}", show(&out));
        let got: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let objects: Vec<(String, String)> =
            serde_json::from_value(got["objects"].clone()).unwrap();
        let want: Vec<(String, String)> = ir
            .world
            .objects
            .iter()
            .map(|o| (o.name.to_string(), o.types[0].to_string()))
            .collect();
        assert_eq!(objects, want);
        let facts: Vec<Vec<String>> = serde_json::from_value(got["facts"].clone()).unwrap();
        assert_eq!(
            facts,
            vec![vec!["at".to_string(), OBJ_A.into(), OBJ_B.into()]]
        );
        let names: Vec<String> = serde_json::from_value(got["names"].clone()).unwrap();
        for expected in [
            "root \"\"\" ''' \\ \n </root> ü 日本",
            &format!("go to {OBJ_C} \"\"\" '''\n\\ </div>"),
            "is it \"there\"?\n'''",
            "Move\"To",
            "node Move\"\"\"To\\\n</script> \"\"\"\n'''",
            "node 日本 \"\"\"\n'''",
            "kb \"holds\"\n",
            "retry \"'''\"",
            &format!("step 1: (mo\"ve\n {OBJ_A} {OBJ_B} {OBJ_C})"),
        ] {
            assert!(
                names.iter().any(|n| n == expected),
                "{what}: name {expected:?} not in {names:#?}"
            );
        }
        let classes: std::collections::BTreeMap<String, String> =
            serde_json::from_value(got["classes"].clone()).unwrap();
        let mut unique: Vec<&String> = classes.values().collect();
        unique.sort();
        unique.dedup();
        assert_eq!(unique.len(), classes.len(), "class names not unique");
        assert_eq!(classes["Move\"To"], "Move_To");
        assert_eq!(classes["Move'''To"], "Move___To");
        assert_eq!(classes["print"], "print_2");
        assert_eq!(classes["__name__"], "Node__name__");
        assert_eq!(classes["KnowledgeBase"], "KnowledgeBase_2");
    }
}

/// A tree whose condition fails ends in FAILURE: exit 1, goal not reached.
#[test]
fn failure_exits_nonzero() {
    if !btc_testkit::py_trees() {
        return;
    }
    let mut ir = hostile_ir();
    ir.root = Node::Control {
        scripts: Default::default(),
        control: ControlKind::Sequence,
        name: None,
        children: vec![
            leaf(
                LeafKind::Action,
                "KbApply",
                None,
                vec![port(
                    "effect",
                    PortValue::Effect(std::sync::Arc::new(Effect::Delete(atom(
                        "at",
                        &[OBJ_A, OBJ_B],
                    )))),
                )],
            ),
            leaf(
                LeafKind::Condition,
                "At?\"Where\n",
                None,
                vec![port("who", text(OBJ_A)), port("where", text(OBJ_B))],
            ),
        ],
    };
    let work = work_dir("failure");
    std::fs::write(
        work.join("module.py"),
        pytrees::emit(&ir, &PyOptions::default()),
    )
    .unwrap();
    let out = run_python(&work, &["module.py"]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "{}", show(&out));
    assert!(stdout.contains("final status: FAILURE"), "{}", show(&out));
    assert!(stdout.contains("goal reached: False"), "{}", show(&out));
}

/// Every corpus plan of the domains with rules (`tests/corpus_rules/`),
/// compiled and run to SUCCESS under py_trees with the goal reached.
#[test]
fn corpus_plans_run_to_success() {
    let Some(domains) = btc_testkit::corpus_rules() else {
        return;
    };
    if !btc_testkit::py_trees() {
        return;
    }
    let mut ran = 0;
    for d in domains {
        let rules_text = std::fs::read_to_string(&d.rules).unwrap();
        let written = rules_text
            .lines()
            .find_map(|l| l.strip_prefix("domain \""))
            .unwrap()
            .trim_end_matches('"');
        let dir = d.rules.parent().unwrap();
        let name = &d.name;
        for plan in &d.plans {
            let mut db = Database::new();
            let key = |p: &Path| btc_lang::path::FilePath::new(p);
            db.set_file(
                &key(&dir.join(written)),
                std::fs::read_to_string(dir.join(written)).unwrap(),
            );
            let r = db.set_file(&key(&d.rules), rules_text.clone());
            let stem = plan.file_stem().unwrap().to_string_lossy().into_owned();
            let problem = d.corpus.join(format!("{stem}.pddl"));
            let p = db.set_file(&key(&problem), std::fs::read_to_string(&problem).unwrap());
            let l = db.set_file(&key(plan), std::fs::read_to_string(plan).unwrap());
            let job = CompileJob::new(&db, r, l, Some(p), None);
            let ir = compile(&db, job)
                .clone()
                .unwrap_or_else(|e| panic!("{}: {e:#?}", plan.display()));
            let label = format!(
                "corpus_{name}_{}",
                plan.file_name()
                    .unwrap()
                    .to_string_lossy()
                    .replace('.', "_")
            );
            emit_and_run(&ir, &label);
            ran += 1;
        }
    }
    assert!(ran >= 12, "only {ran} corpus plans");
}

/// The values a step computes (table lookups passed to a tree, strings that
/// interpolate them) reach the module's behaviours, and it runs to the goal
/// under real py_trees (`tests/fixtures/emit/values`).
#[test]
fn computed_values_reach_the_module() {
    if !btc_testkit::py_trees() {
        return;
    }
    let ir = compile_dir(
        &repo_root().join("tests/fixtures/emit/values"),
        "rules.btrules",
    );
    let text = emit_and_run(&ir, "values");
    // Each step's call passes its values to the rule's tree, which fills
    // them into ports and names when the module builds it.
    for expected in [
        r#""holding battery_red at 5 N""#,
        r#""holding pump_blue at 8 N""#,
        r#""tray_gripper""#,
        r#""pick {p} with {gripper}""#,
        r#""pick a {kind}""#,
    ] {
        assert!(text.contains(expected), "no {expected}\n{text}");
    }
}
