//! BT.CPP's `<include path="...">`: a file brings in the trees (and node
//! models) of others. Paths are relative to the including file; a file
//! that includes itself (directly or not) is refused, and so is a chain of
//! includes deeper than [`MAX_DEPTH`]. The main tree is the first file's
//! (`main_tree_to_execute`, or its only tree when it includes none).

use crate::error::LoadError;
use crate::spec::TreeDoc;
use crate::xml::{self, Include};
use btc_pddl::diagnostic::codes;
use std::path::{Path, PathBuf};

/// The longest chain of includes read.
pub const MAX_DEPTH: usize = 16;

/// An error and the file it is in (as the caller's `open` named it).
#[derive(Debug)]
pub struct Located<F> {
    pub file: F,
    pub error: LoadError,
}

/// A file the caller read: how it names it (for diagnostics), and its text.
pub struct Opened<F> {
    pub file: F,
    pub text: String,
}

/// Reads the XML tree file `path` (already read as `first`) and every file
/// it includes. `open` reads an included file; its error is the reason in
/// the user's terms.
pub fn load<F: Copy>(
    path: &Path,
    first: Opened<F>,
    open: &mut dyn FnMut(&Path) -> Result<Opened<F>, String>,
) -> Result<TreeDoc, Located<F>> {
    let at_first = |error| Located {
        file: first.file,
        error,
    };
    let parsed = xml::parse_file(&first.text).map_err(at_first)?;
    let canonical = path.canonicalize().unwrap_or_else(|_| path.to_path_buf());
    let mut doc = parsed.doc;
    let mut chain = vec![canonical.clone()];
    include_all(
        &mut doc,
        path,
        first.file,
        &parsed.includes,
        &mut chain,
        open,
    )?;
    xml::finish(doc, parsed.main).map_err(at_first)
}

/// Reads the files `includes` of `from` (file `file`) names into `doc`.
/// Paths are joined as given (diagnostics name files as the user wrote
/// them); the chain holds them canonical, to find cycles.
fn include_all<F: Copy>(
    doc: &mut TreeDoc,
    from: &Path,
    file: F,
    includes: &[Include],
    chain: &mut Vec<PathBuf>,
    open: &mut dyn FnMut(&Path) -> Result<Opened<F>, String>,
) -> Result<(), Located<F>> {
    let here = |error| Located { file, error };
    for inc in includes {
        let target = from
            .parent()
            .unwrap_or_else(|| Path::new("."))
            .join(&inc.path);
        let canonical = target.canonicalize().map_err(|e| {
            here(
                LoadError::new(
                    codes::X_INCLUDE_READ,
                    format!(
                        "<include path=\"{}\">: `{}` cannot be read: {e}",
                        inc.path,
                        target.display()
                    ),
                )
                .at(inc.at)
                .hint("the path is relative to the file that includes it"),
            )
        })?;
        if let Some(k) = chain.iter().position(|p| *p == canonical) {
            let cycle: Vec<String> = chain[k..]
                .iter()
                .chain([&canonical])
                .map(|p| file_name(p))
                .collect();
            return Err(here(
                LoadError::new(
                    codes::X_INCLUDE_CYCLE,
                    format!(
                        "<include path=\"{}\">: `{}` includes itself ({})",
                        inc.path,
                        file_name(&canonical),
                        cycle.join(" -> ")
                    ),
                )
                .at(inc.at),
            ));
        }
        if chain.len() >= MAX_DEPTH {
            return Err(here(
                LoadError::new(
                    codes::X_INCLUDE_CYCLE,
                    format!(
                        "<include path=\"{}\">: includes nest more than {MAX_DEPTH} files deep",
                        inc.path
                    ),
                )
                .at(inc.at),
            ));
        }
        let opened = open(&target).map_err(|why| {
            here(
                LoadError::new(
                    codes::X_INCLUDE_READ,
                    format!("<include path=\"{}\">: {why}", inc.path),
                )
                .at(inc.at),
            )
        })?;
        let inner = opened.file;
        let parsed =
            xml::parse_file(&opened.text).map_err(|error| Located { file: inner, error })?;
        for (id, tree) in parsed.doc.trees {
            if doc.tree(&id).is_some() {
                return Err(here(
                    LoadError::new(
                        codes::X_TREE_SYNTAX,
                        format!(
                            "<include path=\"{}\">: the tree `{id}` it defines is defined already",
                            inc.path
                        ),
                    )
                    .at(inc.at),
                ));
            }
            doc.trees.push((id, tree));
        }
        for m in parsed.doc.models {
            if doc.model(&m.id).is_none() {
                doc.models.push(m);
            }
        }
        chain.push(canonical.clone());
        include_all(doc, &target, inner, &parsed.includes, chain, open)?;
        chain.pop();
    }
    Ok(())
}

fn file_name(p: &Path) -> String {
    p.file_name().map_or_else(
        || p.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    )
}
