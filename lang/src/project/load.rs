//! Filling the database from a loader: a rules file and, transitively,
//! every file it names. Files the database has already (an editor's open
//! documents) are kept; files the loader could not give are noted, so that
//! the checks say why and the loader is not asked again until they change.

use super::loader::{FileLoader, ReadFailure};
use super::refs::{references, RefKind};
use crate::db::{Database, Db as _, SourceFile};
use crate::path::FilePath;

/// The file at `path`: the database's copy, or the loader's (read once).
pub fn load_file(
    db: &mut Database,
    loader: &dyn FileLoader,
    path: &FilePath,
) -> Result<SourceFile, ReadFailure> {
    if let Some(f) = db.file(path) {
        return Ok(f);
    }
    if let Some(why) = db.workspace().unread(db).get(path) {
        return Err(why.clone());
    }
    read_file(db, loader, path)
}

/// Reads `path` again, whatever the database has (it changed on disk).
pub fn read_file(
    db: &mut Database,
    loader: &dyn FileLoader,
    path: &FilePath,
) -> Result<SourceFile, ReadFailure> {
    let Some(disk) = path.as_path() else {
        return db.file(path).ok_or(ReadFailure::NotFound);
    };
    match loader.read(disk) {
        Ok(l) => Ok(db.set_read_file(path.clone(), l.text, l.decode)),
        Err(why) => {
            db.set_unread(path.clone(), why.clone());
            Err(why)
        }
    }
}

/// Loads a rules file, then the domain, problem and imports it names, and
/// theirs, transitively (each file once: import cycles are harmless).
pub fn load_rules(
    db: &mut Database,
    loader: &dyn FileLoader,
    path: &FilePath,
) -> Result<SourceFile, ReadFailure> {
    let root = load_file(db, loader, path)?;
    load_references(db, loader, root);
    Ok(root)
}

/// Loads what a rules file names (and, for imports, what they name).
pub fn load_references(db: &mut Database, loader: &dyn FileLoader, rules: SourceFile) {
    let mut todo = vec![rules];
    let mut seen = std::collections::HashSet::new();
    while let Some(f) = todo.pop() {
        if !seen.insert(f) || !f.path(db).is_rules() {
            continue;
        }
        crate::db::parse_ahead(db, f);
        let named: Vec<(RefKind, FilePath)> = references(db, f)
            .iter()
            .map(|r| (r.kind, r.path.clone()))
            .collect();
        for (kind, path) in named {
            // Failures are noted in the database and reported by the checks.
            if let Ok(g) = load_file(db, loader, &path) {
                if kind == RefKind::Import {
                    todo.push(g);
                }
            }
        }
    }
}
