//! A kind declared on the core: its axes, its units of work, how one unit is measured, and its
//! report ([`Declaration`]). [`Declared`] turns a declaration into an [`Experiment`] with
//! everything the core gives every kind: `--filter` on its axes, a journal that resumes a killed
//! run unit by unit, `--shard K/N` and `--merge`, and `--dry-run` listing the axes and units.
//!
//! A unit is what must run on one machine in one process: its timings are compared with each
//! other (every structure of an ao mesh interleaved in one schedule, every structure of a block
//! of frames), so a unit is never split and its times are never paired with another machine's.
//! What a unit measures ([`Declaration::Outcome`]) is journaled as it finishes, under a key that
//! hashes the experiment's inputs, the build, the device, the axes' values and the unit's label;
//! the report is always made from the journaled outcomes read back, so a resumed run, a merged
//! one and an uninterrupted one write their non-timing outputs byte for byte alike.

use super::declaration::{context, dealt, identity, Declaration, Unit};
use super::filter::{self, Axis, Filter};
use super::journal::{Measured, UnitJournal};
use super::merge::{merge_units, ShardManifest, SHARD_MANIFEST};
use super::shard::{share_line, Shard};
use crate::experiment::cli::{BadInput, Cli};
use crate::experiment::contract::{Accepts, Experiment, Finished, RunContext};
use crate::experiment::header::Header;
use crate::experiment::progress::Progress;
use crate::render::Backend;
use std::path::{Path, PathBuf};

/// Refuses a `--tuning` file inside the results folder `home`, which this run (or the merge of
/// its shards) replaces: the file it builds from would be overwritten by its own output.
fn refuse_tuning_inside(path: &Path, home: &Path) -> Result<(), BadInput> {
    let (Ok(file), Ok(home)) = (path.canonicalize(), home.canonicalize()) else {
        return Ok(());
    };
    if file.starts_with(&home) {
        return Err(BadInput(format!(
            "--tuning {}: the file lies in the results folder this run replaces ({}); copy it out first (e.g. `cp {} tuning-kept.csv`) and pass the copy",
            path.display(),
            home.display(),
            path.display()
        )));
    }
    Ok(())
}

/// A declared kind as an experiment.
pub struct Declared<D>(pub D);

/// The share of `units` that falls to `shard`.
fn share(units: &[Unit], shard: Shard) -> Vec<Unit> {
    let (shares, _) = dealt(units, shard.count);
    units
        .iter()
        .zip(shares)
        .filter(|(_, s)| *s == shard.index - 1)
        .map(|(u, _)| u.clone())
        .collect()
}

/// Measures every unit of `spec` in this process, resuming from the journal in `home`
/// (`fresh` discards it first): what `sweep` does without `--shard` or `--merge`, and what
/// library callers use to run a declared kind whole.
pub fn measure_whole<D: Declaration>(
    spec: &D,
    home: &Path,
    fresh: bool,
    backend: &mut dyn Backend,
    progress: &Progress,
) -> anyhow::Result<Measured<D::Outcome>> {
    let units = spec.units();
    let context = context(spec, backend.adapter())?;
    UnitJournal::open(&home.join(".journal"), fresh)?.measure(spec, &units, &context, backend, progress)
}

impl<D: Declaration> Declared<D> {
    /// Runs (a whole run, a shard or a merge) without locating refusals.
    fn run_unlocated(&self, run: &mut RunContext) -> anyhow::Result<Finished> {
        let mut spec = self.filtered(&run.cli.filter)?;
        if let Some(path) = &run.cli.tuning {
            refuse_tuning_inside(path, run.home)?;
            spec.reuse_tuning(path).map_err(BadInput)?;
        }
        spec.keep_state_in(run.home);
        if let Some(shard) = run.cli.shard {
            return self.run_shard(&spec, shard, run);
        }
        let measured = if run.cli.merge.is_empty() {
            measure_whole(&spec, run.home, run.cli.fresh, run.backend, run.progress)?
        } else {
            let (measured, machines) = merge_units(&spec, run)?;
            tracing::info!(
                "merged {} units from shards run on: {}",
                measured.outcomes.len(),
                machines.join("; ")
            );
            measured
        };
        let (units, resumed, failed) = (measured.outcomes.len(), measured.resumed, measured.failed);
        let mut details = spec.report(measured.outcomes, run)?;
        // A unit taken from a journal was measured by an earlier process (its times too): the
        // manifest says how many, so a rerun that measured nothing is not read as fresh timing.
        details.insert("units".into(), toml::Value::Integer(units as i64));
        details.insert("units_from_journal".into(), toml::Value::Integer(resumed as i64));
        let table = format!("see the `error` column of {}", run.home.join(D::FAILURES).display());
        Ok(Finished::Results {
            details,
            failed: Some((failed, table)),
        })
    }

    /// The declaration restricted by the command line's filters.
    fn filtered(&self, filters: &[Filter]) -> Result<D, BadInput> {
        let mut spec = self.0.clone();
        let axes = spec.axes();
        for (axis, keep) in filter::select(&axes, filters, filter::same_text).map_err(BadInput)? {
            // An earlier axis's restriction may have thinned this axis's values (fps: a scene
            // kept takes only its own light counts), so the kept values are found again.
            let values = |axes: &[Axis<D::Axis>]| -> Vec<String> {
                let of = axes.iter().find(|a| a.key == axis).expect("a declared axis");
                of.values.clone()
            };
            let before = values(&axes);
            let kept: Vec<&String> = keep.iter().map(|&i| &before[i]).collect();
            let now: Vec<usize> = values(&spec.axes())
                .iter()
                .enumerate()
                .filter(|(_, v)| kept.contains(v))
                .map(|(i, _)| i)
                .collect();
            spec.restrict(axis, &now);
        }
        Ok(spec)
    }

    /// Runs `shard`'s share into `shard.dir(home)`: its journal, then `shard.toml` last.
    fn run_shard(&self, spec: &D, shard: Shard, run: &mut RunContext) -> anyhow::Result<Finished> {
        let started = std::time::Instant::now();
        let dir = shard.dir(run.home);
        let manifest_path = dir.join(SHARD_MANIFEST);
        // A manifest left by an earlier run would vouch for files this run may replace.
        if manifest_path.exists() {
            std::fs::remove_file(&manifest_path)?;
        }
        let units = spec.units();
        let context = context(spec, run.backend.adapter())?;
        let mine = share(&units, shard);
        let journal = UnitJournal::open(&dir.join(".journal"), run.cli.fresh)?;
        let measured = journal.measure(spec, &mine, &context, run.backend, run.progress)?;
        let resumed = measured.resumed;
        let manifest = ShardManifest {
            shard: shard.to_string(),
            experiment: run.cli.experiment.display().to_string(),
            identity: identity(spec, &context, run.backend.adapter(), &units),
            context,
            machine: crate::experiment::manifest::Machine::current().cpu,
            resumed,
            seconds: started.elapsed().as_secs_f64(),
            units: measured.files,
        };
        crate::files::write_atomic(&manifest_path, toml::to_string(&manifest)?.as_bytes())?;
        tracing::info!(
            "shard {shard}: {} units ({resumed} resumed) in {:.1} s; wrote {}",
            mine.len(),
            manifest.seconds,
            dir.display()
        );
        let journal = format!(
            "their errors reach the `error` column of {} at --merge; rerunning this shard measures them again",
            D::FAILURES
        );
        Ok(Finished::Shard {
            failed: Some((measured.failed, journal)),
        })
    }
}

impl<D: Declaration> Experiment for Declared<D> {
    fn header(&self) -> &Header {
        self.0.header()
    }

    fn accepts(&self) -> Accepts {
        Accepts {
            gpu: self.0.gpu(),
            backend: self.0.backend(),
        }
    }

    fn inputs(&self) -> Vec<PathBuf> {
        self.0.inputs()
    }

    fn gpu_gap(&self) -> Option<String> {
        self.0.gpu_gap()
    }

    fn dry_run(&self, cli: &Cli) -> anyhow::Result<String> {
        let spec = self.filtered(&cli.filter)?;
        let mut out = String::from("axes (--filter AXIS=VALUE):\n");
        for a in spec.axes() {
            out += &format!("  {}: {}\n", a.name(), a.values.join(", "));
        }
        let units = spec.units();
        let units = match cli.shard {
            Some(shard) => {
                let (_, loads) = dealt(&units, shard.count);
                let mine = share(&units, shard);
                out += &share_line(&spec.header().name, shard, mine.len(), "units", &loads);
                mine
            }
            None => units,
        };
        out += &format!("{} units:\n", units.len());
        for u in &units {
            out += &format!("  {}\n", u.label);
        }
        out += &spec.plan(&units)?;
        Ok(out)
    }

    fn folder(&self, cli: &Cli) -> anyhow::Result<String> {
        self.filtered(&cli.filter)?;
        let name = &self.0.header().name;
        Ok(match cli.filter.as_slice() {
            [] => name.clone(),
            f => format!("{name}--{}", filter::label(f)),
        })
    }

    fn run(&self, run: &mut RunContext) -> anyhow::Result<Finished> {
        self.run_unlocated(run).map_err(|e| self.0.locate(e))
    }
}
