//! File identities. A [`FilePath`] is what the database keys files by: a
//! path normalised once, by its components (no `.`, no `name/..`, one
//! separator between names), or a stdlib module. Nothing compares or
//! rewrites paths as strings.

use std::fmt;
use std::path::{Component, Path, PathBuf};

#[derive(Clone, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum FilePath {
    /// A file on disk (or in a loader's memory), relative to the working
    /// folder or absolute, as the user or the editor gave it.
    Disk(PathBuf),
    /// A module of the standard library, `std::NAME`, built into btc.
    Std(String),
}

impl FilePath {
    /// `a/./b/../c` -> `a/c`, `/x/../..` -> `/`; leading `..` of a relative
    /// path stay (nothing here looks at the file system).
    pub fn new(path: impl AsRef<Path>) -> FilePath {
        let mut out = PathBuf::new();
        // Normal components pushed so far (those a `..` may remove).
        let mut names = 0usize;
        for c in path.as_ref().components() {
            match c {
                Component::CurDir => {}
                Component::ParentDir if names > 0 => {
                    out.pop();
                    names -= 1;
                }
                // `/..` is `/`.
                Component::ParentDir if out.has_root() => {}
                Component::ParentDir => out.push(".."),
                Component::Normal(n) => {
                    out.push(n);
                    names += 1;
                }
                Component::RootDir | Component::Prefix(_) => out.push(c.as_os_str()),
            }
        }
        if out.as_os_str().is_empty() {
            out.push(".");
        }
        FilePath::Disk(out)
    }

    pub fn std(module: &str) -> FilePath {
        FilePath::Std(module.to_owned())
    }

    /// The path on disk; `None` for a stdlib module.
    pub fn as_path(&self) -> Option<&Path> {
        match self {
            FilePath::Disk(p) => Some(p),
            FilePath::Std(_) => None,
        }
    }

    /// The folder the file is in (`.` for a bare file name).
    pub fn dir(&self) -> Option<FilePath> {
        let p = self.as_path()?;
        Some(FilePath::new(
            p.parent()
                .filter(|d| !d.as_os_str().is_empty())
                .unwrap_or(Path::new(".")),
        ))
    }

    /// A path written inside this file (`domain "..."`, `import "..."`):
    /// relative to the file's folder unless absolute. Stdlib modules name
    /// no files.
    pub fn sibling(&self, written: impl AsRef<Path>) -> Option<FilePath> {
        let dir = self.dir()?;
        Some(FilePath::new(dir.as_path()?.join(written)))
    }

    /// The file name, e.g. `p01.plan`.
    pub fn file_name(&self) -> Option<&str> {
        self.as_path()?.file_name()?.to_str()
    }

    /// The file name up to its first dot: `p01` for `p01.plan` and
    /// `p01.sas_plan.1`.
    pub fn stem(&self) -> Option<&str> {
        let name = self.file_name()?;
        let stem = name.split('.').next().unwrap_or(name);
        (!stem.is_empty()).then_some(stem)
    }

    /// Whether the name ends in `ext` (without the dot).
    pub fn has_extension(&self, ext: &str) -> bool {
        self.as_path()
            .and_then(Path::extension)
            .is_some_and(|e| e == ext)
    }

    /// A rules file: `.btrules` on disk, or a stdlib module.
    pub fn is_rules(&self) -> bool {
        matches!(self, FilePath::Std(_)) || self.has_extension("btrules")
    }
}

impl fmt::Display for FilePath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            FilePath::Disk(p) => write!(f, "{}", p.display()),
            FilePath::Std(m) => write!(f, "std::{m}"),
        }
    }
}

impl fmt::Debug for FilePath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{self}")
    }
}

/// What names a file: a [`FilePath`], a path, or text (`std::NAME` is a
/// stdlib module, anything else a path). The database's lookups take
/// `&impl AsFilePath`, so `db.file("a/r.btrules")`, `db.file(&path_buf)` and
/// `db.file(&file_path)` all read naturally.
pub trait AsFilePath {
    fn to_file_path(&self) -> FilePath;
}

impl AsFilePath for FilePath {
    fn to_file_path(&self) -> FilePath {
        self.clone()
    }
}

impl AsFilePath for Path {
    fn to_file_path(&self) -> FilePath {
        FilePath::new(self)
    }
}

impl AsFilePath for PathBuf {
    fn to_file_path(&self) -> FilePath {
        FilePath::new(self)
    }
}

impl AsFilePath for str {
    fn to_file_path(&self) -> FilePath {
        match self.strip_prefix("std::") {
            Some(m) => FilePath::std(m),
            None => FilePath::new(self),
        }
    }
}

impl AsFilePath for String {
    fn to_file_path(&self) -> FilePath {
        self.as_str().to_file_path()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shown(p: &str) -> String {
        FilePath::new(p).to_string()
    }

    #[test]
    fn normalises_by_components() {
        assert_eq!(shown("a/./b/../c"), "a/c");
        assert_eq!(shown("./rules.btrules"), "rules.btrules");
        assert_eq!(shown("../x/../y/d.pddl"), "../y/d.pddl");
        assert_eq!(shown("a/../../b"), "../b");
        assert_eq!(shown("a//b"), "a/b");
        assert_eq!(shown("."), ".");
        assert_eq!(shown("a/.."), ".");
    }

    #[test]
    fn absolute_paths_keep_one_leading_separator() {
        assert_eq!(shown("/home/user/r.btrules"), "/home/user/r.btrules");
        assert_eq!(shown("/home/../.."), "/");
        assert_eq!(shown("/a/./b"), "/a/b");
    }

    #[test]
    fn siblings_resolve_against_the_folder() {
        let r = FilePath::new("examples/ariac/rules.btrules");
        assert_eq!(
            r.sibling("domain.pddl").unwrap(),
            FilePath::new("examples/ariac/domain.pddl")
        );
        assert_eq!(
            r.sibling("../p3/d.pddl").unwrap(),
            FilePath::new("examples/p3/d.pddl")
        );
        assert_eq!(
            FilePath::new("rules.btrules").sibling("d.pddl").unwrap(),
            FilePath::new("d.pddl")
        );
        assert_eq!(
            r.sibling("/abs/d.pddl").unwrap(),
            FilePath::new("/abs/d.pddl")
        );
        assert_eq!(FilePath::std("kb").sibling("x"), None);
    }

    #[test]
    fn stems_names_and_kinds() {
        let p = FilePath::new("corpus/blocks/p01.sas_plan.1");
        assert_eq!(p.file_name(), Some("p01.sas_plan.1"));
        assert_eq!(p.stem(), Some("p01"));
        assert!("std::kb".to_file_path().is_rules());
        assert_eq!("std::kb".to_file_path().to_string(), "std::kb");
        assert!(FilePath::new("a/r.btrules").is_rules());
        assert!(!FilePath::new("a/d.pddl").is_rules());
    }
}
