//! A results folder replaced as one set. A run writes its outputs into a staging folder beside
//! the results folder; only when it finishes does [`Outputs::commit`] move the state that
//! outlives runs (a sweep's journal, ground-truth cache and shards) across and exchange the two
//! folders in one step (`renameat2(RENAME_EXCHANGE)` on Linux). A failed or killed run leaves
//! the earlier set whole; a folder never mixes two runs.
//!
//! Names from an experiment file that become paths (the experiment's, its meshes') are plain
//! names ([`super::header::plain_name`]); files named after them are written through
//! [`Outputs::path`], which refuses anything that would leave the staging folder. The other
//! outputs have fixed names.

use crate::files::{check_plain_folder, check_plain_tree};
use anyhow::{bail, Context};
use std::fs::File;
use std::os::unix::fs::MetadataExt;
use std::path::{Component, Path, PathBuf};

/// Entries of a results folder that outlive a run and are carried into the new set.
pub const KEPT: [&str; 3] = [".journal", "cache", "shards"];

/// Where a run's outputs go until they replace the results folder.
#[derive(Debug)]
pub struct Outputs {
    home: PathBuf,
    staging: PathBuf,
    committed: bool,
    /// Where `staging` is a shard's own folder, which outlives the run and is never swapped in:
    /// the folders this run made for it (innermost first), taken away again if left empty.
    shard: Option<Vec<PathBuf>>,
    /// The results folder (exclusively) or a shard's folder (with the results folder shared),
    /// open and locked for as long as this run writes there; the first is the results folder.
    locks: Vec<FolderLock>,
}

/// The results folder a run will replace, as the real path its swap acts on: created if
/// missing (with its parents), followed through symbolic links, and refused when it is not a
/// folder or lies on another file system than its parent (a mount point: the swap is a rename,
/// which cannot cross file systems). `out` must end in a name (not `.` or `..`).
pub fn resolve_home(out: &Path) -> Result<PathBuf, String> {
    let last = out.as_os_str().as_encoded_bytes();
    let dotted = last.ends_with(b"/.") || last.ends_with(b"/..") || last == b"." || last == b"..";
    if dotted || out.file_name().is_none() {
        return Err(format!(
            "{}: the results folder must end in a folder name",
            out.display()
        ));
    }
    std::fs::create_dir_all(out).map_err(|e| format!("creating {}: {e}", out.display()))?;
    let home = out
        .canonicalize()
        .map_err(|e| format!("{}: cannot resolve: {e}", out.display()))?;
    if !home.is_dir() {
        return Err(format!("{}: not a folder", out.display()));
    }
    let parent = home.parent().unwrap_or(Path::new("/"));
    let dev = |p: &Path| std::fs::metadata(p).map(|m| m.dev()).ok();
    if dev(&home) != dev(parent) {
        return Err(format!(
            "{} is on another file system than {} (a mount point): results are swapped in by a rename, which cannot cross file systems; choose a folder inside it",
            home.display(),
            parent.display()
        ));
    }
    Ok(home)
}

/// Checks that kept state at `path`, if any, is a folder (not a link or a file) holding only
/// folders and regular files.
fn check_kept(path: &Path) -> anyhow::Result<()> {
    check_plain_folder(path)?;
    check_plain_tree(path)
}

/// How a run holds a folder: alone (a run that swaps the results folder, a merge, a shard in its
/// own folder) or beside others (shards in one results folder, which must not be swapped under
/// them).
#[derive(Clone, Copy)]
enum Hold {
    Alone,
    Shared,
}

/// A folder locked with `flock`, unlocked explicitly when dropped. Closing alone is not enough:
/// the lock belongs to the open file description, and a process another thread forks holds a
/// copy of every descriptor until it execs, so a folder released by closing could still read
/// as held by "another run" for that moment.
#[derive(Debug)]
struct FolderLock(File);

impl Drop for FolderLock {
    fn drop(&mut self) {
        use std::os::fd::AsRawFd;
        // SAFETY: a valid open descriptor; unlocking acts on the description, every copy.
        unsafe { libc::flock(self.0.as_raw_fd(), libc::LOCK_UN) };
    }
}

/// Locks `dir` for this run as `hold` says, or says which run holds it; the lock lasts as long
/// as the returned lock lives.
fn lock(dir: &Path, hold: Hold, held: &str) -> anyhow::Result<FolderLock> {
    use std::os::fd::AsRawFd;
    let file = File::open(dir).with_context(|| format!("opening {}", dir.display()))?;
    let how = match hold {
        Hold::Alone => libc::LOCK_EX,
        Hold::Shared => libc::LOCK_SH,
    };
    // SAFETY: a valid open descriptor.
    let rc = unsafe { libc::flock(file.as_raw_fd(), how | libc::LOCK_NB) };
    if rc != 0 {
        let e = std::io::Error::last_os_error();
        // Only "would block" means another run holds it; anything else (a file system that
        // cannot lock folders) is said as it is, not taken for a run that does not exist.
        if e.raw_os_error() == Some(libc::EWOULDBLOCK) {
            bail!("{}: {held}", dir.display());
        }
        bail!(
            "{}: cannot lock the folder for this run ({e}); results folders must be on a file system with flock",
            dir.display()
        );
    }
    Ok(FolderLock(file))
}

/// What a run refused by a held results folder is told.
const HOME_HELD: &str =
    "another run is writing into this results folder (a whole run, a merge or a shard); wait for it or choose another --out";

/// This host's name, for staging folders on file systems shared by several machines.
fn host() -> String {
    std::fs::read_to_string("/proc/sys/kernel/hostname")
        .map(|h| h.trim().to_string())
        .unwrap_or_else(|_| "host".into())
}

impl Outputs {
    /// A fresh staging folder for `home` (a folder [`resolve_home`] gave: `.NAME.staging.HOST.PID`
    /// beside it), with `home` locked against other runs; staging folders that killed runs of
    /// this host left behind are removed, after the state they were carrying over ([`KEPT`]) is
    /// moved back into `home` where `home` lacks it. Kept state holding a symbolic link or a
    /// special file, and a link or file named like a staging folder, are refused with their path
    /// before anything is moved or removed.
    pub fn begin(home: &Path) -> anyhow::Result<Outputs> {
        let lock = lock(home, Hold::Alone, HOME_HELD)?;
        let name = home
            .file_name()
            .map(|n| n.to_string_lossy())
            .with_context(|| format!("{}: the results folder needs a name", home.display()))?;
        let parent = home
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        std::fs::create_dir_all(parent).with_context(|| format!("creating {}", parent.display()))?;
        let prefix = format!(".{name}.staging.{}.", host());
        // Links and special files among the kept state would lead writes (the journal, a
        // cached ground truth) or reads outside the folder: refused before anything moves.
        for kept in KEPT {
            check_kept(&home.join(kept))?;
        }
        let mut dead = Vec::new();
        if let Ok(entries) = std::fs::read_dir(parent) {
            for e in entries.flatten() {
                let n = e.file_name().to_string_lossy().into_owned();
                let is_dead = n
                    .strip_prefix(&prefix)
                    .and_then(|pid| pid.parse::<u32>().ok())
                    .is_some_and(|pid| pid != std::process::id() && !Path::new(&format!("/proc/{pid}")).exists());
                if is_dead {
                    // Named like a killed run's staging folder: it must be one (a folder, its
                    // kept state plain), or the cleanup would follow a planted link.
                    check_plain_folder(&e.path())?;
                    for kept in KEPT {
                        check_kept(&e.path().join(kept))?;
                    }
                    dead.push(e.path());
                }
            }
        }
        for d in dead {
            for kept in KEPT {
                let (from, to) = (d.join(kept), home.join(kept));
                if from.exists() && std::fs::symlink_metadata(&to).is_err() {
                    let _ = std::fs::rename(&from, &to);
                }
            }
            let _ = std::fs::remove_dir_all(&d);
        }
        let staging = parent.join(format!("{prefix}{}", std::process::id()));
        if std::fs::symlink_metadata(&staging).is_ok() {
            check_plain_folder(&staging)?;
            std::fs::remove_dir_all(&staging).with_context(|| format!("clearing {}", staging.display()))?;
        }
        std::fs::create_dir(&staging).with_context(|| format!("creating {}", staging.display()))?;
        Ok(Outputs {
            home: home.to_path_buf(),
            staging,
            committed: false,
            shard: None,
            locks: vec![lock],
        })
    }

    /// The shard folder `dir` under `home`, written in place: locked alone (one run per shard),
    /// with `home` held shared, so shards of one results folder run side by side (one node's
    /// cores, or nodes sharing the folder) while no run swaps the folder under them or merges
    /// a shard still being written.
    pub fn begin_shard(home: &Path, dir: &Path) -> anyhow::Result<Outputs> {
        let replacing = "a run that replaces this results folder (a whole run or a merge) holds it; wait for it, then run the shard";
        let home_lock = lock(home, Hold::Shared, replacing)?;
        // The shared folders as folders, and only this shard's own tree: the other shards
        // write files into theirs and into the cache (read through checks of their own) while
        // it runs.
        for kept in ["cache", "shards"] {
            check_plain_folder(&home.join(kept))?;
        }
        let made = crate::files::missing_folders(dir);
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        check_kept(dir)?;
        let dir_lock = lock(dir, Hold::Alone, "another run is writing this shard; wait for it")?;
        Ok(Outputs {
            home: home.to_path_buf(),
            staging: dir.to_path_buf(),
            committed: false,
            shard: Some(made),
            locks: vec![home_lock, dir_lock],
        })
    }

    /// The staging folder.
    pub fn dir(&self) -> &Path {
        &self.staging
    }

    /// The results folder this set will replace.
    pub fn home(&self) -> &Path {
        &self.home
    }

    /// `relative` under the staging folder, refused unless it is made of plain components (no
    /// `..`, no root, no prefix): nothing is written outside the output folder.
    pub fn path(&self, relative: impl AsRef<Path>) -> anyhow::Result<PathBuf> {
        let r = relative.as_ref();
        if r.as_os_str().is_empty() || !r.components().all(|c| matches!(c, Component::Normal(_))) {
            bail!("refusing to write {}: outside the results folder", r.display());
        }
        Ok(self.staging.join(r))
    }

    /// Replaces the results folder with the staged set, carrying over [`KEPT`] entries; if the
    /// swap fails, the carried entries go back where they were and the earlier set stays.
    pub fn commit(mut self) -> anyhow::Result<()> {
        if self.shard.is_some() {
            bail!(
                "{}: a shard's folder is written in place, never swapped in",
                self.staging.display()
            );
        }
        self.check_home_held()?;
        if self.home.is_dir() {
            let mut moved = Vec::new();
            let carried = (|| -> anyhow::Result<()> {
                for kept in KEPT {
                    let from = self.home.join(kept);
                    if from.exists() {
                        let to = self.staging.join(kept);
                        if to.exists() {
                            std::fs::remove_dir_all(&to)?;
                        }
                        std::fs::rename(&from, &to).with_context(|| format!("moving {}", from.display()))?;
                        moved.push(kept);
                    }
                }
                exchange(&self.staging, &self.home)
            })();
            if let Err(e) = carried {
                for kept in moved {
                    let _ = std::fs::rename(self.staging.join(kept), self.home.join(kept));
                }
                return Err(e);
            }
            // The staging path now holds the earlier set.
            std::fs::remove_dir_all(&self.staging)
                .with_context(|| format!("removing the earlier results, now at {}", self.staging.display()))?;
        } else {
            std::fs::rename(&self.staging, &self.home)
                .with_context(|| format!("moving {} to {}", self.staging.display(), self.home.display()))?;
        }
        self.committed = true;
        Ok(())
    }
}

impl Outputs {
    /// Refuses a results folder whose path no longer names the folder this run locked (moved,
    /// or replaced by another folder or a link while the run went): nothing is swapped into
    /// what is there now, and the staged results stay where they are, named.
    fn check_home_held(&mut self) -> anyhow::Result<()> {
        use std::os::unix::fs::MetadataExt;
        let locked = self.locks[0].0.metadata()?;
        let now = std::fs::symlink_metadata(&self.home)
            .ok()
            .filter(|m| m.is_dir())
            .map(|m| (m.dev(), m.ino()));
        if now != Some((locked.dev(), locked.ino())) {
            self.committed = true;
            return Err(crate::files::Refused(format!(
                "{}: moved or replaced while the run went (it is not the folder this run locked); nothing was swapped in, and this run's results are left in {} (move them away before another run into this folder, which clears a killed run's staging folder)",
                self.home.display(),
                self.staging.display()
            ))
            .into());
        }
        Ok(())
    }
}

impl Drop for Outputs {
    fn drop(&mut self) {
        match &self.shard {
            Some(made) => crate::files::remove_empty(made),
            None if !self.committed => {
                let _ = std::fs::remove_dir_all(&self.staging);
            }
            None => {}
        }
    }
}

/// Swaps two folders atomically where the system can (Linux), else by two renames.
fn exchange(a: &Path, b: &Path) -> anyhow::Result<()> {
    #[cfg(target_os = "linux")]
    {
        use std::ffi::CString;
        use std::os::unix::ffi::OsStrExt;
        let (ca, cb) = (
            CString::new(a.as_os_str().as_bytes())?,
            CString::new(b.as_os_str().as_bytes())?,
        );
        // SAFETY: two valid NUL-terminated paths relative to the current folder.
        let rc = unsafe {
            libc::renameat2(
                libc::AT_FDCWD,
                ca.as_ptr(),
                libc::AT_FDCWD,
                cb.as_ptr(),
                libc::RENAME_EXCHANGE,
            )
        };
        if rc == 0 {
            return Ok(());
        }
    }
    let aside = a.with_extension("old");
    std::fs::rename(b, &aside).with_context(|| format!("moving {} aside", b.display()))?;
    std::fs::rename(a, b).with_context(|| format!("moving {} to {}", a.display(), b.display()))?;
    std::fs::rename(&aside, a).with_context(|| format!("moving {} back", aside.display()))?;
    Ok(())
}

/// Whether `home` may be replaced by a run of experiment `name` of `kind`: yes when it does not
/// exist, holds only [`KEPT`] state, or holds a manifest of the same experiment; with `fresh`,
/// also when it holds another experiment's results. A folder with files but no manifest is never
/// a results folder: it is refused.
pub fn check_home(home: &Path, kind: &str, name: &str, experiment: &Path, fresh: bool) -> Result<(), String> {
    let Ok(entries) = std::fs::read_dir(home) else {
        return if home.exists() {
            Err(format!("{}: exists and is not a readable folder", home.display()))
        } else {
            Ok(())
        };
    };
    let names: Vec<String> = entries
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    if names.iter().all(|n| KEPT.contains(&n.as_str())) {
        return Ok(());
    }
    let manifest = home.join("manifest.toml");
    let text = match crate::files::read_regular_text(&manifest) {
        Ok(text) => Some(text),
        // A link, pipe or folder by that name: say so.
        Err(e) if std::fs::symlink_metadata(&manifest).is_ok() => return Err(format!("{e:#}")),
        Err(_) => None,
    };
    let Some(table) = text.and_then(|t| t.parse::<toml::Table>().ok()) else {
        return Err(format!(
            "{} holds files but no readable manifest.toml: not a results folder; choose another --out",
            home.display()
        ));
    };
    let text = |k: &str| table.get(k).and_then(|v| v.as_str()).map(str::to_string);
    let same = match (text("kind"), text("name")) {
        (Some(k), Some(n)) => k == kind && n == name,
        // A manifest from before kinds were recorded: the same experiment file.
        _ => table
            .get("experiment")
            .and_then(|v| v.as_str().or_else(|| v.get("path").and_then(|p| p.as_str())))
            .is_some_and(|p| super::manifest::tidy(Path::new(p)) == super::manifest::tidy(experiment)),
    };
    if same || fresh {
        Ok(())
    } else {
        Err(format!(
            "{} holds the results of another experiment ({}); pass --fresh to replace them, or choose another --out",
            home.display(),
            match (text("kind"), text("name")) {
                (Some(k), Some(n)) => format!("kind `{k}`, name `{n}`"),
                _ => "an earlier manifest".into(),
            }
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_run_side_by_side_but_never_beside_a_run_that_replaces_the_folder() {
        let dir = tempfile::tempdir().unwrap();
        let home = dir.path().join("r");
        std::fs::create_dir_all(&home).unwrap();
        let (one, two) = (home.join("shards/1-of-2"), home.join("shards/2-of-2"));
        let first = Outputs::begin_shard(&home, &one).unwrap();
        let second = Outputs::begin_shard(&home, &two).unwrap();
        let again = Outputs::begin_shard(&home, &one).unwrap_err().to_string();
        assert!(again.contains("another run is writing this shard"), "{again}");
        let whole = Outputs::begin(&home).unwrap_err().to_string();
        assert!(
            whole.contains("another run is writing into this results folder"),
            "{whole}"
        );
        // A shard's folder outlives its run: nothing is removed, and it is never swapped in.
        std::fs::write(one.join("unit.toml"), b"kept").unwrap();
        assert!(first.commit().is_err());
        drop(second);
        assert_eq!(std::fs::read(one.join("unit.toml")).unwrap(), b"kept");
        let merge = Outputs::begin(&home).unwrap();
        let shard = Outputs::begin_shard(&home, &two).unwrap_err().to_string();
        assert!(shard.contains("a whole run or a merge"), "{shard}");
        drop(merge);
        Outputs::begin_shard(&home, &two).unwrap();
    }

    #[test]
    fn a_dropped_lock_is_free_while_a_forked_process_still_holds_its_descriptor() {
        let dir = tempfile::tempdir().unwrap();
        let held = lock(dir.path(), Hold::Alone, "held").unwrap();
        // SAFETY: the child only sleeps and exits (async-signal-safe calls) before it would exec.
        let child = unsafe { libc::fork() };
        assert!(child >= 0, "fork failed");
        if child == 0 {
            unsafe {
                libc::sleep(2);
                libc::_exit(0);
            }
        }
        drop(held);
        let again = lock(dir.path(), Hold::Alone, "held");
        let mut status = 0;
        unsafe { libc::waitpid(child, &mut status, 0) };
        again.unwrap();
    }

    #[test]
    fn a_results_folder_replaced_during_the_run_gets_nothing_and_the_new_set_stays_staged() {
        let dir = tempfile::tempdir().unwrap();
        let home = dir.path().join("r");
        std::fs::create_dir_all(&home).unwrap();
        std::fs::write(home.join("old.csv"), b"old").unwrap();
        let out = Outputs::begin(&home).unwrap();
        std::fs::write(out.path("new.csv").unwrap(), b"new").unwrap();
        let staging = out.dir().to_path_buf();
        std::fs::rename(&home, dir.path().join("r-moved")).unwrap();
        std::fs::create_dir(&home).unwrap();
        std::fs::write(home.join("theirs"), b"theirs").unwrap();
        let e = out.commit().unwrap_err().to_string();
        assert!(e.contains("moved or replaced while the run went"), "{e}");
        assert!(e.contains(&staging.display().to_string()), "{e}");
        let names: Vec<_> = std::fs::read_dir(&home)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names, ["theirs"], "swapped into the folder put there");
        assert_eq!(
            std::fs::read(staging.join("new.csv")).unwrap(),
            b"new",
            "the new set is kept"
        );
        assert_eq!(std::fs::read(dir.path().join("r-moved/old.csv")).unwrap(), b"old");
    }

    #[test]
    fn a_committed_set_replaces_the_old_and_keeps_state() {
        let dir = tempfile::tempdir().unwrap();
        let home = dir.path().join("r");
        std::fs::create_dir_all(home.join("cache")).unwrap();
        std::fs::write(home.join("cache/gt"), b"cached").unwrap();
        std::fs::write(home.join("old.csv"), b"old").unwrap();
        let out = Outputs::begin(&home).unwrap();
        std::fs::write(out.path("new.csv").unwrap(), b"new").unwrap();
        assert!(home.join("old.csv").exists(), "nothing replaced before the commit");
        out.commit().unwrap();
        assert!(!home.join("old.csv").exists());
        assert_eq!(std::fs::read(home.join("new.csv")).unwrap(), b"new");
        assert_eq!(std::fs::read(home.join("cache/gt")).unwrap(), b"cached");
        let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert_eq!(left.len(), 1, "no staging folder left: {left:?}");
    }

    #[test]
    fn a_killed_runs_carried_state_comes_back() {
        let dir = tempfile::tempdir().unwrap();
        let home = dir.path().join("r");
        std::fs::create_dir_all(&home).unwrap();
        // A staging folder of this host whose process is gone, holding the journal it carried.
        let dead = dir.path().join(format!(".r.staging.{}.{}", host(), u32::MAX - 1));
        std::fs::create_dir_all(dead.join(".journal")).unwrap();
        std::fs::write(dead.join(".journal/groups.csv"), b"journaled").unwrap();
        let out = Outputs::begin(&home).unwrap();
        assert!(!dead.exists());
        assert_eq!(std::fs::read(home.join(".journal/groups.csv")).unwrap(), b"journaled");
        drop(out);
    }

    #[test]
    fn planted_links_are_refused_and_nothing_outside_moves() {
        let dir = tempfile::tempdir().unwrap();
        let home = dir.path().join("r");
        std::fs::create_dir_all(&home).unwrap();
        // A foreign folder holding what a staging folder would carry, and a link to it named
        // like a killed run's staging folder.
        let foreign = dir.path().join("foreign");
        std::fs::create_dir_all(foreign.join(".journal")).unwrap();
        std::fs::create_dir_all(foreign.join("cache")).unwrap();
        std::fs::write(foreign.join(".journal/groups.csv"), b"theirs").unwrap();
        let planted = dir.path().join(format!(".r.staging.{}.{}", host(), u32::MAX - 1));
        std::os::unix::fs::symlink(&foreign, &planted).unwrap();
        let e = Outputs::begin(&home).unwrap_err().to_string();
        assert!(
            e.contains(&planted.display().to_string()) && e.contains("symbolic link"),
            "{e}"
        );
        assert_eq!(std::fs::read(foreign.join(".journal/groups.csv")).unwrap(), b"theirs");
        assert!(foreign.join("cache").is_dir() && !home.join(".journal").exists());
        std::fs::remove_file(&planted).unwrap();
        // Kept state that is a link, or holds one, or a pipe.
        std::os::unix::fs::symlink(&foreign, home.join("cache")).unwrap();
        let e = Outputs::begin(&home).unwrap_err().to_string();
        assert!(e.contains("r/cache") && e.contains("symbolic link"), "{e}");
        std::fs::remove_file(home.join("cache")).unwrap();
        std::fs::create_dir_all(home.join("shards/1-of-2/.journal")).unwrap();
        std::os::unix::fs::symlink(
            foreign.join(".journal/groups.csv"),
            home.join("shards/1-of-2/.journal/groups.csv"),
        )
        .unwrap();
        let e = Outputs::begin(&home).unwrap_err().to_string();
        assert!(e.contains("groups.csv"), "{e}");
        std::fs::remove_file(home.join("shards/1-of-2/.journal/groups.csv")).unwrap();
        assert!(Outputs::begin(&home).is_ok(), "plain state is accepted");
        assert_eq!(std::fs::read(foreign.join(".journal/groups.csv")).unwrap(), b"theirs");
    }

    #[test]
    fn an_abandoned_set_leaves_the_old_whole() {
        let dir = tempfile::tempdir().unwrap();
        let home = dir.path().join("r");
        std::fs::create_dir_all(&home).unwrap();
        std::fs::write(home.join("old.csv"), b"old").unwrap();
        {
            let out = Outputs::begin(&home).unwrap();
            std::fs::write(out.path("new.csv").unwrap(), b"new").unwrap();
        }
        assert_eq!(std::fs::read(home.join("old.csv")).unwrap(), b"old");
        assert!(!home.join("new.csv").exists());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn paths_stay_under_the_folder() {
        let dir = tempfile::tempdir().unwrap();
        let out = Outputs::begin(&resolve_home(&dir.path().join("r")).unwrap()).unwrap();
        for bad in ["../x", "/abs", "a/../../b", "", "."] {
            assert!(out.path(bad).is_err(), "{bad}");
        }
        assert!(out.path("images/a.png").unwrap().starts_with(out.dir()));
    }

    #[test]
    fn a_results_folder_is_resolved_to_the_folder_its_swap_acts_on() {
        let dir = tempfile::tempdir().unwrap();
        let made = resolve_home(&dir.path().join("a/b")).unwrap();
        assert!(made.is_dir() && made.ends_with("a/b"), "parents made");
        for bad in ["a/.", "a/..", "."] {
            let e = resolve_home(&dir.path().join(bad)).unwrap_err();
            assert!(e.contains("must end in a folder name"), "{bad}: {e}");
        }
        std::os::unix::fs::symlink(dir.path().join("a/b"), dir.path().join("link")).unwrap();
        assert_eq!(resolve_home(&dir.path().join("link")).unwrap(), made, "links followed");
        std::fs::write(dir.path().join("file"), b"x").unwrap();
        assert!(resolve_home(&dir.path().join("file")).is_err(), "a file is no folder");
        // One run at a time.
        let first = Outputs::begin(&made).unwrap();
        let e = Outputs::begin(&made).unwrap_err().to_string();
        assert!(e.contains("another run is writing"), "{e}");
        drop(first);
        assert!(Outputs::begin(&made).is_ok());
    }

    #[test]
    fn homes_holding_something_else_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let home = dir.path().join("r");
        let e = Path::new("e.toml");
        assert!(check_home(&home, "ao", "r", e, false).is_ok(), "new folder");
        std::fs::create_dir_all(home.join(".journal")).unwrap();
        assert!(check_home(&home, "ao", "r", e, false).is_ok(), "state only");
        std::fs::write(home.join("notes.txt"), b"mine").unwrap();
        assert!(check_home(&home, "ao", "r", e, true).is_err(), "no manifest: never");
        std::fs::write(home.join("manifest.toml"), "kind = \"sweep\"\nname = \"r\"\n").unwrap();
        assert!(check_home(&home, "ao", "r", e, false).is_err(), "another kind");
        assert!(check_home(&home, "ao", "r", e, true).is_ok(), "--fresh replaces it");
        assert!(check_home(&home, "sweep", "r", e, false).is_ok(), "the same experiment");
        std::fs::write(home.join("manifest.toml"), "experiment = \"e.toml\"\n").unwrap();
        assert!(
            check_home(&home, "ao", "r", e, false).is_ok(),
            "an older manifest of the same file"
        );
        assert!(check_home(&home, "ao", "r", Path::new("f.toml"), false).is_err());
        // A manifest that is a pipe is refused as one, at once.
        std::fs::remove_file(home.join("manifest.toml")).unwrap();
        let made = std::process::Command::new("mkfifo")
            .arg(home.join("manifest.toml"))
            .status();
        assert!(made.unwrap().success());
        let e = check_home(&home, "ao", "r", e, true).unwrap_err();
        assert!(e.contains("manifest.toml") && e.contains("named pipe"), "{e}");
    }
}
