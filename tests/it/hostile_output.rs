//! Where a run's output goes is hostile too: a standard stream that is full or whose reader
//! has gone, and a results folder whose files share their inodes with a backup (`cp -al`).
//! Every case ends with the command's own exit status (never a panic's 101), says why where
//! standard error can still take it, and changes nothing outside the output folder.

use crate::hostile_input::{first_file, snapshot, tiny, Scratch};
use std::fs::File;
use std::path::Path;
use std::process::{Command, Stdio};

/// `/dev/full` for writing: every write fails with ENOSPC.
fn full() -> Stdio {
    Stdio::from(File::options().write(true).open("/dev/full").unwrap())
}

/// The write end of a pipe whose reader has already gone: every write fails with EPIPE.
fn closed_pipe() -> Stdio {
    use std::os::fd::{FromRawFd, OwnedFd};
    let mut ends = [0; 2];
    assert_eq!(unsafe { libc::pipe(ends.as_mut_ptr()) }, 0, "pipe");
    // SAFETY: both descriptors were just opened by pipe(2) and are owned by nothing else.
    let (reader, writer) = unsafe { (OwnedFd::from_raw_fd(ends[0]), OwnedFd::from_raw_fd(ends[1])) };
    drop(reader);
    Stdio::from(writer)
}

/// Runs `command` and returns its exit status (-1 when a signal ended it) and standard error
/// (empty when standard error was redirected elsewhere).
fn status_and_stderr(command: &mut Command) -> (i32, String) {
    let out = command.output().unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn a_full_or_closed_standard_stream_ends_the_command_with_its_status() {
    let s = Scratch::new(&tiny(), "tiny");
    let sweep = |args: &[&str]| {
        let mut c = Command::new(env!("CARGO_BIN_EXE_sweep"));
        c.current_dir(&s.work).args(args);
        c
    };
    // A dry run's plan into a full disk: status 1, said on standard error.
    let (code, stderr) = status_and_stderr(sweep(&["exp.toml", "--dry-run"]).stdout(full()));
    assert_eq!(code, 1, "{stderr}");
    assert!(stderr.contains("standard output"), "{stderr}");
    // Into a pipe whose reader went away (`| head -1`): status 1, nothing said.
    let (code, stderr) = status_and_stderr(sweep(&["exp.toml", "--dry-run"]).stdout(closed_pipe()));
    assert_eq!((code, stderr.as_str()), (1, ""));
    // Bad input with standard error full keeps its status 2 and writes nothing.
    let before = snapshot(&s.root);
    std::fs::write(
        s.work.join("bad.toml"),
        tiny().replace("seeds = [1, 2]", "seeds = [1, 1]"),
    )
    .unwrap();
    let (code, _) = status_and_stderr(sweep(&["bad.toml"]).stderr(full()));
    assert_eq!(code, 2);
    std::fs::remove_file(s.work.join("bad.toml")).unwrap();
    assert_eq!(snapshot(&s.root), before, "a refused run wrote something");
    // A whole run with standard error full (its log lines and progress lost) succeeds.
    let (code, _) = status_and_stderr(sweep(&["exp.toml", "--fresh"]).stderr(full()));
    assert_eq!(code, 0);
    let results = s.work.join("results/tiny");
    assert!(results.join("report.md").is_file());
    // The page binary's "wrote" line into a full disk or a closed pipe.
    for (out, says) in [(full(), true), (closed_pipe(), false)] {
        let (code, stderr) = status_and_stderr(Command::new(env!("CARGO_BIN_EXE_page")).arg(&results).stdout(out));
        assert_eq!(code, 1, "{stderr}");
        assert_eq!(stderr.contains("standard output"), says, "{stderr}");
    }
}

/// Every regular file under `from` hard-linked at the same place under `to`: the backup
/// `cp -al` makes.
fn link_tree(from: &Path, to: &Path) {
    for entry in std::fs::read_dir(from).unwrap() {
        let path = entry.unwrap().path();
        let there = to.join(path.file_name().unwrap());
        if path.is_dir() {
            std::fs::create_dir_all(&there).unwrap();
            link_tree(&path, &there);
        } else {
            std::fs::hard_link(&path, &there).unwrap();
        }
    }
}

/// A results folder backed up with hard links, then resumed with more seeds (new units
/// appended to its journal) and one cached ground truth to write again under its name, that
/// name hard-linked to a file outside: the backup, sharing every inode at the start, is byte
/// for byte what it was, the outside file too, and the resumed folder holds the new runs.
#[test]
fn a_hard_linked_backup_is_never_changed_by_a_resumed_run() {
    let s = Scratch::new(&tiny(), "tiny");
    let (code, stderr) = s.run(&["exp.toml", "--fresh"]);
    assert_eq!(code, 0, "{stderr}");
    let (results, backup) = (s.work.join("results/tiny"), s.root.join("backup"));
    link_tree(&results, &backup);
    let before = snapshot(&backup);
    // The journal's files by their names inside the folder, with their bytes.
    let journal = |dir: &Path| -> Vec<(std::path::PathBuf, Vec<u8>)> {
        snapshot(&dir.join(".journal"))
            .into_iter()
            .map(|(p, bytes)| (p.strip_prefix(dir).unwrap().to_path_buf(), bytes))
            .collect()
    };
    assert!(!journal(&backup).is_empty(), "the run keeps a journal");
    // A cached ground truth whose name the run will write again (its content no longer reads
    // as one: a cache miss) shares its inode with a file outside the folder.
    let cached = first_file(&results.join("cache"), "a cached ground truth");
    let outside = s.root.join("outside");
    std::fs::write(&outside, b"not a ground truth").unwrap();
    std::fs::remove_file(&cached).unwrap();
    std::fs::hard_link(&outside, &cached).unwrap();
    std::fs::write(
        s.work.join("exp.toml"),
        tiny().replace("seeds = [1, 2]", "seeds = [1, 2, 3]"),
    )
    .unwrap();
    let (code, stderr) = s.run(&["exp.toml"]);
    assert_eq!(code, 0, "{stderr}");
    assert_eq!(snapshot(&backup), before, "the backup changed through a shared inode");
    assert_ne!(
        journal(&results),
        journal(&backup),
        "the resumed run journaled nothing new"
    );
    assert!(
        std::fs::read(&cached).unwrap() != b"not a ground truth",
        "the run did not write the cached ground truth again"
    );
    assert!(
        std::fs::read(&outside).unwrap() == b"not a ground truth",
        "written through the cache file's shared inode"
    );
}

/// A fresh run of the scratch tree's experiment, paused (`PENUMBRA_TEST_PAUSE_AFTER`) after its
/// `units`-th journaled unit: returned once `pause` exists, the run waiting until it is removed.
#[cfg(feature = "test-hooks")]
fn fresh_run_paused_after(s: &Scratch, units: i64, pause: &Path) -> std::process::Child {
    let mut child = Command::new(env!("CARGO_BIN_EXE_sweep"))
        .current_dir(&s.work)
        .args(["exp.toml", "--fresh"])
        .env("PENUMBRA_TEST_PAUSE_AFTER", format!("{units}:{}", pause.display()))
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = std::time::Instant::now();
    while !pause.exists() {
        assert!(start.elapsed().as_secs() < 300, "the run never paused");
        assert!(child.try_wait().unwrap().is_none(), "the run ended before pausing");
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    child
}

/// A results folder's `.journal` or `cache` swapped for a link to a folder elsewhere, or for
/// another plain folder, while the run goes (paused after its first journaled unit, before the
/// second ground truth): the run never writes into the folder put there, ends with status 2
/// naming the swapped folder, and the earlier results stay whole.
#[cfg(feature = "test-hooks")]
#[test]
fn a_folder_swapped_for_a_link_mid_run_is_never_written_through() {
    let two_radii = tiny().replace("light_radii = [0.02]", "light_radii = [0.02, 0.04]");
    for (swapped, link) in [
        (".journal", true),
        ("cache", true),
        (".journal", false),
        ("cache", false),
    ] {
        let s = Scratch::new(&two_radii, "tiny");
        let home = s.work.join("results/tiny");
        let earlier = std::fs::read(home.join("runs.csv")).unwrap();
        let (foreign, pause) = (s.root.join("foreign"), s.root.join("pause"));
        std::fs::create_dir(&foreign).unwrap();
        std::fs::write(foreign.join("theirs"), b"theirs").unwrap();
        let child = fresh_run_paused_after(&s, 1, &pause);
        let target = home.join(swapped);
        assert!(target.is_dir(), "{swapped} is there while the run goes");
        std::fs::rename(&target, home.join(format!("{swapped}-moved"))).unwrap();
        let foreign = if link {
            std::os::unix::fs::symlink(&foreign, &target).unwrap();
            foreign
        } else {
            std::fs::create_dir(&target).unwrap();
            std::fs::write(target.join("theirs"), b"theirs").unwrap();
            target
        };
        let before = snapshot(&foreign);
        std::fs::remove_file(&pause).unwrap();
        let out = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{swapped}: {stderr}");
        assert!(stderr.contains(&format!("tiny/{swapped}")), "{swapped}: {stderr}");
        assert_eq!(
            snapshot(&foreign),
            before,
            "{swapped}: written into the folder put there"
        );
        assert_eq!(std::fs::read(home.join("runs.csv")).unwrap(), earlier, "{swapped}");
    }
}

/// The results folder itself moved away and replaced by another folder after the last unit
/// is journaled: nothing is written or swapped into the folder put there, the run ends with
/// status 2 saying where the folder went, and the moved folder keeps the earlier results.
#[cfg(feature = "test-hooks")]
#[test]
fn a_results_folder_replaced_before_the_swap_gets_nothing() {
    let s = Scratch::new(&tiny(), "tiny");
    let (code, stderr) = s.run(&["exp.toml", "--fresh"]);
    assert_eq!(code, 0, "{stderr}");
    let home = s.work.join("results/tiny");
    let units = crate::common::manifest_count(&home, "units");
    let earlier = std::fs::read(home.join("runs.csv")).unwrap();
    let pause = s.root.join("pause");
    let child = fresh_run_paused_after(&s, units, &pause);
    let moved = s.work.join("results/tiny-moved");
    std::fs::rename(&home, &moved).unwrap();
    std::fs::create_dir(&home).unwrap();
    std::fs::write(home.join("theirs"), b"theirs").unwrap();
    let before = snapshot(&home);
    std::fs::remove_file(&pause).unwrap();
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    // The journal's read-back of the last unit finds its folder moved first.
    assert!(
        stderr.contains("results/tiny/.journal: moved to") && stderr.contains("results/tiny-moved/.journal"),
        "{stderr}"
    );
    assert_eq!(snapshot(&home), before, "outputs swapped into the folder put there");
    assert_eq!(std::fs::read(moved.join("runs.csv")).unwrap(), earlier);
}

/// A folder where a cached ground truth's file belongs is refused when the run reads the cache,
/// exit 2 naming it, before the render whose result could not be written there; the earlier
/// results stay as they were.
#[test]
fn a_folder_at_a_cached_ground_truths_name_is_refused_before_rendering() {
    let s = Scratch::new(&tiny(), "tiny");
    let (code, stderr) = s.run(&["exp.toml", "--fresh"]);
    assert_eq!(code, 0, "{stderr}");
    let home = s.work.join("results/tiny");
    let cached = first_file(&home.join("cache"), "a cached ground truth");
    std::fs::remove_file(&cached).unwrap();
    std::fs::create_dir(&cached).unwrap();
    let before = snapshot(&s.root);
    let (code, stderr) = s.run(&["exp.toml"]);
    assert_eq!(code, 2, "{stderr}");
    let name = cached.file_name().unwrap().to_string_lossy();
    assert!(
        stderr.contains(&*name) && stderr.contains("not a regular file"),
        "{stderr}"
    );
    assert_eq!(snapshot(&s.root), before, "the refused run changed something");
}
