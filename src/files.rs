//! Reading input files, with encoding problems reported as diagnostics
//! rather than failures: into [`Sources`] for the PDDL commands, and as the
//! project loader's disk ([`Disk`]) for rules files and what they name.

use btc_lang::project::report::decode_diagnostic;
use btc_lang::project::{FileLoader, Loaded, ReadFailure};
use btc_pddl::diagnostic::{codes, Diagnostic};
use btc_pddl::source::{decode, DecodeProblem, FileId, Sources};
use std::path::{Path, PathBuf};

/// A file's text as read from disk, and what was wrong with it.
struct Read {
    text: String,
    /// A file over the size limit reads as empty, with this problem.
    problem: Option<DecodeProblem>,
}

/// Reads and decodes a file. `Err` only when it cannot be read at all.
fn read(path: &Path) -> std::io::Result<Read> {
    let len = std::fs::metadata(path).map(|m| m.len()).unwrap_or(0);
    if len > btc_pddl::source::MAX_FILE_BYTES as u64 {
        return Ok(Read {
            text: String::new(),
            problem: Some(DecodeProblem::TooLarge {
                bytes: len as usize,
            }),
        });
    }
    let bytes = std::fs::read(path)?;
    let (text, problem) = decode(&bytes);
    Ok(Read { text, problem })
}

fn unreadable(path: &Path, e: &std::io::Error) -> anyhow::Error {
    anyhow::anyhow!(
        "[{}] cannot read `{}`: {e}",
        codes::FILE_UNREADABLE.id,
        path.display()
    )
}

/// The disk as the project loader sees it: every file a rules file names
/// is read through [`read`].
pub struct Disk;

impl FileLoader for Disk {
    fn read(&self, path: &Path) -> Result<Loaded, ReadFailure> {
        match read(path) {
            Ok(r) => Ok(Loaded {
                text: r.text,
                decode: r.problem,
            }),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Err(ReadFailure::NotFound),
            Err(e) => Err(ReadFailure::Unreadable {
                reason: e.to_string(),
            }),
        }
    }

    fn list(&self, dir: &Path) -> Vec<PathBuf> {
        let Ok(entries) = std::fs::read_dir(dir) else {
            return Vec::new();
        };
        let mut out: Vec<PathBuf> = entries
            .filter_map(Result::ok)
            .filter(|e| e.file_type().is_ok_and(|t| t.is_file()))
            .map(|e| dir.join(e.file_name()))
            .collect();
        out.sort();
        out
    }
}

/// A file the user named that cannot be read: the command stops (exit 2).
pub fn unreadable_job_file(e: btc_lang::project::job::Unreadable) -> anyhow::Error {
    anyhow::anyhow!("[{}] {e}", codes::FILE_UNREADABLE.id)
}

/// Writes `text` to `path` through a temporary file in the same folder and
/// a rename, so a failed run never leaves a half-written output.
pub fn write_atomically(path: &Path, text: &str) -> anyhow::Result<()> {
    use std::io::Write;
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let mut tmp = tempfile::NamedTempFile::new_in(dir)
        .map_err(|e| anyhow::anyhow!("cannot write in `{}`: {e}", dir.display()))?;
    tmp.write_all(text.as_bytes())?;
    tmp.as_file().sync_all()?;
    tmp.persist(path)
        .map_err(|e| anyhow::anyhow!("cannot write `{}`: {}", path.display(), e.error))?;
    Ok(())
}

/// Reads a file. `Err` only when it cannot be read at all.
pub fn load(
    sources: &mut Sources,
    path: &Path,
    diags: &mut Vec<Diagnostic>,
) -> anyhow::Result<FileId> {
    let r = read(path).map_err(|e| unreadable(path, &e))?;
    let id = sources.add(path.display().to_string(), r.text);
    if let Some(p) = r.problem {
        diags.push(decode_diagnostic(id, &p));
    }
    Ok(id)
}
