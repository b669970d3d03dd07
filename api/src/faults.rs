//! Fault scenarios (`btc run --faults`): the ARIAC challenges a run or an
//! agent meets, read from the TOML form docs/runtime.md describes.

use crate::diagnostic::{Diagnostic, Error, Position};
use btc_agent::faults::Scenario;
use btc_pddl::source::SourceFile;
use btc_runtime::LoadError;
use std::path::Path;

/// The path scenario texts are reported under.
const FAULTS_TEXT: &str = "<faults>";

#[derive(Clone, Debug)]
pub struct Faults {
    pub(crate) scenario: Scenario,
    pub(crate) path: String,
    text: String,
}

impl Faults {
    /// The scenario's faults as behaviours would report them to an agent
    /// that runs with its own executor ([`crate::Agent::run_with`]), by
    /// their labels (the `name`, or the kind).
    pub fn reported(&self) -> Vec<(String, crate::ReportedFault)> {
        self.scenario
            .faults
            .iter()
            .map(|f| (f.label(), crate::ReportedFault::of(f)))
            .collect()
    }

    pub fn parse(text: &str) -> Result<Faults, Error> {
        Faults::read(text.to_owned(), FAULTS_TEXT.to_owned())
    }

    pub fn open(path: impl AsRef<Path>) -> Result<Faults, Error> {
        let path = path.as_ref();
        let shown = path.display().to_string();
        let bytes = btc_files::read(path, btc_pddl::source::MAX_FILE_BYTES).map_err(|e| {
            Error::one(Diagnostic::without_place(
                btc_pddl::diagnostic::codes::FILE_UNREADABLE.id,
                format!("cannot read `{shown}`: {e}"),
                &shown,
            ))
        })?;
        let (text, _) = btc_pddl::source::decode(&bytes);
        Faults::read(text, shown)
    }

    fn read(text: String, path: String) -> Result<Faults, Error> {
        match Scenario::parse(&text) {
            Ok(scenario) => Ok(Faults {
                scenario,
                path,
                text,
            }),
            Err(e) => Err(placed(&e, &path, Some(&text))),
        }
    }

    /// A run-time error about this scenario (a fault that names what the
    /// problem lacks), placed in its text.
    pub(crate) fn error(&self, e: &LoadError) -> Error {
        placed(e, &self.path, Some(&self.text))
    }
}

/// A tree's or scenario's load error as a diagnostic of `path`.
pub(crate) fn load_error(e: &LoadError, path: &str) -> Error {
    placed(e, path, None)
}

fn placed(e: &LoadError, path: &str, text: Option<&str>) -> Error {
    let mut d = Diagnostic::without_place(e.code.id, e.message.clone(), path);
    if let (Some(off), Some(text)) = (e.offset, text) {
        let (line, column) = SourceFile::new(path, text).line_col(off as u32);
        d.start = Position { line, column };
        d.end = d.start;
    }
    d.hint = e.hint.clone();
    Error::one(d)
}
