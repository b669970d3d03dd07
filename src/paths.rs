//! Paths a JSON IR records: relative to the file that records them, so a
//! compiled tree moves with its PDDL files (`cd out && btc run --tree
//! p01.json`). Lexical only: nothing here touches the file system but the
//! working directory.

use std::path::{Component, Path, PathBuf};

/// `p` absolute (against the working directory) with `.` and `..` folded.
fn absolute(p: &Path) -> PathBuf {
    let joined = if p.is_absolute() {
        p.to_path_buf()
    } else {
        std::env::current_dir().unwrap_or_default().join(p)
    };
    let mut out = PathBuf::new();
    for c in joined.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                out.pop();
            }
            other => out.push(other),
        }
    }
    out
}

/// `path` as seen from the folder `base`.
pub fn relative_to(path: &Path, base: &Path) -> PathBuf {
    let (p, b) = (absolute(path), absolute(base));
    let (pc, bc): (Vec<Component>, Vec<Component>) =
        (p.components().collect(), b.components().collect());
    let common = pc.iter().zip(&bc).take_while(|(x, y)| x == y).count();
    if common == 0 {
        return p; // another root (a Windows drive): keep it absolute
    }
    let mut out = PathBuf::new();
    for _ in common..bc.len() {
        out.push("..");
    }
    for c in &pc[common..] {
        out.push(c);
    }
    out
}

/// A path recorded in `file`: relative ones are relative to its folder.
pub fn beside(file: &Path, recorded: &str) -> PathBuf {
    let p = Path::new(recorded);
    if p.is_absolute() {
        return p.to_path_buf();
    }
    file.parent().unwrap_or(Path::new("")).join(p)
}

/// A path as text with `/` separators, as btc records paths.
pub fn text(p: &Path) -> String {
    p.to_string_lossy().replace('\\', "/")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_paths_go_up_and_down() {
        assert_eq!(
            relative_to(Path::new("/a/b/domain.pddl"), Path::new("/a/out")),
            PathBuf::from("../b/domain.pddl")
        );
        assert_eq!(
            relative_to(Path::new("/a/b/./x/../domain.pddl"), Path::new("/a/b")),
            PathBuf::from("domain.pddl")
        );
        assert_eq!(text(Path::new("/home/u/d.pddl")), "/home/u/d.pddl");
        assert_eq!(text(Path::new("x/y.pddl")), "x/y.pddl");
    }

    #[test]
    fn recorded_paths_are_read_beside_their_file() {
        assert_eq!(
            beside(Path::new("out/p01.json"), "../ex/domain.pddl"),
            PathBuf::from("out/../ex/domain.pddl")
        );
        assert_eq!(
            beside(Path::new("p.json"), "/abs/d.pddl"),
            PathBuf::from("/abs/d.pddl")
        );
    }
}
