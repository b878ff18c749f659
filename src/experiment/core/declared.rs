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

use super::filter::{self, Axis, Filter};
use super::merge::{
    differing_fields, list_lines, read_shard_manifest, rerun_command, shard_dirs, split_count, MergeRefused,
};
use super::shard::{deal, share_line, Cost, Shard};
use crate::experiment::cli::{BadInput, Cli};
use crate::experiment::contract::{Accepts, Experiment, Finished, RunContext};
use crate::experiment::header::Header;
use crate::experiment::progress::Progress;
use crate::fingerprint::{build_id, fnv1a};
use crate::render::{AdapterInfo, Backend, BackendChoice};
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use std::fmt::Write as _;
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

    /// Its axes and their values, in the file's order.
    fn axes(&self) -> Vec<Axis>;

    /// Keeps, on axis `axis` (an index into [`Declaration::axes`]), only the values at `keep`.
    fn restrict(&mut self, axis: usize, keep: &[usize]);

    /// Its units, in canonical order: the order outcomes reach the report.
    fn units(&self) -> Vec<Unit>;

    /// What `--dry-run` prints about `units` (their plans, sizes); the core adds the axes.
    fn plan(&self, units: &[Unit]) -> anyhow::Result<String>;

    /// Measures one unit.
    fn measure(&self, unit: &Unit, backend: &mut dyn Backend, progress: &Progress) -> anyhow::Result<Self::Outcome>;

    /// Writes the outputs from every unit's outcome (canonical order) into `run.out`; returns
    /// the kind's table for the manifest.
    fn report(&self, outcomes: Vec<Self::Outcome>, run: &RunContext) -> anyhow::Result<toml::Table>;
}

/// A declared kind as an experiment.
pub struct Declared<D>(pub D);

/// A shard's manifest, written last: the merge takes a shard only with it, only if it ran the
/// same units under the same context, and only the unit files it lists, unchanged.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct ShardManifest {
    /// `K/N`.
    pub shard: String,
    /// The experiment file it ran (for people; `identity` is what is compared).
    pub experiment: String,
    /// Hash of every unit key of the whole (filtered) experiment.
    pub identity: String,
    /// The keys' context ([`context`]): inputs, axes, device and build.
    pub context: String,
    /// The machine it ran on (times from shards on unlike machines are not comparable).
    pub machine: String,
    /// Units taken from the shard's journal rather than measured.
    pub resumed: usize,
    /// Seconds the shard ran.
    pub seconds: f64,
    /// Every unit of the share: its key and the FNV-1a of its journal file.
    pub units: Vec<UnitFile>,
}

/// One journaled unit a shard holds.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct UnitFile {
    /// The unit's key.
    pub key: String,
    /// FNV-1a of its journal file as written.
    pub fnv1a: String,
}

/// A shard's manifest file.
pub const SHARD_MANIFEST: &str = "shard.toml";

/// What a unit's journal file holds.
#[derive(Serialize, Deserialize)]
struct Journaled<O> {
    key: String,
    label: String,
    outcome: O,
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
        .map(|a| format!("{}:{}", a.name, a.values.join(",")))
        .collect();
    Ok(format!(
        "inputs={};axes={:016x};device={:?};build={:016x}",
        inputs.join(","),
        fnv1a(axes.join("|").as_bytes()),
        (&adapter.backend, &adapter.name, &adapter.driver, &adapter.api),
        build_id()
    ))
}

/// A unit's key under `context`.
pub fn unit_key(context: &str, unit: &Unit) -> String {
    format!("{:016x}", fnv1a(format!("{context};{}", unit.label).as_bytes()))
}

/// Hash of every unit key: which work an experiment (as filtered) is.
fn identity(context: &str, units: &[Unit]) -> String {
    let keys: Vec<String> = units.iter().map(|u| unit_key(context, u)).collect();
    format!("{:016x}", fnv1a(keys.join(",").as_bytes()))
}

/// The first line of a journaled unit's file, before the FNV-1a of the rest.
const CHECK: &str = "# fnv1a ";

/// A folder of journaled units, one TOML file each, written atomically as each finishes.
struct UnitJournal {
    dir: PathBuf,
}

impl UnitJournal {
    fn open(dir: &Path, fresh: bool) -> anyhow::Result<UnitJournal> {
        if fresh && dir.exists() {
            std::fs::remove_dir_all(dir)?;
        }
        std::fs::create_dir_all(dir)?;
        Ok(UnitJournal { dir: dir.into() })
    }

    fn path(&self, key: &str) -> PathBuf {
        self.dir.join(format!("{key}.toml"))
    }

    /// The outcome journaled under `key`: none if no file is there, and a refusal if one is
    /// there but is not the file this run wrote (its first line, `# fnv1a HASH`, hashes the rest
    /// as written: an edited, cut or foreign file would otherwise be taken as measured).
    fn read<O: DeserializeOwned>(path: &Path, key: &str) -> anyhow::Result<Option<O>> {
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

/// Measures `units` (or takes them from `journal`), each outcome read back from its file; returns
/// the outcomes in `units`' order, how many were resumed, and each unit's key and file hash.
fn measure_all<D: Declaration>(
    spec: &D,
    units: &[Unit],
    context: &str,
    journal: &UnitJournal,
    backend: &mut dyn Backend,
    progress: &Progress,
) -> anyhow::Result<(Vec<D::Outcome>, usize, Vec<UnitFile>)> {
    // Every journaled unit is read before anything is measured: a damaged one is refused
    // before hours of work, not after.
    let mut journaled = Vec::with_capacity(units.len());
    for unit in units {
        let key = unit_key(context, unit);
        let earlier = UnitJournal::read::<D::Outcome>(&journal.path(&key), &key)?;
        journaled.push((key, earlier));
    }
    let bar = progress.bar("units", units.len() as u64);
    let (mut outcomes, mut resumed, mut files) = (Vec::new(), 0, Vec::new());
    for (unit, (key, earlier)) in units.iter().zip(journaled) {
        let path = journal.path(&key);
        let outcome = match earlier {
            Some(o) => {
                resumed += 1;
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
        files.push(UnitFile {
            key,
            fnv1a: format!("{:016x}", fnv1a(&bytes)),
        });
        outcomes.push(outcome);
        bar.inc(1);
    }
    bar.finish();
    if resumed > 0 {
        tracing::info!("{resumed} of {} units taken from the journal", units.len());
    }
    Ok((outcomes, resumed, files))
}

impl<D: Declaration> Declared<D> {
    /// The declaration restricted by the command line's filters.
    fn filtered(&self, filters: &[Filter]) -> Result<D, BadInput> {
        let mut spec = self.0.clone();
        let axes = spec.axes();
        for (axis, keep) in filter::select(&axes, filters, filter::same_text).map_err(BadInput)? {
            // An earlier axis's restriction may have thinned this axis's values (fps: a scene
            // kept takes only its own light counts), so the kept values are found again.
            let kept: Vec<&String> = keep.iter().map(|&i| &axes[axis].values[i]).collect();
            let now: Vec<usize> = spec.axes()[axis]
                .values
                .iter()
                .enumerate()
                .filter(|(_, v)| kept.contains(v))
                .map(|(i, _)| i)
                .collect();
            spec.restrict(axis, &now);
        }
        Ok(spec)
    }

    /// `units`, and each one's share among `count`.
    fn dealt(units: &[Unit], count: u32) -> (Vec<u32>, Vec<f64>) {
        let costs: Vec<Cost> = units.iter().map(|u| u.cost.clone()).collect();
        deal(&costs, count)
    }

    /// The share of `units` that falls to `shard`.
    fn share(units: &[Unit], shard: Shard) -> Vec<Unit> {
        let (shares, _) = Self::dealt(units, shard.count);
        units
            .iter()
            .zip(shares)
            .filter(|(_, s)| *s == shard.index - 1)
            .map(|(u, _)| u.clone())
            .collect()
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
        let mine = Self::share(&units, shard);
        let journal = UnitJournal::open(&dir.join(".journal"), run.cli.fresh)?;
        let (_, resumed, files) = measure_all(spec, &mine, &context, &journal, run.backend, run.progress)?;
        let manifest = ShardManifest {
            shard: shard.to_string(),
            experiment: run.cli.experiment.display().to_string(),
            identity: identity(&context, &units),
            context,
            machine: crate::experiment::manifest::Machine::current().cpu,
            resumed,
            seconds: started.elapsed().as_secs_f64(),
            units: files,
        };
        crate::files::write_atomic(&manifest_path, toml::to_string(&manifest)?.as_bytes())?;
        tracing::info!(
            "shard {shard}: {} units ({resumed} resumed) in {:.1} s; wrote {}",
            mine.len(),
            manifest.seconds,
            dir.display()
        );
        Ok(Finished::Shard { failed: None })
    }

    /// The outcomes of every unit, from the shards `run.cli.merge` names, with the machines they
    /// ran on and how many units they took from their journals; or a refusal listing what is
    /// missing, duplicated or foreign and the shards to rerun.
    fn merge(&self, spec: &D, run: &mut RunContext) -> anyhow::Result<(Vec<D::Outcome>, Vec<String>, usize)> {
        let (dirs, given) = shard_dirs(&run.cli.merge, run.home)?;
        let units = spec.units();
        let context = context(spec, run.backend.adapter())?;
        let identity = identity(&context, &units);
        let mut problems = String::new();
        let mut shards: Vec<(PathBuf, Shard, ShardManifest)> = Vec::new();
        for dir in &dirs {
            match read_shard(dir, &identity, &context) {
                Ok((shard, m)) => shards.push((dir.clone(), shard, m)),
                Err(e) => {
                    let _ = writeln!(problems, "{e}");
                }
            }
        }
        let counts: Vec<u32> = shards.iter().map(|s| s.1.count).collect();
        let count = split_count(given, &counts, &dirs);
        if counts.iter().any(|&n| n != count) {
            let listed: Vec<String> = shards.iter().map(|s| format!("{} ({})", s.1, s.0.display())).collect();
            let _ = writeln!(
                problems,
                "shards of different splits (merging {count}): {}",
                listed.join(", ")
            );
        }
        let (owner, _) = Self::dealt(&units, count);
        let mut held: HashMap<&str, Vec<usize>> = HashMap::new();
        for (s, (_, _, m)) in shards.iter().enumerate() {
            for f in &m.units {
                held.entry(f.key.as_str()).or_default().push(s);
            }
        }
        let mut missing: Vec<Vec<String>> = vec![Vec::new(); count as usize];
        let mut duplicated = Vec::new();
        let mut outcomes = Vec::new();
        for (unit, &own) in units.iter().zip(&owner) {
            let key = unit_key(&context, unit);
            match held.get(key.as_str()).map(Vec::as_slice) {
                None | Some([]) => missing[own as usize].push(unit.label.clone()),
                Some([s]) => {
                    let (dir, shard, m) = &shards[*s];
                    let path = dir.join(".journal").join(format!("{key}.toml"));
                    let want = &m.units.iter().find(|f| f.key == key).expect("held").fnv1a;
                    let bytes = crate::files::read_regular(&path).ok();
                    let outcome = bytes
                        .filter(|b| format!("{:016x}", fnv1a(b)) == *want)
                        .and_then(|_| UnitJournal::read::<D::Outcome>(&path, &key).ok().flatten());
                    match outcome {
                        Some(o) => outcomes.push(o),
                        None => {
                            let _ = writeln!(
                                problems,
                                "{}: the unit `{}` is not the file shard {shard} wrote (missing or changed since)",
                                path.display(),
                                unit.label
                            );
                        }
                    }
                }
                Some(many) => {
                    let holders: Vec<String> = many
                        .iter()
                        .map(|&s| format!("{} ({})", shards[s].1, shards[s].0.display()))
                        .collect();
                    duplicated.push(format!("{}: in {}", unit.label, holders.join(" and ")));
                }
            }
        }
        let rerun = rerun_command(run.cli);
        for (own, lines) in missing.iter().enumerate().filter(|(_, l)| !l.is_empty()) {
            let shard = Shard {
                index: own as u32 + 1,
                count,
            };
            let _ = writeln!(
                problems,
                "shard {shard} is incomplete ({} units missing); rerun it: {rerun} {shard}",
                lines.len()
            );
            list_lines(&mut problems, lines);
        }
        if !duplicated.is_empty() {
            let _ = writeln!(problems, "{} units are in more than one shard:", duplicated.len());
            list_lines(&mut problems, &duplicated);
        }
        if !problems.is_empty() {
            return Err(MergeRefused(format!("cannot merge the shards:\n{}", problems.trim_end())).into());
        }
        let mut machines: Vec<String> = shards.iter().map(|s| s.2.machine.clone()).collect();
        machines.sort();
        machines.dedup();
        if machines.len() > 1 {
            tracing::warn!(
                "the shards ran on {} kinds of machine ({}): each unit's times compare only within it",
                machines.len(),
                machines.join("; ")
            );
        }
        let resumed = shards.iter().map(|s| s.2.resumed).sum();
        Ok((outcomes, machines, resumed))
    }
}

/// Reads the manifest of the shard in `dir` (a folder of folders and regular files only), or
/// says why it cannot be taken.
fn read_shard(dir: &Path, identity: &str, context: &str) -> Result<(Shard, ShardManifest), String> {
    let (shard, m) = read_shard_manifest(dir, SHARD_MANIFEST, |m: &ShardManifest| &m.shard)?;
    if m.context != context {
        return Err(format!(
            "{}: shard {shard} ran under another {} than this merge (same inputs, axes, device and build \
             are required: run the merge with the shards' binary on their kind of device)",
            dir.display(),
            differing_fields(&m.context, context).join(", ")
        ));
    }
    if m.identity != identity {
        return Err(format!(
            "{}: shard {shard} ran other work (experiment file `{}`: other units or filters)",
            dir.display(),
            m.experiment
        ));
    }
    Ok((shard, m))
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
            out += &format!("  {}: {}\n", a.name, a.values.join(", "));
        }
        let units = spec.units();
        let units = match cli.shard {
            Some(shard) => {
                let (_, loads) = Self::dealt(&units, shard.count);
                let mine = Self::share(&units, shard);
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
        let spec = self.filtered(&run.cli.filter)?;
        if let Some(shard) = run.cli.shard {
            return self.run_shard(&spec, shard, run);
        }
        let (outcomes, resumed) = if run.cli.merge.is_empty() {
            let units = spec.units();
            let context = context(&spec, run.backend.adapter())?;
            let journal = UnitJournal::open(&run.home.join(".journal"), run.cli.fresh)?;
            let (outcomes, resumed, _) = measure_all(&spec, &units, &context, &journal, run.backend, run.progress)?;
            (outcomes, resumed)
        } else {
            let (outcomes, machines, resumed) = self.merge(&spec, run)?;
            tracing::info!(
                "merged {} units from shards run on: {}",
                outcomes.len(),
                machines.join("; ")
            );
            (outcomes, resumed)
        };
        let units = outcomes.len();
        let mut details = spec.report(outcomes, run)?;
        // A unit taken from a journal was measured by an earlier process (its times too): the
        // manifest says how many, so a rerun that measured nothing is not read as fresh timing.
        details.insert("units".into(), toml::Value::Integer(units as i64));
        details.insert("units_from_journal".into(), toml::Value::Integer(resumed as i64));
        Ok(Finished::Results { details, failed: None })
    }
}
