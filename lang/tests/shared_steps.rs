//! Steps that repeat a ground action share their logic and their node in
//! the IR, and the emitters write a shared value once and copy it. The
//! output must not depend on that: each emitter writes the same text for
//! the compiled IR as for a copy of it in which nothing is shared (the IR
//! read back from its JSON, where every step has its own values). Nor
//! on streaming: each emitter streams the bytes it returns whole, and its
//! parts (made on two threads by `btc compile -o`) follow each other into
//! the same bytes.

use btc_emit::{emit, emit_part_handing_over, emit_to, parts, pytrees::Runtime, Format, Options};
use btc_ir::TreeIr;
use btc_lang::db::{compile, CompileJob, Database};
use std::path::Path;

fn read(p: &str) -> String {
    let root = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/.."));
    std::fs::read_to_string(root.join(p)).unwrap_or_else(|e| panic!("{p}: {e}"))
}

/// Compiles `rules` (a path) with the plan text `plan` for `problem`.
fn compiled(dir: &str, rules: &str, problem: &str, plan: String) -> TreeIr {
    let mut db = Database::new();
    db.set_file(
        &format!("{dir}/domain.pddl"),
        read(&format!("{dir}/domain.pddl")),
    );
    for f in
        std::fs::read_dir(Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/..")).join(dir)).unwrap()
    {
        let name = f.unwrap().file_name().to_string_lossy().into_owned();
        if name.ends_with(".btrules") && name != rules {
            db.set_file(&format!("{dir}/{name}"), read(&format!("{dir}/{name}")));
        }
    }
    let r = db.set_file(&format!("{dir}/{rules}"), read(&format!("{dir}/{rules}")));
    let p = db.set_file(
        &format!("{dir}/{problem}"),
        read(&format!("{dir}/{problem}")),
    );
    let l = db.set_file(&format!("{dir}/plan.txt"), plan);
    let job = CompileJob::new(&db, r, l, Some(p), None);
    compile(&db, job)
        .clone()
        .unwrap_or_else(|e| panic!("{dir}/{rules}: {e:#?}"))
        .as_ref()
        .clone()
}

/// The IR with nothing shared: every step's logic and node its own.
fn unshared(ir: &TreeIr) -> TreeIr {
    serde_json::from_str(&serde_json::to_string(ir).unwrap()).unwrap()
}

fn same_output(what: &str, ir: &TreeIr) {
    let copy = unshared(ir);
    assert_eq!(&copy, ir, "{what}: the JSON copy is the same IR");
    for &(format, _) in Format::ALL {
        for inline in [false, true] {
            let options = Options {
                inline,
                runtime: Runtime::Import,
                ..Options::default()
            };
            let whole = emit(ir, format, &options);
            assert!(
                whole == emit(&copy, format, &options),
                "{what}: {} (inline: {inline}) writes a shared step differently",
                format.name()
            );
            assert_streams_as_whole(what, ir, format, &options, &whole);
        }
    }
}

fn assert_streams_as_whole(
    what: &str,
    ir: &TreeIr,
    format: Format,
    options: &Options,
    whole: &str,
) {
    let mut streamed = Vec::new();
    emit_to(ir, format, options, &mut streamed).expect("a Vec takes every write");
    assert!(
        streamed == whole.as_bytes(),
        "{what}: {} (inline: {}) streams other bytes than it returns",
        format.name(),
        options.inline
    );
    let mut handed = Vec::new();
    for &part in parts(format) {
        emit_part_handing_over(ir, format, options, part, &mut |buffer: Vec<u8>| {
            handed.extend_from_slice(&buffer);
            Vec::with_capacity(buffer.capacity())
        })
        .expect("handing over never fails");
    }
    assert!(
        handed == whole.as_bytes(),
        "{what}: {} (inline: {}) makes other bytes in parts than whole",
        format.name(),
        options.inline
    );
}

/// A plan long enough that its outputs stream in several chunks.
#[test]
fn a_long_plan_streams_the_bytes_it_returns() {
    let ir = compiled(
        "examples/p3_assembler",
        "rules.btrules",
        "problem.pddl",
        btc_testkit::long_p3_plan(20_000),
    );
    for format in [Format::Btcpp, Format::Pytrees, Format::Json] {
        for (inline, runtime) in [(false, Runtime::Import), (true, Runtime::Inline)] {
            let options = Options {
                inline,
                runtime,
                ..Options::default()
            };
            let whole = emit(&ir, format, &options);
            assert!(
                whole.len() > 1 << 20,
                "{}: {} bytes",
                format.name(),
                whole.len()
            );
            assert_streams_as_whole("P3, 20,000 steps", &ir, format, &options, &whole);
        }
    }
}

#[test]
fn a_long_plan_emits_as_its_unshared_copy() {
    let ir = compiled(
        "examples/p3_assembler",
        "rules.btrules",
        "problem.pddl",
        btc_testkit::long_p3_plan(300),
    );
    same_output("P3, 300 steps", &ir);
}

#[test]
fn every_step_arrangement_emits_as_its_unshared_copy() {
    let dir = "lang/tests/fixtures/pytrees/workshop";
    // The plan twice over is not a valid plan, but it compiles in order
    // and in parallel (lowering does not replay it), and it repeats every
    // ground action. `steps backchained` regresses the goal through the
    // plan, so it gets the plan once.
    let plan = read(&format!("{dir}/plan.txt"));
    let twice = format!("{plan}{plan}");
    for (rules, plan) in [
        ("in_order.btrules", &twice),
        ("parallel.btrules", &twice),
        ("backchained.btrules", &plan),
    ] {
        let ir = compiled(dir, rules, "problem.pddl", plan.clone());
        same_output(&format!("workshop {rules}"), &ir);
    }
}
