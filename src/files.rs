//! Writing results without ever leaving a half-written file: write a temporary file beside the
//! target, flush it to disk, then rename it over the target (atomic on POSIX file systems). The
//! temporary file is named after the host, the process and its start, so writers on several
//! machines sharing a folder (shards filling one ground-truth cache) never write into each
//! other's temporary file.
//!
//! What a run reads back from a folder it writes into (a results folder's journal, cache and
//! shards; the files the `page` binary rebuilds a page from) is read only from folders and
//! regular files, never through a symbolic link and never from a pipe or device: a link planted
//! there would make a run read or write outside the folder, a pipe would block it for ever.

use anyhow::Context;
use std::io::{Read, Write};
use std::path::Path;

/// Writes `bytes` to `path` atomically, creating parent folders.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> anyhow::Result<()> {
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let tmp = temporary(path);
    let result = (|| {
        // A fresh file: never one (or a link) already at the temporary name.
        let mut f = std::fs::OpenOptions::new().write(true).create_new(true).open(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result.with_context(|| format!("writing {}", path.display()))
}

/// The folders missing on the way to `path`, `path` first: those a `create_dir_all(path)` would
/// make, and a failed run should take away again ([`remove_empty`]).
pub fn missing_folders(path: &Path) -> Vec<std::path::PathBuf> {
    path.ancestors()
        .take_while(|p| !p.as_os_str().is_empty() && std::fs::symlink_metadata(p).is_err())
        .map(Path::to_path_buf)
        .collect()
}

/// Removes `folders` (innermost first) that are empty, stopping at the first that is not.
pub fn remove_empty(folders: &[std::path::PathBuf]) {
    for p in folders {
        if std::fs::remove_dir(p).is_err() {
            break;
        }
    }
}

/// A folder a run writes into, held open for the run: every file is created and replaced
/// through the handle (`openat` and `renameat`, never following a link), so a folder swapped for
/// a link to somewhere else while the run goes is never written through; [`Folder::check_held`]
/// then says so before anything reads the swapped path.
pub struct Folder {
    path: std::path::PathBuf,
    handle: std::fs::File,
    identity: (u64, u64),
    /// The folders `create` made, innermost first.
    made: Vec<std::path::PathBuf>,
}

impl Folder {
    /// Creates `path` (and its parents) where missing and holds it; a link or a non-folder
    /// there is refused.
    pub fn create(path: &Path) -> anyhow::Result<Folder> {
        use std::os::unix::fs::{MetadataExt, OpenOptionsExt};
        check_plain_folder(path)?;
        let made = missing_folders(path);
        std::fs::create_dir_all(path).with_context(|| format!("creating {}", path.display()))?;
        let handle = std::fs::OpenOptions::new()
            .read(true)
            .custom_flags(libc::O_DIRECTORY | libc::O_NOFOLLOW)
            .open(path)
            .map_err(|e| Refused(format!("{}: cannot hold it as a folder: {e}", path.display())))?;
        let m = handle.metadata()?;
        let folder = Folder {
            path: path.to_path_buf(),
            handle,
            identity: (m.dev(), m.ino()),
            made,
        };
        folder.remove_dead_temporaries();
        Ok(folder)
    }

    /// Removes the temporary files that runs of this host killed mid-write left here (their
    /// processes are gone, and the file has not changed for [`DEAD_TEMPORARY_AGE`]); another
    /// host's, or a live process's, stay. Best effort: shards opening one cache at once race to
    /// remove the same file, and a leftover never stops a run.
    fn remove_dead_temporaries(&self) {
        let host = host();
        let Ok(names) = self.names() else { return };
        for name in names.into_iter().filter(|n| dead_temporary(n, &host)) {
            let old = self
                .metadata(&name)
                .and_then(|m| m.modified().ok())
                .and_then(|t| t.elapsed().ok())
                .is_some_and(|age| age > DEAD_TEMPORARY_AGE);
            if old {
                let _ = self.unlink(&name);
            }
        }
    }

    /// The metadata of the folder's entry `name` (not followed if a link), through the handle.
    fn metadata(&self, name: &str) -> Option<std::fs::Metadata> {
        use std::os::fd::AsRawFd;
        std::fs::symlink_metadata(format!("/proc/self/fd/{}/{name}", self.handle.as_raw_fd())).ok()
    }

    /// Whether the folder's entry `name` is a folder (not a link to one): what
    /// [`Folder::write_atomic`] cannot rename a file over.
    pub fn holds_folder(&self, name: &str) -> bool {
        self.metadata(name).is_some_and(|m| m.is_dir())
    }

    /// The names of the folder's files (not folders) with UTF-8 names, listed through the handle.
    fn names(&self) -> anyhow::Result<Vec<String>> {
        use std::os::fd::AsRawFd;
        let listed = std::fs::read_dir(format!("/proc/self/fd/{}", self.handle.as_raw_fd()))
            .with_context(|| format!("listing {}", self.path.display()))?;
        let mut names = Vec::new();
        for entry in listed {
            let entry = entry?;
            if !entry.file_type()?.is_dir() {
                names.extend(entry.file_name().to_str().map(str::to_string));
            }
        }
        Ok(names)
    }

    /// Removes the folder's file `name` through the handle; one already gone is no error.
    fn unlink(&self, name: &str) -> anyhow::Result<()> {
        use std::os::fd::AsRawFd;
        let c = self.component(name)?;
        // SAFETY: unlinkat on the held descriptor with a NUL-terminated name.
        if unsafe { libc::unlinkat(self.handle.as_raw_fd(), c.as_ptr(), 0) } != 0 {
            let e = std::io::Error::last_os_error();
            if e.raw_os_error() == Some(libc::ENOENT) {
                return Ok(());
            }
            return Err(e).with_context(|| format!("removing {}", self.path.join(name).display()));
        }
        Ok(())
    }

    /// Removes the folders `create` made (the folder and the parents it had to make) where
    /// they are still empty and the folder is still the one held: what a failed step leaves
    /// when it wrote nothing (anything written stays, for a resume).
    pub fn remove_if_made_and_empty(&self) {
        if self.check_held().is_ok() {
            remove_empty(&self.made);
        }
    }

    /// The path the folder was opened at.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Refuses a folder whose path no longer names the folder held: swapped for a link, moved
    /// or replaced while the run went.
    pub fn check_held(&self) -> anyhow::Result<()> {
        use std::os::unix::fs::MetadataExt;
        let now = std::fs::symlink_metadata(&self.path)
            .ok()
            .filter(|m| m.file_type().is_dir())
            .map(|m| (m.dev(), m.ino()));
        if now != Some(self.identity) {
            use std::os::fd::AsRawFd;
            // Where the held folder is now: renamed (it or a folder above it), or deleted.
            let moved = std::fs::read_link(format!("/proc/self/fd/{}", self.handle.as_raw_fd()))
                .ok()
                .filter(|p| p.exists() && *p != self.path);
            let what = match moved {
                Some(p) => format!("moved to {} (it or a folder above it was renamed)", p.display()),
                None => "replaced (by a link, or another folder)".to_string(),
            };
            return Err(Refused(format!(
                "{}: {what} while the run was writing into it; refused, and nothing was written into what is there now",
                self.path.display()
            ))
            .into());
        }
        Ok(())
    }

    /// `name` (one path component) as a C string.
    fn component(&self, name: &str) -> anyhow::Result<std::ffi::CString> {
        anyhow::ensure!(
            !name.is_empty() && !name.contains('/') && name != "." && name != "..",
            "{}: `{name}` is not a file name",
            self.path.display()
        );
        Ok(std::ffi::CString::new(name)?)
    }

    /// Writes `bytes` to the folder's file `name` atomically (a fresh temporary file, flushed,
    /// renamed over it), through the handle; then checks the folder is still the one held.
    pub fn write_atomic(&self, name: &str, bytes: &[u8]) -> anyhow::Result<()> {
        use std::os::fd::{AsRawFd, FromRawFd};
        let target = self.component(name)?;
        let tmp_name = temporary(Path::new(name));
        let tmp = self.component(&tmp_name.to_string_lossy())?;
        let dir = self.handle.as_raw_fd();
        let result = (|| -> std::io::Result<()> {
            // SAFETY: openat on a held folder's descriptor and a NUL-terminated name; the
            // descriptor it returns is owned by the File made from it.
            let fd = unsafe {
                libc::openat(
                    dir,
                    tmp.as_ptr(),
                    libc::O_WRONLY | libc::O_CREAT | libc::O_EXCL | libc::O_NOFOLLOW | libc::O_CLOEXEC,
                    0o644,
                )
            };
            if fd < 0 {
                return Err(std::io::Error::last_os_error());
            }
            let mut f = unsafe { std::fs::File::from_raw_fd(fd) };
            f.write_all(bytes)?;
            f.sync_all()?;
            // SAFETY: both names are NUL-terminated and relative to the held descriptor.
            if unsafe { libc::renameat(dir, tmp.as_ptr(), dir, target.as_ptr()) } != 0 {
                return Err(std::io::Error::last_os_error());
            }
            Ok(())
        })();
        if result.is_err() {
            // SAFETY: as above; a temporary file that is not there is no error worth reporting.
            unsafe { libc::unlinkat(dir, tmp.as_ptr(), 0) };
        }
        result.with_context(|| format!("writing {}", self.path.join(name).display()))?;
        self.check_held()
    }

    /// The bytes of the folder's regular file `name`, read through the handle (a link, pipe or
    /// device there refused as [`open_regular`] refuses it); none where there is no such file.
    pub fn read(&self, name: &str) -> anyhow::Result<Option<Vec<u8>>> {
        use std::os::fd::{AsRawFd, FromRawFd};
        let c = self.component(name)?;
        let shown = self.path.join(name);
        // SAFETY: openat on the held descriptor with a NUL-terminated name; the descriptor it
        // returns is owned by the File made from it.
        let fd = unsafe {
            libc::openat(
                self.handle.as_raw_fd(),
                c.as_ptr(),
                libc::O_RDONLY | libc::O_NOFOLLOW | libc::O_NONBLOCK | libc::O_CLOEXEC,
            )
        };
        let opened = if fd < 0 {
            let e = std::io::Error::last_os_error();
            if e.raw_os_error() == Some(libc::ENOENT) {
                return Ok(None);
            }
            Err(e)
        } else {
            // SAFETY: a descriptor openat just returned, owned by nothing else.
            Ok(unsafe { std::fs::File::from_raw_fd(fd) })
        };
        let mut file = regular(opened, &shown)?;
        let mut bytes = Vec::new();
        file.read_to_end(&mut bytes)
            .with_context(|| format!("reading {}", shown.display()))?;
        Ok(Some(bytes))
    }

    /// Removes every file of the folder not named in `keep`, listed and unlinked through the
    /// handle (a folder swapped while the run went is refused first); folders in it, and files
    /// whose names are not UTF-8, are left.
    pub fn remove_all_but(&self, keep: &std::collections::HashSet<String>) -> anyhow::Result<()> {
        self.check_held()?;
        for name in self.names()? {
            if !keep.contains(&name) {
                self.unlink(&name)?;
            }
        }
        Ok(())
    }
}

/// A path refused as a place to read or write (a link, pipe, device or folder where a regular
/// file or a plain folder belongs): bad input, exit status 2.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct Refused(pub String);

/// Opens `path` for reading if it is a regular file: a final symbolic link is not followed and a
/// pipe, device or folder is refused before anything is read (the open does not block).
pub fn open_regular(path: &Path) -> anyhow::Result<std::fs::File> {
    use std::os::unix::fs::OpenOptionsExt;
    let opened = std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK)
        .open(path);
    regular(opened, path)
}

/// The file an open of `path` that did not follow a final link gave, where it is a regular file:
/// a link (the open's ELOOP), a failed open, or a pipe, device or folder is refused.
fn regular(opened: std::io::Result<std::fs::File>, path: &Path) -> anyhow::Result<std::fs::File> {
    let file = opened.map_err(|e| match e.raw_os_error() {
        Some(libc::ELOOP) => Refused(format!(
            "{}: a symbolic link; refused (it could lead outside the folder)",
            path.display()
        )),
        _ => Refused(format!("{}: cannot open: {e}", path.display())),
    })?;
    let kind = file
        .metadata()
        .with_context(|| format!("{}: cannot read its metadata", path.display()))?
        .file_type();
    if !kind.is_file() {
        return Err(Refused(format!(
            "{}: not a regular file ({}); refused",
            path.display(),
            describe(kind)
        ))
        .into());
    }
    Ok(file)
}

/// The bytes of the regular file `path` ([`open_regular`]).
pub fn read_regular(path: &Path) -> anyhow::Result<Vec<u8>> {
    let mut bytes = Vec::new();
    open_regular(path)?
        .read_to_end(&mut bytes)
        .with_context(|| format!("reading {}", path.display()))?;
    Ok(bytes)
}

/// The text of the regular file `path` ([`open_regular`]); bytes that are not UTF-8 are refused
/// naming the offset of the first.
pub fn read_regular_text(path: &Path) -> anyhow::Result<String> {
    read_regular_text_at_most(path, u64::MAX)
}

/// [`read_regular_text`] of a file of at most `max` bytes: a longer one is refused from its
/// length, before anything is read (and one that grows while it is read, at `max`).
pub fn read_regular_text_at_most(path: &Path, max: u64) -> anyhow::Result<String> {
    let file = open_regular(path)?;
    let length = file.metadata()?.len();
    let too_long = |length: u64| {
        Refused(format!(
            "{}: {length} bytes, over the {max} bytes a text here may take; refused",
            path.display()
        ))
    };
    if length > max {
        return Err(too_long(length).into());
    }
    let mut bytes = Vec::new();
    file.take(max.saturating_add(1))
        .read_to_end(&mut bytes)
        .with_context(|| format!("reading {}", path.display()))?;
    if bytes.len() as u64 > max {
        return Err(too_long(bytes.len() as u64).into());
    }
    String::from_utf8(bytes).map_err(|e| {
        Refused(format!(
            "{}: not UTF-8 text (byte {} starts an invalid sequence); refused",
            path.display(),
            e.utf8_error().valid_up_to()
        ))
        .into()
    })
}

/// Checks that `root`, if it exists, and everything under it are folders and regular files: no
/// symbolic link (which a write or a removal would follow out of the tree), pipe, socket or
/// device. The error names the first offending path.
pub fn check_plain_tree(root: &Path) -> anyhow::Result<()> {
    let mut stack = vec![root.to_path_buf()];
    while let Some(p) = stack.pop() {
        let kind = match std::fs::symlink_metadata(&p) {
            Ok(m) => m.file_type(),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound && p == root => return Ok(()),
            Err(e) => anyhow::bail!("{}: cannot read its metadata: {e}", p.display()),
        };
        if kind.is_dir() {
            for e in std::fs::read_dir(&p).with_context(|| format!("listing {}", p.display()))? {
                stack.push(e.with_context(|| format!("listing {}", p.display()))?.path());
            }
        } else if !kind.is_file() {
            return Err(Refused(format!(
                "{}: {}, where only folders and regular files belong; remove it",
                p.display(),
                describe(kind)
            ))
            .into());
        }
    }
    Ok(())
}

/// Checks that `dir`, if it exists, is a folder itself, not a symbolic link to one (or a file).
pub fn check_plain_folder(dir: &Path) -> anyhow::Result<()> {
    match std::fs::symlink_metadata(dir) {
        Ok(m) if m.file_type().is_dir() => Ok(()),
        Ok(m) => Err(Refused(format!(
            "{}: {}, not a folder; refused",
            dir.display(),
            describe(m.file_type())
        ))
        .into()),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(e) => anyhow::bail!("{}: cannot read its metadata: {e}", dir.display()),
    }
}

/// A file type in a few words, for refusals.
fn describe(kind: std::fs::FileType) -> &'static str {
    use std::os::unix::fs::FileTypeExt;
    if kind.is_symlink() {
        "a symbolic link"
    } else if kind.is_dir() {
        "a folder"
    } else if kind.is_fifo() {
        "a named pipe"
    } else if kind.is_socket() {
        "a socket"
    } else if kind.is_block_device() || kind.is_char_device() {
        "a device"
    } else if kind.is_file() {
        "a regular file"
    } else {
        "not a regular file"
    }
}

/// A word from an input file as an error message may show it: quoted when it reads as a number
/// (digits, sign, point, exponent, or `nan` and `inf`), else only described. Naming the wrong
/// file (a points path that reaches a system file) then never prints what that file holds.
pub fn shown(word: &str) -> String {
    let numeric = !word.is_empty()
        && word.len() <= 32
        && (word.parse::<f64>().is_ok()
            || word
                .chars()
                .all(|c| c.is_ascii_digit() || matches!(c, '+' | '-' | '.' | 'e' | 'E')));
    if numeric {
        format!("`{word}`")
    } else {
        format!("a word of {} characters", word.chars().count())
    }
}

/// This host's name, as temporary files carry it.
fn host() -> String {
    std::fs::read_to_string("/proc/sys/kernel/hostname")
        .ok()
        .or_else(|| std::env::var("HOSTNAME").ok())
        .map_or_else(|| "host".to_string(), |h| h.trim().to_string())
}

/// How long a temporary file of a process that is gone must have been left unchanged before it
/// is taken for a killed run's: a process of this host name in another PID namespace (a
/// container sharing the host's name) is not in this `/proc`, yet writes and renames its
/// temporary within seconds.
const DEAD_TEMPORARY_AGE: std::time::Duration = std::time::Duration::from_secs(3600);

/// Whether `name` is a temporary file ([`temporary`]) of a process of this host that is gone:
/// what a killed run left half-written.
fn dead_temporary(name: &str, host: &str) -> bool {
    let Some(rest) = name.strip_prefix('.').and_then(|n| n.strip_suffix(".tmp")) else {
        return false;
    };
    let mut parts = rest.rsplitn(3, '.');
    let (Some(started), Some(pid), Some(before)) = (parts.next(), parts.next(), parts.next()) else {
        return false;
    };
    u128::from_str_radix(started, 16).is_ok()
        && before.ends_with(&format!(".{host}"))
        && pid
            .parse::<u32>()
            .is_ok_and(|pid| pid != std::process::id() && !Path::new(&format!("/proc/{pid}")).exists())
}

/// This host's and process's temporary file for `path`, beside it.
fn temporary(path: &Path) -> std::path::PathBuf {
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("out");
    let host = host();
    // The process's start time tells apart processes of one host name and id (containers).
    static STARTED: std::sync::OnceLock<u128> = std::sync::OnceLock::new();
    let started = STARTED.get_or_init(|| {
        std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos())
    });
    path.with_file_name(format!(".{name}.{host}.{}.{started:x}.tmp", std::process::id()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_killed_runs_temporaries_are_removed_and_no_one_elses() {
        let dir = tempfile::tempdir().unwrap();
        let root = dir.path().join("journal");
        std::fs::create_dir(&root).unwrap();
        let host = host();
        // No process has the largest id; this one is alive.
        let dead = format!(".unit.toml.{host}.{}.1f.tmp", u32::MAX);
        let kept = [
            format!(".unit.toml.{host}.{}.1f.tmp", std::process::id()),
            format!(".unit.toml.another-{host}.{}.1f.tmp", u32::MAX),
            format!(".unit.toml.{host}.{}.not-hex.tmp", u32::MAX),
            "unit.toml".to_string(),
        ];
        // Every file but this one was left two hours ago; a process not in this `/proc` that
        // wrote it just now may be alive in another PID namespace.
        let just_written = format!(".other.toml.{host}.{}.1f.tmp", u32::MAX);
        let long_ago = std::time::SystemTime::now() - 2 * DEAD_TEMPORARY_AGE;
        for name in kept.iter().chain([&dead]) {
            let f = std::fs::File::create(root.join(name)).unwrap();
            f.set_modified(long_ago).unwrap();
        }
        std::fs::write(root.join(&just_written), b"x").unwrap();
        let kept = [kept.as_slice(), &[just_written]].concat();
        Folder::create(&root).unwrap();
        let mut left: Vec<String> = std::fs::read_dir(&root)
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        left.sort();
        let mut expected = kept.to_vec();
        expected.sort();
        assert_eq!(left, expected);
    }

    #[test]
    fn replaces_whole_file_and_leaves_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a/b.txt");
        write_atomic(&p, b"first").unwrap();
        write_atomic(&p, b"second").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"second");
        let names: Vec<_> = std::fs::read_dir(p.parent().unwrap())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names.len(), 1, "{names:?}");
    }

    #[test]
    fn failed_write_keeps_the_old_file() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("x");
        write_atomic(&p, b"kept").unwrap();
        // A directory where the temporary file should go makes the write fail.
        std::fs::create_dir(temporary(&p)).unwrap();
        assert!(write_atomic(&p, b"lost").is_err());
        assert_eq!(std::fs::read(&p).unwrap(), b"kept");
    }

    #[test]
    fn links_pipes_and_folders_are_refused_as_inputs() {
        let dir = tempfile::tempdir().unwrap();
        let (file, link, fifo) = (dir.path().join("f"), dir.path().join("l"), dir.path().join("p"));
        std::fs::write(&file, b"text").unwrap();
        std::os::unix::fs::symlink(&file, &link).unwrap();
        assert!(std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap()
            .success());
        assert_eq!(read_regular_text(&file).unwrap(), "text");
        let e = read_regular(&link).unwrap_err().to_string();
        assert!(e.contains("symbolic link"), "{e}");
        // Refused at once, not blocked on a pipe no one writes.
        let e = read_regular(&fifo).unwrap_err().to_string();
        assert!(e.contains("named pipe"), "{e}");
        let e = read_regular(dir.path()).unwrap_err().to_string();
        assert!(e.contains("a folder"), "{e}");
        let e = read_regular(Path::new("/dev/null")).unwrap_err().to_string();
        assert!(e.contains("device"), "{e}");
    }

    #[test]
    fn a_tree_with_a_link_or_pipe_anywhere_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let root = dir.path().join("cache");
        assert!(check_plain_tree(&root).is_ok(), "a missing tree is plain");
        std::fs::create_dir_all(root.join("a/b")).unwrap();
        std::fs::write(root.join("a/b/x"), b"x").unwrap();
        assert!(check_plain_tree(&root).is_ok());
        std::os::unix::fs::symlink("/tmp", root.join("a/b/out")).unwrap();
        let e = check_plain_tree(&root).unwrap_err().to_string();
        assert!(e.contains("a/b/out") && e.contains("symbolic link"), "{e}");
        std::fs::remove_file(root.join("a/b/out")).unwrap();
        assert!(std::process::Command::new("mkfifo")
            .arg(root.join("a/q"))
            .status()
            .unwrap()
            .success());
        let e = check_plain_tree(&root).unwrap_err().to_string();
        assert!(e.contains("a/q") && e.contains("named pipe"), "{e}");
        // The root itself a link to a folder.
        let elsewhere = dir.path().join("elsewhere");
        std::fs::create_dir(&elsewhere).unwrap();
        std::os::unix::fs::symlink(&elsewhere, dir.path().join("linked")).unwrap();
        assert!(check_plain_tree(&dir.path().join("linked")).is_err());
        assert!(check_plain_folder(&dir.path().join("linked")).is_err());
        assert!(check_plain_folder(&elsewhere).is_ok());
        assert!(check_plain_folder(&dir.path().join("missing")).is_ok());
    }

    #[test]
    fn a_write_replaces_a_planted_link_and_never_follows_it() {
        let dir = tempfile::tempdir().unwrap();
        let outside = dir.path().join("outside");
        std::fs::write(&outside, b"theirs").unwrap();
        let target = dir.path().join("index.html");
        std::os::unix::fs::symlink(&outside, &target).unwrap();
        write_atomic(&target, b"ours").unwrap();
        assert_eq!(std::fs::read(&outside).unwrap(), b"theirs");
        assert!(!std::fs::symlink_metadata(&target).unwrap().file_type().is_symlink());
        assert_eq!(std::fs::read(&target).unwrap(), b"ours");
    }
}
