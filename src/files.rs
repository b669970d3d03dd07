//! Reading input files into [`Sources`], with encoding problems reported as
//! diagnostics rather than failures, and writing outputs. Every command's
//! files go through here, and through `btc_files` underneath: one bounded
//! reader, one writer.

use btc_pddl::diagnostic::{codes, Diagnostic};
use btc_pddl::source::{decode, DecodeProblem, FileId, Sources, Span, MAX_FILE_BYTES};
use std::path::Path;

/// A file's text as read from disk, and what was wrong with it.
struct Read {
    text: String,
    /// A file over the size limit reads as empty, with this problem.
    problem: Option<DecodeProblem>,
}

/// Reads and decodes a file. `Err` only when it cannot be read at all.
fn read(path: &Path) -> anyhow::Result<Read> {
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
        Err(e @ btc_files::ReadError::NotAFile { .. }) => Err(anyhow::anyhow!(
            "[{}] cannot read `{}`: {e}",
            codes::FILE_NOT_REGULAR.id,
            path.display()
        )),
        Err(btc_files::ReadError::Io(e)) => Err(anyhow::anyhow!(
            "[{}] cannot read `{}`: {e}",
            codes::FILE_UNREADABLE.id,
            path.display()
        )),
    }
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

/// Writes an output file (`-o`, `fmt`): atomically for a regular file,
/// keeping its mode, owner and links; in place for special files.
pub fn write_atomically(path: &Path, text: &str) -> anyhow::Result<()> {
    write_bytes_atomically(path, text.as_bytes())
}

/// [`write_atomically`] for bytes.
pub fn write_bytes_atomically(path: &Path, bytes: &[u8]) -> anyhow::Result<()> {
    btc_files::write(path, bytes)
        .map_err(|e| anyhow::anyhow!("cannot write `{}`: {e}", path.display()))
}

/// Opens an output that is written as it is produced (`--trace`).
pub fn stream(path: &Path) -> anyhow::Result<btc_files::Stream> {
    btc_files::Stream::create(path)
        .map_err(|e| anyhow::anyhow!("cannot write `{}`: {e}", path.display()))
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
    // A stream that went on past the limit has no known size.
    let message = if bytes == MAX_FILE_BYTES as u64 + 1 {
        format!("this input goes on past {MAX_FILE_BYTES} bytes, the most btc reads")
    } else {
        format!("this file has {bytes} bytes; btc reads files of at most {MAX_FILE_BYTES} bytes")
    };
    Diagnostic::error(codes::FILE_TOO_LARGE, Span::new(id, 0, 0), message)
}
