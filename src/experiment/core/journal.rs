//! The unit journal: one TOML file per measured unit, written atomically as the unit finishes
//! and read back before the report sees it, so a killed run resumes unit by unit and a resumed,
//! merged or uninterrupted run reports from the same bytes.

use super::declaration::{unit_key, Declaration, Unit};
use crate::experiment::cli::BadInput;
use crate::experiment::progress::Progress;
use crate::fingerprint::fnv1a;
use crate::render::Backend;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// One journaled unit a shard holds.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct UnitFile {
    /// The unit's key.
    pub key: String,
    /// FNV-1a of its journal file as written.
    pub fnv1a: String,
}

/// What measuring units yielded: the outcomes in the units' order, how many came from the
/// journal, how many of the outcomes' runs failed, and each unit's key and file hash.
pub struct Measured<O> {
    /// In the units' order.
    pub outcomes: Vec<O>,
    /// Units taken from the journal rather than measured.
    pub resumed: usize,
    /// Runs that failed, summed over the outcomes ([`Declaration::failed`]).
    pub failed: usize,
    /// Every unit's key and the hash of its file.
    pub files: Vec<UnitFile>,
}

/// What a unit's journal file holds.
#[derive(Serialize, Deserialize)]
struct Journaled<O> {
    key: String,
    label: String,
    outcome: O,
}

/// The first line of a journaled unit's file, before the FNV-1a of the rest.
const CHECK: &str = "# fnv1a ";

/// A folder of journaled units, one TOML file each, written atomically as each finishes,
/// through a handle held for the run ([`crate::files::Folder`]): a journal folder swapped for a
/// link mid-run is never written or read through.
pub(super) struct UnitJournal {
    folder: crate::files::Folder,
    /// Whether every unit is measured again (`--fresh`): nothing is read from the journal, and
    /// what this run did not write is removed only when it succeeds, so a refused or failed
    /// fresh run loses nothing journaled.
    fresh: bool,
}

impl UnitJournal {
    pub(super) fn open(dir: &Path, fresh: bool) -> anyhow::Result<UnitJournal> {
        Ok(UnitJournal {
            folder: crate::files::Folder::create(dir)?,
            fresh,
        })
    }

    /// Measures `units` into this journal ([`measure_all`]); a run that fails before it
    /// journals anything leaves no journal folder it made behind, and a fresh run that
    /// succeeds leaves only its own units.
    pub(super) fn measure<D: Declaration>(
        &self,
        spec: &D,
        units: &[Unit],
        context: &str,
        backend: &mut dyn Backend,
        progress: &Progress,
    ) -> anyhow::Result<Measured<D::Outcome>> {
        let measured = measure_all(spec, units, context, self, backend, progress);
        match &measured {
            Err(_) => self.folder.remove_if_made_and_empty(),
            Ok(m) if self.fresh => {
                let kept: std::collections::HashSet<String> = m.files.iter().map(|f| Self::name(&f.key)).collect();
                self.folder.remove_all_but(&kept)?;
            }
            Ok(_) => {}
        }
        measured
    }

    fn name(key: &str) -> String {
        format!("{key}.toml")
    }

    /// Refuses, in a fresh run, a folder where `key`'s file belongs: the run reads nothing
    /// there, but could not rename its unit over a folder, which it would find only when the
    /// unit is written, after measuring it.
    fn check_replaceable(&self, key: &str) -> Result<(), BadInput> {
        if self.folder.holds_folder(&Self::name(key)) {
            return Err(BadInput(format!(
                "{}: a folder where a journaled unit belongs, which --fresh cannot replace; remove it",
                self.path(key).display()
            )));
        }
        Ok(())
    }

    pub(super) fn path(&self, key: &str) -> PathBuf {
        self.folder.path().join(Self::name(key))
    }

    /// The outcome journaled under `key` in this journal, read through its handle, with the
    /// bytes of its file ([`UnitJournal::parse`]).
    fn read_held<O: DeserializeOwned>(&self, key: &str) -> anyhow::Result<Option<(O, Vec<u8>)>> {
        let path = self.path(key);
        let Some(bytes) = self
            .folder
            .read(&Self::name(key))
            .map_err(|e| damaged(&path, &format!("cannot be read ({e:#})")))?
        else {
            return Ok(None);
        };
        let text = std::str::from_utf8(&bytes).map_err(|_| damaged(&path, "is not UTF-8 text"))?;
        Ok(Some((Self::parse(&path, text, key)?, bytes)))
    }

    /// The outcome journaled under `key` at `path` (a shard's journal, read by a merge): none
    /// if no file is there, and a refusal if one is there but is not the file its run wrote
    /// ([`UnitJournal::parse`]).
    pub(super) fn read<O: DeserializeOwned>(path: &Path, key: &str) -> anyhow::Result<Option<O>> {
        if std::fs::symlink_metadata(path).is_err() {
            return Ok(None);
        }
        let text =
            crate::files::read_regular_text(path).map_err(|e| damaged(path, &format!("cannot be read ({e:#})")))?;
        Self::parse(path, &text, key).map(Some)
    }

    /// A journaled unit's outcome from the text of its file at `path`, refused where it is not
    /// the file a run wrote (its first line, `# fnv1a HASH`, hashes the rest as written: an
    /// edited, cut or foreign file would otherwise be taken as measured).
    fn parse<O: DeserializeOwned>(path: &Path, text: &str, key: &str) -> anyhow::Result<O> {
        let (check, body) = text.split_once('\n').unwrap_or((text, ""));
        if check.strip_prefix(CHECK) != Some(&format!("{:016x}", fnv1a(body.as_bytes()))) {
            return Err(damaged(path, "has changed since it was written (its checksum does not match)").into());
        }
        let j: Journaled<O> = toml::from_str(body).map_err(|e| damaged(path, &format!("does not parse ({e})")))?;
        if j.key != key {
            return Err(damaged(path, &format!("holds unit {} under another unit's name", j.key)).into());
        }
        Ok(j.outcome)
    }

    fn write<O: Serialize>(&self, key: &str, label: &str, outcome: O) -> anyhow::Result<()> {
        let body = toml::to_string(&Journaled {
            key: key.into(),
            label: label.into(),
            outcome,
        })?;
        let text = format!("{CHECK}{:016x}\n{body}", fnv1a(body.as_bytes()));
        self.folder.write_atomic(&Self::name(key), text.as_bytes())?;
        die_after_journaled();
        Ok(())
    }
}

/// The refusal of the journaled unit at `path` that `why` (cannot be read, has changed, ...):
/// bad input, with the two ways on.
fn damaged(path: &Path, why: &str) -> BadInput {
    BadInput(format!(
        "{}: a journaled unit {why}; remove the file to measure the unit again, or rerun with --fresh",
        path.display()
    ))
}

/// Test hooks after each journaled unit, so tests interrupt or change a run at a known point
/// (a sweep's group, an ao mesh, a block of frames): with `PENUMBRA_TEST_DIE_AFTER=n` the
/// process aborts (no cleanup, as when a node kills a job) right after its n-th; with
/// `PENUMBRA_TEST_PAUSE_AFTER=n:FILE` it creates FILE after its n-th and waits, up to a minute,
/// until the test removes it (a folder swapped for a link while the run goes).
pub fn die_after_journaled() {
    #[cfg(feature = "test-hooks")]
    {
        use std::sync::atomic::{AtomicUsize, Ordering};
        static JOURNALED: AtomicUsize = AtomicUsize::new(0);
        let n = JOURNALED.fetch_add(1, Ordering::SeqCst) + 1;
        let limit = std::env::var("PENUMBRA_TEST_DIE_AFTER")
            .ok()
            .and_then(|v| v.parse().ok());
        if limit == Some(n) {
            std::process::abort();
        }
        let pause = std::env::var("PENUMBRA_TEST_PAUSE_AFTER").ok();
        if let Some((at, file)) = pause.as_deref().and_then(|v| v.split_once(':')) {
            if at.parse() == Ok(n) && std::fs::write(file, b"paused").is_ok() {
                let start = std::time::Instant::now();
                while std::path::Path::new(file).exists() && start.elapsed().as_secs() < 60 {
                    std::thread::sleep(std::time::Duration::from_millis(20));
                }
            }
        }
    }
}

/// Measures `units` (or takes them from `journal`), each outcome read back from its file. A
/// journaled outcome with failed runs is measured again: a failure is never resumed.
fn measure_all<D: Declaration>(
    spec: &D,
    units: &[Unit],
    context: &str,
    journal: &UnitJournal,
    backend: &mut dyn Backend,
    progress: &Progress,
) -> anyhow::Result<Measured<D::Outcome>> {
    // Every journaled unit is read before anything is measured: a damaged one is refused
    // before hours of work, not after.
    let mut journaled = Vec::with_capacity(units.len());
    for unit in units {
        let key = unit_key(spec, context, backend.adapter(), unit);
        let earlier = if journal.fresh {
            journal.check_replaceable(&key)?;
            None
        } else {
            journal.read_held::<D::Outcome>(&key)?
        };
        journaled.push((key, earlier.filter(|(o, _)| spec.failed(o) == 0)));
    }
    let bar = progress.bar("units", units.len() as u64);
    let mut out = Measured {
        outcomes: Vec::new(),
        resumed: 0,
        failed: 0,
        files: Vec::new(),
    };
    for (unit, (key, earlier)) in units.iter().zip(journaled) {
        let (outcome, bytes) = match earlier {
            Some(o) => {
                out.resumed += 1;
                o
            }
            None => {
                bar.message(unit.label.clone());
                let measured = spec.measure(unit, backend, progress)?;
                journal.write(&key, &unit.label, measured)?;
                journal.read_held(&key)?.ok_or_else(|| {
                    anyhow::anyhow!("{}: a journaled unit does not read back", journal.path(&key).display())
                })?
            }
        };
        out.files.push(UnitFile {
            key,
            fnv1a: format!("{:016x}", fnv1a(&bytes)),
        });
        out.failed += spec.failed(&outcome);
        out.outcomes.push(outcome);
        bar.inc(1);
    }
    bar.finish();
    if out.resumed > 0 {
        tracing::info!("{} of {} units taken from the journal", out.resumed, units.len());
    }
    Ok(out)
}
