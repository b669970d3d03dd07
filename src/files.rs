//! Reading input files into [`Sources`], with encoding problems reported as
//! diagnostics rather than failures.

use btc_pddl::diagnostic::{codes, Diagnostic};
use btc_pddl::source::{decode, DecodeProblem, FileId, Sources, Span};
use std::path::Path;

/// A file's text as read from disk, and what was wrong with it.
struct Read {
    text: String,
    /// A file over the size limit reads as empty, with this problem.
    problem: Option<DecodeProblem>,
}

/// Reads and decodes a file. `Err` only when it cannot be read at all.
fn read(path: &Path) -> anyhow::Result<Read> {
    let len = std::fs::metadata(path).map(|m| m.len()).unwrap_or(0);
    if len > btc_pddl::source::MAX_FILE_BYTES as u64 {
        return Ok(Read {
            text: String::new(),
            problem: Some(DecodeProblem::TooLarge {
                bytes: len as usize,
            }),
        });
    }
    let bytes = std::fs::read(path).map_err(|e| {
        anyhow::anyhow!(
            "[{}] cannot read `{}`: {e}",
            codes::FILE_UNREADABLE.id,
            path.display()
        )
    })?;
    let (text, problem) = decode(&bytes);
    Ok(Read { text, problem })
}

/// Reads a file into the database (under its normalized path), reporting
/// encoding problems as diagnostics. `Err` only when it cannot be read.
pub fn load_into_db(
    db: &mut btc_lang::db::Database,
    path: &Path,
    diags: &mut Vec<Diagnostic>,
) -> anyhow::Result<btc_lang::db::SourceFile> {
    let r = read(path)?;
    let f = db.set_file(&btc_lang::db::normalize(path), r.text);
    if let Some(p) = r.problem {
        diags.push(decode_diagnostic(btc_lang::db::file_id(db, f), p));
    }
    Ok(f)
}

fn decode_diagnostic(id: FileId, problem: DecodeProblem) -> Diagnostic {
    match problem {
        DecodeProblem::InvalidUtf8 { offset, byte } => Diagnostic::error(
            codes::FILE_ENCODING,
            Span::new(id, offset, offset + 3),
            format!("this file is not UTF-8: byte 0x{byte:02X} at offset {offset} is not valid"),
        )
        .with_hint("save the file as UTF-8; btc read the rest with the bad bytes replaced"),
        DecodeProblem::BadUtf16 => Diagnostic::error(
            codes::FILE_ENCODING,
            Span::new(id, 0, 0),
            "this file starts with a UTF-16 byte-order mark but is not valid UTF-16",
        )
        .with_hint("save the file as UTF-8"),
        DecodeProblem::TooLarge { bytes } => too_large(id, bytes as u64),
    }
}

/// Writes `text` to `path` through a temporary file in the same folder and
/// a rename, so a failed run never leaves a half-written output.
pub fn write_atomically(path: &Path, text: &str) -> anyhow::Result<()> {
    write_bytes_atomically(path, text.as_bytes())
}

/// [`write_atomically`] for bytes.
pub fn write_bytes_atomically(path: &Path, bytes: &[u8]) -> anyhow::Result<()> {
    use std::io::Write;
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let mut tmp = tempfile::NamedTempFile::new_in(dir)
        .map_err(|e| anyhow::anyhow!("cannot write in `{}`: {e}", dir.display()))?;
    tmp.write_all(bytes)?;
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
    let r = read(path)?;
    let id = sources.add(path.display().to_string(), r.text);
    if let Some(p) = r.problem {
        diags.push(decode_diagnostic(id, p));
    }
    Ok(id)
}

fn too_large(id: FileId, bytes: u64) -> Diagnostic {
    Diagnostic::error(
        codes::FILE_TOO_LARGE,
        Span::new(id, 0, 0),
        format!(
            "this file has {bytes} bytes; btc reads files of at most {} bytes",
            btc_pddl::source::MAX_FILE_BYTES
        ),
    )
}
