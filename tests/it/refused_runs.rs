//! What a refused run leaves: nothing it made, and everything an earlier run journaled. A
//! device's binding limit (lowered by the `test-hooks` feature's `PENUMBRA_TEST_BINDING_BYTES`)
//! refuses the tiny sweep's first ground truth, after the journal and the cache are open.

use crate::common;
use crate::hostile_input::snapshot;
use std::ffi::OsStr;
use std::path::Path;

/// The tiny sweep on the GPU in `dir`, its results into `dir/out`.
fn tiny_on_gpu(dir: &Path) -> std::path::PathBuf {
    common::tiny_experiment(dir, |t| format!("backend = \"gpu\"\n{t}"))
}

const LIMITED: [(&str, &str); 1] = [("PENUMBRA_TEST_BINDING_BYTES", "4096")];

/// A first run refused leaves no results folder, no journal, no cache; a refused `--shard`
/// leaves no `shards` folder.
#[test]
fn a_refused_first_run_or_shard_leaves_no_folder_behind() {
    let dir = tempfile::tempdir().unwrap();
    let exp = tiny_on_gpu(dir.path());
    let out = dir.path().join("results/tiny");
    let (o, e) = (OsStr::new("--out"), exp.as_os_str());
    let (code, err) = common::sweep_with(&[e, o, out.as_os_str()], &LIMITED);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("measure.width") && err.contains("hit buffer"), "{err}");
    assert!(
        !dir.path().join("results").exists(),
        "left {:?}",
        snapshot(dir.path()).keys()
    );
    std::fs::create_dir_all(&out).unwrap();
    let (code, err) = common::sweep_with(
        &[e, o, out.as_os_str(), OsStr::new("--shard"), OsStr::new("1/2")],
        &LIMITED,
    );
    assert_eq!(code, 2, "{err}");
    let left: Vec<_> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert!(left.is_empty(), "the refused shard left {left:?}");
}

/// `--fresh` measures every unit again, but a refused fresh run keeps every journaled unit
/// (byte for byte), and only a fresh run that succeeds drops the units it did not write.
#[test]
fn a_refused_fresh_run_keeps_the_journal_and_a_finished_one_replaces_it() {
    let dir = tempfile::tempdir().unwrap();
    let exp = tiny_on_gpu(dir.path());
    let out = dir.path().join("out");
    let (o, e) = (OsStr::new("--out"), exp.as_os_str());
    let (code, err) = common::sweep_with(&[e, o, out.as_os_str()], &[]);
    assert_eq!(code, 0, "{err}");
    let journal = out.join(".journal");
    let stale = journal.join("0000000000000000.toml");
    std::fs::write(&stale, "# a unit no run of this experiment wrote\n").unwrap();
    let before = snapshot(&journal);
    assert!(before.len() > 2, "nothing journaled: {:?}", before.keys());

    let fresh = OsStr::new("--fresh");
    let (code, err) = common::sweep_with(&[e, o, out.as_os_str(), fresh], &LIMITED);
    assert_eq!(code, 2, "{err}");
    assert_eq!(snapshot(&journal), before, "the refused fresh run changed the journal");

    let (code, err) = common::sweep_with(&[e, o, out.as_os_str(), fresh], &[]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(
        common::manifest_count(&out, "units_from_journal"),
        0,
        "a fresh run takes nothing from the journal"
    );
    assert!(!stale.exists(), "the fresh run kept a unit it did not write");
    let after = snapshot(&journal);
    assert_eq!(after.len(), before.len() - 1, "{:?}", after.keys());
}

/// A frame past the binding limit is located at the key that set its size, not at another
/// frame's: the sweep's figures (after its measured groups fit) at `figures.width`, the ao
/// kind's tuning frames at `tuning.width`; the earlier results stay as they were.
#[test]
fn a_refused_frame_is_located_at_the_key_of_its_own_size() {
    let dir = tempfile::tempdir().unwrap();
    let figures =
        "\n[figures]\ncamera = \"measure\"\nwidth = 64\nheight = 64\nsamples = 16\nground_truth_samples = 64\n";
    let exp = common::tiny_experiment(dir.path(), |t| format!("backend = \"gpu\"\n{t}{figures}"));
    let out = dir.path().join("out");
    let (o, e) = (OsStr::new("--out"), exp.as_os_str());
    let (code, err) = common::sweep_with(&[e, o, out.as_os_str()], &[]);
    assert_eq!(code, 0, "{err}");
    let before = snapshot(&out);
    // The measured 24 x 24 frames' hit buffers (27,648 bytes) fit; the figures' 64 x 64 one
    // (196,608 bytes) does not.
    let limited = [("PENUMBRA_TEST_BINDING_BYTES", "100000")];
    let fresh = OsStr::new("--fresh");
    let (code, err) = common::sweep_with(&[e, o, out.as_os_str(), fresh], &limited);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("tiny.toml:") && err.contains("figures.width") && err.contains("64x64 frame"),
        "{err}"
    );
    assert_eq!(snapshot(&out), before, "the refused run changed the results");

    let ao = dir.path().join("ao.toml");
    std::fs::write(
        &ao,
        common::small_ao(
            "ao-tuned",
            "gpu",
            "kdtree",
            128,
            "[accel.kdtree]\nmax_depth = [8, 22]\nleaf_size = 8\n",
            ("cow", &common::repo("assets/meshes/cow.off").display().to_string()),
        ),
    )
    .unwrap();
    // The 8 x 8 frames fit, the 128 x 128 tuning frames' hit buffers (786,432 bytes) do not.
    let ao_out = dir.path().join("ao-out");
    let (code, err) = common::sweep_with(
        &[ao.as_os_str(), o, ao_out.as_os_str()],
        &[("PENUMBRA_TEST_BINDING_BYTES", "700000")],
    );
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("ao.toml:") && err.contains("tuning.width") && err.contains("128x128 frame"),
        "{err}"
    );
    assert!(!ao_out.exists(), "the refused run left {}", ao_out.display());
}

/// A folder where one of this run's units belongs is refused by a fresh run before anything is
/// measured (the run reads nothing there, and could not rename the unit over it), exit 2 naming
/// it; the journal stays as it was.
#[test]
fn a_fresh_run_refuses_a_folder_at_a_units_name_before_measuring() {
    let dir = tempfile::tempdir().unwrap();
    let exp = common::tiny_experiment(dir.path(), |t| t);
    let out = dir.path().join("out");
    let (o, e) = (OsStr::new("--out"), exp.as_os_str());
    let (code, err) = common::sweep_with(&[e, o, out.as_os_str()], &[]);
    assert_eq!(code, 0, "{err}");
    let journal = out.join(".journal");
    let unit = crate::hostile_input::first_file(&journal, "journaled unit");
    std::fs::remove_file(&unit).unwrap();
    std::fs::create_dir(&unit).unwrap();
    std::fs::write(unit.join("theirs"), b"theirs").unwrap();
    let before = snapshot(&journal);
    let (code, err) = common::sweep_with(&[e, o, out.as_os_str(), OsStr::new("--fresh")], &[]);
    assert_eq!(code, 2, "{err}");
    let named = unit.file_name().unwrap().to_string_lossy().into_owned();
    assert!(
        err.contains(&named) && err.contains("a folder where a journaled unit belongs"),
        "{err}"
    );
    assert!(!err.contains("units:"), "measured before refusing: {err}");
    assert_eq!(snapshot(&journal), before);
}
