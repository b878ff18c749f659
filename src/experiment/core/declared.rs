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

use super::filter::{self, Axis, AxisKey, Filter};
use super::journal::{measure_all, Measured, UnitJournal};
use super::merge::{merge_units, ShardManifest, SHARD_MANIFEST};
use super::shard::{deal, share_line, Cost, Shard};
use crate::experiment::cli::{BadInput, Cli};
use crate::experiment::contract::{Accepts, Experiment, Finished, RunContext};
use crate::experiment::header::Header;
use crate::experiment::progress::Progress;
use crate::fingerprint::{build_id, fnv1a};
use crate::render::{AdapterInfo, Backend, BackendChoice};
use serde::de::DeserializeOwned;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// One unit of work: measured whole, on one machine.
#[derive(Clone, Debug, PartialEq)]
pub struct Unit {
    /// Where it lies in the kind's own terms (indices into its lists), for its measure.
    pub at: Vec<usize>,
    /// `axis=value ...`: what it covers, for people (dry runs, refusals, progress) and its key.
    pub label: String,
    /// Its expected cost, for dealing it to a shard.
    pub cost: Cost,
}

/// A kind, declared: the core runs it ([`Declared`]).
pub trait Declaration: Clone {
    /// What measuring one unit yields; journaled (TOML, exact for every float, NaN included),
    /// carried in shards, and handed to the report in canonical unit order.
    type Outcome: Serialize + DeserializeOwned;

    /// The shared keys.
    fn header(&self) -> &Header;

    /// Every file it reads, hashed into the manifest and the units' keys.
    fn inputs(&self) -> Vec<PathBuf>;

    /// Whether it runs on the GPU (otherwise it times the f64 CPU backend and refuses `gpu`).
    fn gpu(&self) -> bool {
        false
    }

    /// The backend where neither the file nor the command line names one.
    fn backend(&self) -> BackendChoice {
        BackendChoice::Auto
    }

    /// What of it the GPU cannot run, at its file and key ([`Experiment::gpu_gap`]).
    fn gpu_gap(&self) -> Option<String> {
        None
    }

    /// Its axes' keys ([`crate::axis_keys!`]).
    type Axis: AxisKey;

    /// Its axes and their values, in the file's order.
    fn axes(&self) -> Vec<Axis<Self::Axis>>;

    /// Keeps, on `axis`, only the values at `keep` (indices into its values, sorted).
    fn restrict(&mut self, axis: Self::Axis, keep: &[usize]);

    /// Its units, in canonical order: the order outcomes reach the report.
    fn units(&self) -> Vec<Unit>;

    /// What `--dry-run` prints about `units` (their plans, sizes); the core adds the axes.
    fn plan(&self, units: &[Unit]) -> anyhow::Result<String>;

    /// Where state that outlives a run may be kept (the results folder: a sweep's ground-truth
    /// cache, shared by its shards and their merge); called once before any unit is measured.
    fn keep_state_in(&mut self, _home: &Path) {}

    /// What, beside its label, determines `unit`'s outcome on `adapter`, where that is less than
    /// the default (every input's content and every axis's values): a unit keyed by it is taken
    /// from the journal after edits that cannot change it (a sweep's group after another scheme
    /// is added). It must name the device and the build.
    fn unit_context(&self, _unit: &Unit, _adapter: &AdapterInfo) -> Option<String> {
        None
    }

    /// Measures one unit.
    fn measure(&self, unit: &Unit, backend: &mut dyn Backend, progress: &Progress) -> anyhow::Result<Self::Outcome>;

    /// Runs of `outcome` that failed and were recorded as such rather than ending the run (a
    /// sweep renders on past a failed run). A unit with failures is measured again on resume,
    /// and the run exits with status 3 naming [`Declaration::FAILURES`].
    fn failed(&self, _outcome: &Self::Outcome) -> usize {
        0
    }

    /// The table whose rows say why runs failed.
    const FAILURES: &'static str = "runs.csv";

    /// Writes the outputs from every unit's outcome (canonical order) into `run.out`; returns
    /// the kind's table for the manifest. It may use the device (a merge renders what no shard
    /// left it, such as a ground truth missing from the cache).
    fn report(&self, outcomes: Vec<Self::Outcome>, run: &mut RunContext) -> anyhow::Result<toml::Table>;
}

/// A declared kind as an experiment.
pub struct Declared<D>(pub D);

/// Everything besides a unit's label that determines its outcome: the content of every input,
/// the axes' values (a filtered run never takes an unfiltered run's unit), the device and the
/// build.
pub fn context<D: Declaration>(spec: &D, adapter: &AdapterInfo) -> anyhow::Result<String> {
    let mut inputs = Vec::new();
    for path in spec.inputs() {
        let bytes = crate::files::read_regular(&path)?;
        inputs.push(format!("{:016x}", fnv1a(&bytes)));
    }
    let axes: Vec<String> = spec
        .axes()
        .iter()
        .map(|a| format!("{}:{}", a.name(), a.values.join(",")))
        .collect();
    Ok(format!(
        "inputs={};axes={:016x};device={:?};build={:016x}",
        inputs.join(","),
        fnv1a(axes.join("|").as_bytes()),
        (&adapter.backend, &adapter.name, &adapter.driver, &adapter.api),
        build_id()
    ))
}

/// A unit's journal key: its label under `context`, or under what the kind says determines it
/// ([`Declaration::unit_context`]).
pub fn unit_key<D: Declaration>(spec: &D, context: &str, adapter: &AdapterInfo, unit: &Unit) -> String {
    let text = match spec.unit_context(unit, adapter) {
        Some(own) => format!("own:{own};{}", unit.label),
        None => format!("{context};{}", unit.label),
    };
    format!("{:016x}", fnv1a(text.as_bytes()))
}

/// Hash of every unit key: which work an experiment (as filtered) is.
pub(super) fn identity<D: Declaration>(spec: &D, context: &str, adapter: &AdapterInfo, units: &[Unit]) -> String {
    let keys: Vec<String> = units.iter().map(|u| unit_key(spec, context, adapter, u)).collect();
    format!("{:016x}", fnv1a(keys.join(",").as_bytes()))
}

/// `units`, and each one's share among `count`.
pub(super) fn dealt(units: &[Unit], count: u32) -> (Vec<u32>, Vec<f64>) {
    let costs: Vec<Cost> = units.iter().map(|u| u.cost.clone()).collect();
    deal(&costs, count)
}

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
    let journal = UnitJournal::open(&home.join(".journal"), fresh)?;
    measure_all(spec, &units, &context, &journal, backend, progress)
}

impl<D: Declaration> Declared<D> {
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
        let measured = measure_all(spec, &mine, &context, &journal, run.backend, run.progress)?;
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
        let journal = dir.join(".journal").display().to_string();
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
        let mut spec = self.filtered(&run.cli.filter)?;
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
        let table = run.home.join(D::FAILURES).display().to_string();
        Ok(Finished::Results {
            details,
            failed: Some((failed, table)),
        })
    }
}
