//! One project loader for every front door. `btc check`, `btc compile`,
//! `btc run` and the language server load a rules file and the files it
//! names through the same functions ([`load`]) from a [`FileLoader`], and
//! report the same diagnostics in the same order ([`report`]). Which problem
//! a plan goes with is decided here too ([`job`]).

pub mod concurrent;
pub mod disk;
pub mod fit;
pub mod job;
pub mod load;
pub mod loader;
pub mod misfit;
pub mod nearby;
pub mod refs;
pub mod report;

pub use disk::DiskLoader;
pub use job::{
    load_job, load_job_files, load_neighbours_if_wanted, JobPaths, LoadedJob, PlanSource,
    ProblemChoice,
};
pub use load::{load_file, load_references, load_rules, read_file};
pub use loader::{FileLoader, Loaded, MemoryLoader, ReadFailure};
pub use nearby::suggest_paths;
pub use refs::{references, RefKind, Reference};
pub use report::{flatten, job_report, project_report, FileReport};
