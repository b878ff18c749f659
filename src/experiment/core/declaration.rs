//! What a kind declares to run on the core ([`Declaration`]): its axes, its units of work, how
//! one unit is measured, and its report; and what names a unit in a journal or a shard: its key
//! under the experiment's context ([`unit_key`]) and the identity of a whole set of units.

use super::filter::{Axis, AxisKey};
use super::shard::{deal, Cost};
use crate::experiment::contract::RunContext;
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

    /// Takes the settings kept in the tuning.csv at `path` (`--tuning`) in place of tuning them
    /// again; the file becomes one of its inputs. Kinds that tune nothing refuse it.
    fn reuse_tuning(&mut self, _path: &Path) -> Result<(), String> {
        Err(format!(
            "--tuning: `{}` experiments tune no structure",
            self.header().kind.name()
        ))
    }

    /// What, beside its label, determines `unit`'s outcome on `adapter`, where that is less than
    /// the default (every input's content and every axis's values): a unit keyed by it is taken
    /// from the journal after edits that cannot change it (a sweep's group after another scheme
    /// is added). It must name the device and the build.
    fn unit_context(&self, _unit: &Unit, _adapter: &AdapterInfo) -> Option<String> {
        None
    }

    /// `e` located at the experiment's key where it is a refusal known only while the run
    /// goes (a device's binding limit: [`crate::render::limit::DeviceLimit`]); kinds without
    /// such places return it as it is, and it still exits with status 2.
    fn locate(&self, e: anyhow::Error) -> anyhow::Error {
        e
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
