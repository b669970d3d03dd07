//! Any bytes as an ARIAC 2023 trial file (`btc trial`) and as a cell file
//! (`--cell`): read the YAML into a trial, build its PDDL problem with the
//! bundled cell's mapping and check that problem against the cell's domain;
//! parse the same text as a `cell.toml`; render every diagnostic.
#![no_main]

use btc_agent::cell::{bundled, load, Cell, CellSpec, TrialProblem};
use btc_lang::db::{self, Database};
use btc_pddl::pipeline::problem_unit_from;
use btc_pddl::render::to_terminal;
use btc_pddl::source::decode;
use libfuzzer_sys::fuzz_target;
use std::path::Path;

/// The bundled cell, loaded once.
fn cell() -> &'static Cell {
    thread_local! {
        static CELL: &'static Cell = {
            let mut db = Database::new();
            let c = load::load(&mut db, Path::new(bundled::CELL_PATH), &mut bundled::read)
                .unwrap_or_else(|_| panic!("the bundled cell loads"));
            Box::leak(Box::new(c))
        };
    }
    CELL.with(|c| *c)
}

fuzz_target!(|data: &[u8]| {
    let (text, _) = decode(data);
    let cell = cell();
    // A database of its own: setting a file in a clone of a shared one
    // waits for every other handle to it to go (salsa), forever.
    let mut db = Database::new();
    let f = db.set_file("trial.yaml", text.to_string());
    let fid = db::file_id(&db, f);
    let (trial, mut diags) = btc_agent::trial::read(&text, fid);
    if let Some(t) = trial {
        let tp = TrialProblem::build(cell, &t, "fuzz");
        let pf = db.set_problem("trial.problem.pddl", tp.written.clone());
        let pid = db::file_id(&db, pf);
        // The problem's text reads back as the value the trial runs on.
        let pu = problem_unit_from(
            tp.written.text(),
            pid,
            cell.domain.domain.as_ref(),
            &cell.domain.index,
        );
        assert_eq!(pu.problem, Some(tp.written.problem(pid)));
        diags.extend(pu.diagnostics);
    }
    if let Err(more) = CellSpec::parse(&text, fid) {
        diags.extend(more);
    }
    let _ = to_terminal(&diags, &db.sources(), false);
});
