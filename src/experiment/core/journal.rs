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

/// A folder of journaled units, one TOML file each, written atomically as each finishes.
pub(super) struct UnitJournal {
    dir: PathBuf,
}

impl UnitJournal {
    pub(super) fn open(dir: &Path, fresh: bool) -> anyhow::Result<UnitJournal> {
        if fresh && dir.exists() {
            std::fs::remove_dir_all(dir)?;
        }
        std::fs::create_dir_all(dir)?;
        Ok(UnitJournal { dir: dir.into() })
    }

    pub(super) fn path(&self, key: &str) -> PathBuf {
        self.dir.join(format!("{key}.toml"))
    }

    /// The outcome journaled under `key`: none if no file is there, and a refusal if one is
    /// there but is not the file this run wrote (its first line, `# fnv1a HASH`, hashes the rest
    /// as written: an edited, cut or foreign file would otherwise be taken as measured).
    pub(super) fn read<O: DeserializeOwned>(path: &Path, key: &str) -> anyhow::Result<Option<O>> {
        if std::fs::symlink_metadata(path).is_err() {
            return Ok(None);
        }
        let damaged = |why: &str| {
            BadInput(format!(
                "{}: a journaled unit {why}; remove the file to measure the unit again, or rerun with --fresh",
                path.display()
            ))
        };
        let text = crate::files::read_regular_text(path).map_err(|e| damaged(&format!("cannot be read ({e:#})")))?;
        let (check, body) = text.split_once('\n').unwrap_or((&text, ""));
        if check.strip_prefix(CHECK) != Some(&format!("{:016x}", fnv1a(body.as_bytes()))) {
            return Err(damaged("has changed since it was written (its checksum does not match)").into());
        }
        let j: Journaled<O> = toml::from_str(body).map_err(|e| damaged(&format!("does not parse ({e})")))?;
        if j.key != key {
            return Err(damaged(&format!("holds unit {} under another unit's name", j.key)).into());
        }
        Ok(Some(j.outcome))
    }

    fn write<O: Serialize>(&self, key: &str, label: &str, outcome: O) -> anyhow::Result<()> {
        let body = toml::to_string(&Journaled {
            key: key.into(),
            label: label.into(),
            outcome,
        })?;
        let text = format!("{CHECK}{:016x}\n{body}", fnv1a(body.as_bytes()));
        crate::files::write_atomic(&self.path(key), text.as_bytes())?;
        die_after_journaled();
        Ok(())
    }
}

/// Test hook: with `PENUMBRA_TEST_DIE_AFTER=n` set, the process aborts (no cleanup, as when a
/// node kills a job) right after its n-th journaled unit (a sweep's group, an ao mesh, a block of
/// frames), so tests interrupt a run at a known point.
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
    }
}

/// Measures `units` (or takes them from `journal`), each outcome read back from its file. A
/// journaled outcome with failed runs is measured again: a failure is never resumed.
pub(super) fn measure_all<D: Declaration>(
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
        let earlier = UnitJournal::read::<D::Outcome>(&journal.path(&key), &key)?;
        journaled.push((key, earlier.filter(|o| spec.failed(o) == 0)));
    }
    let bar = progress.bar("units", units.len() as u64);
    let mut out = Measured {
        outcomes: Vec::new(),
        resumed: 0,
        failed: 0,
        files: Vec::new(),
    };
    for (unit, (key, earlier)) in units.iter().zip(journaled) {
        let path = journal.path(&key);
        let outcome = match earlier {
            Some(o) => {
                out.resumed += 1;
                o
            }
            None => {
                bar.message(unit.label.clone());
                let measured = spec.measure(unit, backend, progress)?;
                journal.write(&key, &unit.label, measured)?;
                UnitJournal::read(&path, &key)?
                    .ok_or_else(|| anyhow::anyhow!("{}: a journaled unit does not read back", path.display()))?
            }
        };
        let bytes = crate::files::read_regular(&path)?;
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
