//! An input file named with its hash, and whether the repository's file still matches it.

use crate::fingerprint::fnv1a;
use serde::{Deserialize, Serialize};
use std::path::{Component, Path, PathBuf};

/// An input file and its hash.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Input {
    /// Path as the run resolved it, `.` and `..` folded; an absolute path inside the folder the
    /// run ran in is written relative to it, so that the same file reads the same however it was
    /// named and a results folder copied from another checkout still names its inputs.
    pub path: String,
    /// FNV-1a of its bytes.
    pub fnv1a: String,
    /// Its size.
    pub bytes: u64,
}

impl Input {
    /// `path` read and hashed now.
    pub fn read(path: &Path) -> std::io::Result<Input> {
        let bytes = std::fs::read(path)?;
        let tidied = tidy(path);
        let shown = std::env::current_dir()
            .ok()
            .and_then(|here| tidied.strip_prefix(tidy(&here)).ok().map(Path::to_path_buf))
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or(tidied);
        Ok(Input {
            path: shown.display().to_string(),
            fnv1a: format!("{:016x}", fnv1a(&bytes)),
            bytes: bytes.len() as u64,
        })
    }
}

/// `path` with `.` dropped and `a/..` folded, without touching the file system.
pub fn tidy(path: &Path) -> PathBuf {
    let mut out: Vec<Component> = Vec::new();
    for c in path.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir if matches!(out.last(), Some(Component::Normal(_))) => {
                out.pop();
            }
            c => out.push(c),
        }
    }
    out.iter().collect()
}

/// Why the input file a manifest lists no longer matches the repository's, if it does not. A
/// relative path is the run's, relative to the folder it ran in: the repository root, where
/// `results/` is.
pub(super) fn input_problem(input: &Input, repo: &Path) -> Option<String> {
    let recorded = tidy(Path::new(&input.path));
    let relative = if recorded.is_absolute() {
        match recorded.strip_prefix(repo) {
            Ok(r) => r.to_path_buf(),
            Err(_) => {
                return Some(format!(
                    "input `{}` was read outside this repository (run from its root with relative paths)",
                    input.path
                ))
            }
        }
    } else {
        recorded
    };
    if relative.components().next() == Some(Component::ParentDir) {
        return Some(format!(
            "input `{}` lies outside the repository (run from its root with relative paths)",
            input.path
        ));
    }
    match Input::read(&repo.join(&relative)) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            Some(format!("input `{}` no longer exists", relative.display()))
        }
        Err(e) => Some(format!("input `{}` cannot be read: {e}", relative.display())),
        Ok(current) => {
            let now = current.fnv1a;
            (now != input.fnv1a).then(|| {
                format!(
                    "input `{}` changed since the run (FNV-1a {} then, {now} now)",
                    relative.display(),
                    input.fnv1a
                )
            })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_are_folded() {
        assert_eq!(
            tidy(Path::new("experiments/scenes/../../assets/x.obj")),
            PathBuf::from("assets/x.obj")
        );
        assert_eq!(tidy(Path::new("./a/./b")), PathBuf::from("a/b"));
        assert_eq!(tidy(Path::new("../a")), PathBuf::from("../a"));
    }
}
