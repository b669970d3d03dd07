//! The disk as a project loader reads it, through btc's bounded reader:
//! folders and devices are refused, and nothing is read past `limit`
//! bytes. The language server and the library facade load projects with
//! it (the CLI keeps its own, which reads an over-long file as a
//! diagnostic instead of a failure).

use super::loader::{FileLoader, Loaded, ReadFailure};
use std::path::{Path, PathBuf};

pub struct DiskLoader {
    /// The largest file read, in bytes.
    pub limit: usize,
}

impl FileLoader for DiskLoader {
    fn read(&self, path: &Path) -> Result<Loaded, ReadFailure> {
        match btc_files::read(path, self.limit) {
            Ok(bytes) => Ok(Loaded::from_bytes(&bytes)),
            Err(btc_files::ReadError::Io(e)) if e.kind() == std::io::ErrorKind::NotFound => {
                Err(ReadFailure::NotFound)
            }
            Err(e @ btc_files::ReadError::NotAFile { .. }) => Err(ReadFailure::NotAFile {
                reason: e.to_string(),
            }),
            Err(e) => Err(ReadFailure::Unreadable {
                reason: e.to_string(),
            }),
        }
    }

    fn list(&self, dir: &Path) -> Vec<PathBuf> {
        let mut out: Vec<PathBuf> = std::fs::read_dir(dir)
            .into_iter()
            .flatten()
            .filter_map(Result::ok)
            .filter(|e| e.file_type().is_ok_and(|t| t.is_file()))
            .map(|e| e.path())
            .collect();
        out.sort();
        out
    }
}
