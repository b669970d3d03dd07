//! The disk as a project reads it: through btc's bounded reader (folders and
//! devices refused, nothing read past btc's file limit).

use btc_lang::project::{FileLoader, Loaded, ReadFailure};
use std::path::{Path, PathBuf};

pub(crate) struct Disk;

impl FileLoader for Disk {
    fn read(&self, path: &Path) -> Result<Loaded, ReadFailure> {
        match btc_files::read(path, btc_pddl::source::MAX_FILE_BYTES) {
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
