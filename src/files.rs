//! Reading input files, with encoding problems reported as diagnostics
//! rather than failures (into [`Sources`] for the PDDL commands, and as the
//! project loader's disk, [`Disk`], for rules files and what they name),
//! and writing outputs. Every command's files go through here, and through
//! `btc_files` underneath: one bounded reader, one writer.

use btc_lang::project::report::decode_diagnostic;
use btc_lang::project::{FileLoader, Loaded, ReadFailure};
use btc_pddl::diagnostic::{codes, Diagnostic};
use btc_pddl::source::{decode, DecodeProblem, FileId, Sources, MAX_FILE_BYTES};
use std::path::{Path, PathBuf};

/// A file's text as read from disk, and what was wrong with it.
struct Read {
    text: String,
    /// A file over the size limit reads as empty, with this problem.
    problem: Option<DecodeProblem>,
}

/// Reads and decodes a file. `Err` only when it cannot be read at all.
fn read(path: &Path) -> Result<Read, btc_files::ReadError> {
    match btc_files::read(path, MAX_FILE_BYTES) {
        Ok(bytes) => {
            let (text, problem) = decode_owned(bytes);
            Ok(Read { text, problem })
        }
        Err(btc_files::ReadError::TooLarge { known, .. }) => Ok(Read {
            text: String::new(),
            problem: Some(DecodeProblem::TooLarge {
                bytes: known.map_or(MAX_FILE_BYTES + 1, |n| n as usize),
            }),
        }),
        Err(e) => Err(e),
    }
}

/// The command stops on a file it was given that cannot be read (exit 2):
/// one message for every command, F001 (F004 for a folder or a device),
/// with the closest file beside it when it does not exist.
fn file_error(path: &Path, why: &ReadFailure) -> anyhow::Error {
    let code = match why {
        ReadFailure::NotAFile { .. } => codes::FILE_NOT_REGULAR,
        _ => codes::FILE_UNREADABLE,
    };
    let mut message = format!("[{}] cannot read `{}`: {why}", code.id, path.display());
    if *why == ReadFailure::NotFound {
        if let Some(near) = closest_beside(path) {
            message.push_str(&format!("; did you mean `{}`?", near.display()));
        }
    }
    anyhow::anyhow!(message)
}

/// The file in `path`'s folder whose name is closest to its name.
fn closest_beside(path: &Path) -> Option<PathBuf> {
    let name = path.file_name()?.to_string_lossy();
    let dir = path.parent().unwrap_or(Path::new(""));
    let listed = list(if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    });
    let names: Vec<String> = listed
        .iter()
        .filter_map(|p| Some(p.file_name()?.to_string_lossy().into_owned()))
        .collect();
    let best = btc_pddl::diagnostic::closest(&name, names.iter().map(String::as_str))?;
    Some(dir.join(best))
}

/// Reads a UTF-8 file whole through the bounded reader, for readers that
/// take their files' texts from a callback (the cell loader): every
/// problem is the error's text.
pub fn read_text(path: &Path) -> Result<String, String> {
    let bytes = btc_files::read(path, MAX_FILE_BYTES).map_err(|e| {
        let code = match e {
            btc_files::ReadError::NotAFile { .. } => codes::FILE_NOT_REGULAR,
            btc_files::ReadError::TooLarge { .. } => codes::FILE_TOO_LARGE,
            btc_files::ReadError::Io(_) => codes::FILE_UNREADABLE,
        };
        format!("[{}] {e}", code.id)
    })?;
    String::from_utf8(bytes).map_err(|e| {
        format!(
            "it is not UTF-8: byte 0x{:02X} at offset {} is not valid",
            e.as_bytes()[e.utf8_error().valid_up_to()],
            e.utf8_error().valid_up_to()
        )
    })
}

/// [`decode`] without copying a UTF-8 file's bytes.
fn decode_owned(bytes: Vec<u8>) -> (String, Option<DecodeProblem>) {
    let plain = !bytes.starts_with(&[0xEF, 0xBB, 0xBF])
        && !bytes.starts_with(&[0xFF, 0xFE])
        && !bytes.starts_with(&[0xFE, 0xFF]);
    if plain {
        match String::from_utf8(bytes) {
            Ok(s) => (s, None),
            Err(e) => decode(e.as_bytes()),
        }
    } else {
        decode(&bytes)
    }
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
            Err(e) => Err(failure(e)),
        }
    }

    fn list(&self, dir: &Path) -> Vec<PathBuf> {
        list(dir)
    }
}

/// A reader's error as the project loader records it.
pub fn failure(e: btc_files::ReadError) -> ReadFailure {
    match e {
        btc_files::ReadError::Io(e) if e.kind() == std::io::ErrorKind::NotFound => {
            ReadFailure::NotFound
        }
        e @ btc_files::ReadError::NotAFile { .. } => ReadFailure::NotAFile {
            reason: e.to_string(),
        },
        e => ReadFailure::Unreadable {
            reason: e.to_string(),
        },
    }
}

/// The regular files directly in a folder, sorted.
pub fn list(dir: &Path) -> Vec<PathBuf> {
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

/// A file the user named that cannot be read: the command stops (exit 2).
pub fn unreadable_job_file(e: btc_lang::project::job::Unreadable) -> anyhow::Error {
    match e.path.as_path() {
        Some(p) => file_error(p, &e.why),
        None => anyhow::anyhow!("[{}] {e}", codes::FILE_UNREADABLE.id),
    }
}

/// Writes an output file (`-o`, `fmt`): atomically for a regular file,
/// keeping its mode, owner and links; in place for special files.
pub fn write_atomically(path: &Path, text: &str) -> anyhow::Result<()> {
    write_bytes_atomically(path, text.as_bytes())
}

/// Creates the missing folders above an output file: every command that
/// writes (`-o`, `--trace`, `--btlog`, ...) does, as `btc executor -o` does
/// for its folder. Called once the output is ready to be written, so a
/// command that fails first creates nothing.
fn make_parent(path: &Path) -> anyhow::Result<()> {
    match path.parent() {
        Some(dir) if !dir.as_os_str().is_empty() && !dir.exists() => std::fs::create_dir_all(dir)
            .map_err(|e| anyhow::anyhow!("cannot create the folder `{}`: {e}", dir.display())),
        _ => Ok(()),
    }
}

/// [`write_atomically`] for bytes.
pub fn write_bytes_atomically(path: &Path, bytes: &[u8]) -> anyhow::Result<()> {
    make_parent(path)?;
    btc_files::write(path, bytes)
        .map_err(|e| anyhow::anyhow!("cannot write `{}`: {e}", path.display()))
}

/// [`write_atomically`] of what `produce` writes as it makes it (a long
/// plan's tree is streamed, never whole in memory).
pub fn write_produced(
    path: &Path,
    produce: &mut btc_files::write::Produce<'_>,
) -> anyhow::Result<()> {
    make_parent(path)?;
    btc_files::write_with(path, produce)
        .map_err(|e| anyhow::anyhow!("cannot write `{}`: {e}", path.display()))
}

/// Whether writing what `produce` writes would change the file at `path`
/// (`--check`): nothing is written.
pub fn would_change(
    path: &Path,
    produce: &mut btc_files::write::Produce<'_>,
) -> anyhow::Result<btc_files::Comparison> {
    btc_files::would_change(path, produce)
        .map_err(|e| anyhow::anyhow!("cannot read `{}`: {e}", path.display()))
}

/// Opens an output that is written as it is produced (`--trace`).
pub fn stream(path: &Path) -> anyhow::Result<btc_files::Stream> {
    make_parent(path)?;
    btc_files::Stream::create(path)
        .map_err(|e| anyhow::anyhow!("cannot write `{}`: {e}", path.display()))
}

/// Reads a file. `Err` only when it cannot be read at all.
pub fn load(
    sources: &mut Sources,
    path: &Path,
    diags: &mut Vec<Diagnostic>,
) -> anyhow::Result<FileId> {
    let r = read(path).map_err(|e| file_error(path, &failure(e)))?;
    let id = sources.add(path.display().to_string(), r.text);
    if let Some(p) = r.problem {
        diags.push(decode_diagnostic(id, &p));
    }
    Ok(id)
}

/// Reads a file into the database through [`Disk`], with its encoding
/// problems as diagnostics. `Err` only when it cannot be read at all.
pub fn load_into_db(
    db: &mut btc_lang::db::Database,
    path: &Path,
    diags: &mut Vec<Diagnostic>,
) -> anyhow::Result<btc_lang::db::SourceFile> {
    let at = btc_lang::path::FilePath::new(path);
    let f = btc_lang::project::read_file(db, &Disk, &at)
        .map_err(|why| unreadable_job_file(btc_lang::project::job::Unreadable { path: at, why }))?;
    diags.extend(
        btc_lang::project::report::read_diagnostics(db, f)
            .iter()
            .cloned(),
    );
    Ok(f)
}
