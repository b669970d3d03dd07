//! Loading a cell from its files. The reading is the caller's (the CLI
//! reads from disk, tests too); this puts the texts in the rules database,
//! so every diagnostic renders with its file.

use super::{Cell, CellSpec};
use btc_lang::db::{self, Database};
use btc_lang::path::FilePath;
use btc_pddl::diagnostic::Diagnostic;
use std::path::{Path, PathBuf};

/// Why a cell could not be loaded.
#[derive(Debug)]
pub enum LoadError {
    /// A file could not be read: its path and why.
    Read(PathBuf, String),
    /// The cell's files have errors.
    Invalid(Vec<Diagnostic>),
}

/// Reads `cell.toml` at `path` with `read`, and the domain and rules files
/// it names (relative to it), into `db`.
pub fn load(
    db: &mut Database,
    path: &Path,
    read: &mut dyn FnMut(&Path) -> Result<String, String>,
) -> Result<Cell, LoadError> {
    let mut get = |p: &Path| read(p).map_err(|e| LoadError::Read(p.to_path_buf(), e));
    let text = get(path)?;
    let cf = db.set_file(path, text.clone());
    let cid = db::file_id(db, cf);
    let spec = CellSpec::parse(&text, cid).map_err(LoadError::Invalid)?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let dpath = dir.join(&spec.domain);
    let dtext = get(&dpath)?;
    let dname = FilePath::new(&dpath).to_string();
    let df = db.set_file(&dname, dtext.clone());
    let did = db::file_id(db, df);
    let mut rules = Vec::new();
    for r in &spec.robots {
        let rpath = dir.join(&r.rules);
        let rtext = get(&rpath)?;
        let rname = FilePath::new(&rpath).to_string();
        db.set_file(&rname, rtext.clone());
        rules.push((r.robot, rname, rtext));
    }
    Cell::new(spec, cid, dname, dtext, did, rules).map_err(LoadError::Invalid)
}
