//! "Did you mean" for the paths a rules file names that do not exist:
//! the closest file name in the folder the path points into. Looking at a
//! folder is the loader's business (the database reads no disk), so this
//! runs where the reports are printed or published, over a loader.

use super::loader::{FileLoader, ReadFailure};
use super::refs::references;
use crate::db::{Database, Db as _, SourceFile};
use btc_pddl::diagnostic::{closest, codes, Diagnostic};
use std::path::Path;

/// Adds to each "cannot find" diagnostic (R017, R018) of `rules` a hint
/// and a fix naming the closest existing file beside the one written.
pub fn suggest_paths(
    db: &Database,
    loader: &dyn FileLoader,
    rules: SourceFile,
    diags: &mut [Diagnostic],
) {
    let unread = db.workspace().unread(db);
    let text = rules.text(db);
    for r in references(db, rules) {
        if unread.get(&r.path) != Some(&ReadFailure::NotFound) {
            continue;
        }
        let Some(disk) = r.path.as_path() else {
            continue;
        };
        let (Some(dir), Some(name)) = (disk.parent(), disk.file_name()) else {
            continue;
        };
        let dir = if dir.as_os_str().is_empty() {
            Path::new(".")
        } else {
            dir
        };
        let names: Vec<String> = loader
            .list(dir)
            .iter()
            .filter_map(|p| Some(p.file_name()?.to_string_lossy().into_owned()))
            .collect();
        let Some(best) = closest(&name.to_string_lossy(), names.iter().map(String::as_str)) else {
            continue;
        };
        let written = match Path::new(&r.written).parent() {
            Some(p) if !p.as_os_str().is_empty() => format!("{}/{best}", p.display()),
            _ => best.to_owned(),
        };
        let quoted = text
            .get(r.span.start as usize..r.span.end as usize)
            .is_some_and(|s| s.starts_with('"'));
        let replacement = if quoted {
            format!("\"{written}\"")
        } else {
            written.clone()
        };
        for d in diags.iter_mut().filter(|d| {
            [codes::R_NO_DOMAIN.id, codes::R_IMPORT.id].contains(&d.code)
                && d.span.file == r.span.file
                && d.span.start <= r.span.start
                && r.span.end <= d.span.end
        }) {
            *d = d
                .clone()
                .with_hint(format!("did you mean `{written}`? It is beside it"))
                .with_fix(
                    format!("change to `{written}`"),
                    r.span,
                    replacement.clone(),
                );
        }
    }
}
