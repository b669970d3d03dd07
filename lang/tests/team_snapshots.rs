//! What a team writes to snapshot its trees with insta in its own Rust
//! tests, through btc's crates (docs/testing.md shows this file): a disk
//! loader, a compile job per plan, the tree in a format, one snapshot each.
//! Here it is run on `examples/two_robots`.

use btc_emit::{emit, Format, Options};
use btc_lang::db::{compile, Database};
use btc_lang::path::FilePath;
use btc_lang::project::{load_job, FileLoader, JobPaths, Loaded, PlanSource, ReadFailure};
use std::path::{Path, PathBuf};

/// The files btc reads, from disk.
struct Disk;

impl FileLoader for Disk {
    fn read(&self, path: &Path) -> Result<Loaded, ReadFailure> {
        match std::fs::read(path) {
            Ok(bytes) => Ok(Loaded::from_bytes(&bytes)),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Err(ReadFailure::NotFound),
            Err(e) => Err(ReadFailure::Unreadable {
                reason: e.to_string(),
            }),
        }
    }

    fn list(&self, dir: &Path) -> Vec<PathBuf> {
        std::fs::read_dir(dir)
            .map(|d| d.filter_map(|e| e.ok().map(|e| e.path())).collect())
            .unwrap_or_default()
    }
}

/// The tree `rules` makes of `plan` (its problem found as `btc compile`
/// finds it), in `format`.
fn tree(rules: &Path, plan: &Path, format: Format) -> String {
    let mut db = Database::new();
    let paths = JobPaths {
        rules: FilePath::new(rules),
        plan: PlanSource::File(FilePath::new(plan)),
        problem: None,
        domain: None,
    };
    let job = load_job(&mut db, &Disk, &paths).expect("the files are readable");
    let ir = compile(&db, job.job)
        .as_ref()
        .unwrap_or_else(|errors| panic!("{errors:#?}"));
    emit(ir, format, &Options::default())
}

#[test]
fn two_robots_tree() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/two_robots");
    let mermaid = tree(
        &dir.join("rules.btrules"),
        &dir.join("plan.plan"),
        Format::Mermaid,
    );
    insta::assert_snapshot!("two_robots_mermaid", mermaid);
}
