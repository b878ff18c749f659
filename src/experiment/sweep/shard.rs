//! A sweep split across machines: `--shard K/N` runs the K-th of N deterministic shares of the
//! runs into its own folder (`shards/K-of-N/` under the results folder), never the final
//! outputs; [`super::merge`] puts the shares back together.
//!
//! The unit of a share is a group (a configuration with all its seeds): its per-pixel
//! bias/variance split needs every seed's image in one process. Groups are dealt by expected
//! cost, the rays their frames trace, longest first onto the share that would finish earliest
//! (LPT scheduling), where a share that does not yet hold a group's (lights, radius) pair is also
//! charged that pair's ground-truth render: groups sharing a ground truth stay together exactly
//! where that finishes sooner than spreading them. The deal depends on the experiment alone
//! (axes and their key texts), not on the machine, so every shard and the merge compute it alike.
//!
//! The ground-truth cache (`cache/` under the results folder) is shared by the shards and the
//! merge. A shard that finds no cached ground truth renders it (deterministically: same seed,
//! same device, same bytes) and writes it atomically under a name unique to its host and
//! process, so two shards racing for one entry both end with a whole, identical file; a cache
//! entry is only ever read whole. Shards on machines without a shared file system each fill
//! their own copy; the entries have the same names and contents, so copying them together is
//! safe.

use super::journal::{GroupRow, Journal};
use super::record::{Record, Status};
use super::run::{context_key, expand, Group};
use super::runner;
use super::runner::render_groups;
use super::spec::Spec;
pub use crate::experiment::core::shard::Shard;
use crate::experiment::core::shard::{deal as deal_costs, share_line, Cost};
use crate::fingerprint::fnv1a;
use crate::output::table::write_rows;
use crate::render::{Backend, RenderPlan, View};
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// A finished shard's manifest, written last.
pub const MANIFEST: &str = "shard.toml";
/// A finished shard's records, every run of its share (failed ones included).
pub const RECORDS: &str = "records.csv";
/// A finished shard's bias/variance splits, one per group of its share.
pub const GROUPS: &str = "groups.csv";

/// Rays one frame of `lights` lights at `samples` rays each traces at most: the unit of
/// expected cost.
fn frame_rays(spec: &Spec, lights: u32, samples: u32) -> f64 {
    let scene = spec.scene_with(lights, spec.axes.light_radii[0], samples, &spec.axes.accelerators[0]);
    let view = View {
        camera: &scene.cameras[&spec.measure.camera],
        width: spec.measure.width,
        height: spec.measure.height,
    };
    RenderPlan::new(&scene, view).map_or(0.0, |p| p.max_rays() as f64)
}

/// The share (0-based) each group of `groups` (a sweep's canonical expansion) falls to among
/// `count` shares; see the module documentation.
pub fn assign(spec: &Spec, groups: &[Group], count: u32) -> Vec<u32> {
    deal(spec, groups, count).0
}

/// [`assign`]'s shares, and each share's expected rays (ground truths it renders included):
/// the core's deal ([`deal_costs`]), each group's setup its (lights, radius) ground truth.
pub fn deal(spec: &Spec, groups: &[Group], count: u32) -> (Vec<u32>, Vec<f64>) {
    // Frame rays per (lights, samples): each asks for a scene, so each is computed once.
    let mut memo: HashMap<(u32, u32), f64> = HashMap::new();
    let mut rays = |lights: u32, samples: u32| {
        *memo
            .entry((lights, samples))
            .or_insert_with(|| frame_rays(spec, lights, samples))
    };
    let costs: Vec<Cost> = groups
        .iter()
        .map(|g| {
            let head = g.head();
            let pair = fnv1a(format!("{};{}", head.lights, head.light_radius.to_bits()).as_bytes());
            Cost {
                work: g.runs.len() as f64 * rays(head.lights, head.samples),
                setup: Some((pair, rays(head.lights, spec.ground_truth.samples))),
                tie: head.key_text(),
            }
        })
        .collect();
    deal_costs(&costs, count)
}

/// The groups of the sweep that fall to `shard`, in canonical order.
pub fn share(spec: &Spec, shard: Shard) -> Vec<Group> {
    let groups = expand(spec);
    let shares = assign(spec, &groups, shard.count);
    groups
        .into_iter()
        .zip(shares)
        .filter(|(_, s)| *s == shard.index - 1)
        .map(|(g, _)| g)
        .collect()
}

/// What a finished shard writes last (`shard.toml`): the merge takes a shard only with it, and
/// only if it ran the same sweep under the same context.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct ShardManifest {
    /// `K/N`.
    pub shard: String,
    /// The experiment file it ran (for people; [`Self::sweep`] is what is compared).
    pub experiment: String,
    /// Hash of every run key of the whole (filtered) sweep and the figures' ray count.
    pub sweep: String,
    /// The run keys' context ([`context_key`]): inputs, device and build.
    pub context: String,
    /// Runs in the share.
    pub runs: usize,
    /// Runs that failed (their rows say why).
    pub failed: usize,
    /// Groups taken from the shard's journal rather than rendered.
    pub resumed: usize,
    /// FNV-1a of [`RECORDS`] as written: the merge takes no file changed since.
    pub records_fnv1a: String,
    /// FNV-1a of [`GROUPS`] as written.
    pub groups_fnv1a: String,
    /// Seconds the shard ran.
    pub seconds: f64,
}

/// Identity of a sweep's work: every run key (so the axes, seeds and context) and the figures'
/// ray count (which groups keep figures).
pub fn sweep_identity(spec: &Spec, context: &str) -> String {
    let keys: Vec<String> = expand(spec)
        .iter()
        .flat_map(|g| g.runs.iter().map(|r| r.key(context)))
        .collect();
    let text = format!("{};figures={}", keys.join(","), runner::figure_samples(spec));
    format!("{:016x}", fnv1a(text.as_bytes()))
}

/// What a shard hands back.
pub struct ShardOutcome {
    /// The shard's manifest, as written.
    pub manifest: ShardManifest,
    /// Where it was written.
    pub dir: PathBuf,
}

/// Runs `shard`'s share of the sweep into `shard.dir(results)`: its journal (`.journal/`, from
/// which a killed shard resumes), then `records.csv`, `groups.csv` and, last, `shard.toml`.
/// The ground-truth cache is `results/cache`. No final output is written.
pub fn run_shard(
    spec: &Spec,
    backend: &mut dyn Backend,
    shard: Shard,
    results: &Path,
    fresh: bool,
    progress: &crate::experiment::progress::Progress,
) -> anyhow::Result<ShardOutcome> {
    let started = std::time::Instant::now();
    let dir = shard.dir(results);
    let manifest_path = dir.join(MANIFEST);
    // A manifest left by an earlier run would vouch for files this run is about to replace.
    if manifest_path.exists() {
        std::fs::remove_file(&manifest_path)?;
    }
    let context = context_key(spec, backend.adapter());
    let groups = share(spec, shard);
    let mut journal = Journal::open(&dir.join(".journal"), fresh)?;
    let out = render_groups(
        spec,
        backend,
        &groups,
        &mut journal,
        &results.join("cache"),
        &context,
        progress,
    )?;
    let hash =
        |file: &str| -> anyhow::Result<String> { Ok(format!("{:016x}", fnv1a(&std::fs::read(dir.join(file))?))) };
    write_rows(&dir.join(RECORDS), &out.records)?;
    let rows = out.groups.iter().map(|stats| {
        let group = groups
            .iter()
            .find(|g| g.head().key(&context) == stats.key)
            .expect("a split per group");
        GroupRow::new(&group.key(&context), &stats.split)
    });
    write_rows(&dir.join(GROUPS), rows)?;
    let manifest = ShardManifest {
        shard: shard.to_string(),
        experiment: spec.path.display().to_string(),
        sweep: sweep_identity(spec, &context),
        context,
        runs: out.records.len(),
        failed: out.records.iter().filter(|r: &&Record| r.status != Status::Ok).count(),
        resumed: out.resumed,
        records_fnv1a: hash(RECORDS)?,
        groups_fnv1a: hash(GROUPS)?,
        seconds: started.elapsed().as_secs_f64(),
    };
    crate::files::write_atomic(&manifest_path, toml::to_string(&manifest)?.as_bytes())?;
    Ok(ShardOutcome { manifest, dir })
}

/// What `--dry-run --shard K/N` prints: the share's configurations and its expected rays.
pub fn dry_run(spec: &Spec, shard: Shard) -> String {
    let groups = expand(spec);
    let (shares, rays) = deal(spec, &groups, shard.count);
    let mine: Vec<&Group> = groups
        .iter()
        .zip(&shares)
        .filter(|(_, &s)| s == shard.index - 1)
        .map(|(g, _)| g)
        .collect();
    let runs: usize = mine.iter().map(|g| g.runs.len()).sum();
    let what = format!(
        "runs in {} configurations (units: a configuration with its seeds)",
        mine.len()
    );
    let mut out = share_line(&spec.name, shard, runs, &what, &rays);
    for g in mine {
        let seeds: Vec<String> = g.runs.iter().map(|r| r.seed.to_string()).collect();
        out += &format!("  {} seeds=[{}]\n", g.config(), seeds.join(", "));
    }
    out
}
