//! Sharded sweeps put back together: the shards' records, bias/variance splits and figures are
//! checked (every run of the sweep present exactly once, from shards that ran the same sweep
//! under the same inputs, device and build) and assembled in the order an unsharded sweep lists
//! them; then the merge builds the references (from the shared ground-truth cache) and runs the
//! timing phase itself, so every frame time the report compares comes from one interleaved phase
//! on one machine, as in an unsharded sweep. Nothing is written unless every check passes.

use super::journal::{Figure, GroupRow, Journal};
use super::record::{Record, Status};
use super::reference::Reference;
use super::run::{context_key, expand, GroupStats};
use super::runner::{by_reference, empty_outcome, figure_samples, keep_figure, time_phase, Outcome};
use super::shard::{assign, sweep_identity, Shard, ShardManifest, GROUPS, MANIFEST, RECORDS};
use super::spec::Spec;
pub use crate::experiment::core::merge::MergeRefused;
use crate::experiment::core::merge::{differing_fields, list_lines, read_shard_manifest, split_count};
use crate::fingerprint::fnv1a;
use crate::output::table::read_rows;
use crate::render::Backend;
use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// One finished shard, read back.
struct ShardFiles {
    dir: PathBuf,
    shard: Shard,
    manifest: ShardManifest,
    records: Vec<Record>,
    groups: HashMap<String, GroupRow>,
    journal: Journal,
}

/// Reads the shard in `dir` (a folder of folders and regular files only), or says why it cannot
/// be taken.
fn read_shard(dir: &Path, identity: &str, context: &str) -> Result<ShardFiles, String> {
    let (shard, manifest) = read_shard_manifest(dir, MANIFEST, |m: &ShardManifest| &m.shard)?;
    if manifest.context != context {
        return Err(format!(
            "{}: shard {shard} ran under another {} than this merge (same inputs, device and build are \
             required: run the merge with the shards' binary on their kind of device)",
            dir.display(),
            differing_fields(&manifest.context, context).join(", ")
        ));
    }
    if manifest.sweep != identity {
        return Err(format!(
            "{}: shard {shard} ran another sweep (experiment file `{}`: other axes, seeds, filters or \
             figures)",
            dir.display(),
            manifest.experiment
        ));
    }
    for (file, want) in [(RECORDS, &manifest.records_fnv1a), (GROUPS, &manifest.groups_fnv1a)] {
        let got = std::fs::read(dir.join(file))
            .ok()
            .map(|b| format!("{:016x}", fnv1a(&b)));
        if got.as_ref() != Some(want) {
            return Err(format!(
                "{}: {file} is not the file shard {shard} wrote (missing or changed since)",
                dir.display()
            ));
        }
    }
    let records: Vec<Record> = read_rows(&dir.join(RECORDS));
    let groups: HashMap<String, GroupRow> = read_rows::<GroupRow>(&dir.join(GROUPS))
        .into_iter()
        .map(|g| (g.group_key.clone(), g))
        .collect();
    if records.len() != manifest.runs {
        return Err(format!(
            "{}: {RECORDS} holds {} runs, {MANIFEST} says {}",
            dir.display(),
            records.len(),
            manifest.runs
        ));
    }
    let journal = Journal::read(&dir.join(".journal")).map_err(|e| format!("{e:#}"))?;
    Ok(ShardFiles {
        dir: dir.to_path_buf(),
        shard,
        manifest,
        records,
        groups,
        journal,
    })
}

/// What to merge: the shard folders, and the split they are expected to form.
pub struct MergePlan<'a> {
    /// Shard folders (`RESULTS/shards/K-of-N`).
    pub dirs: &'a [PathBuf],
    /// N, where the caller knows it (`--merge N`); otherwise read from the shards' manifests,
    /// or their folder names.
    pub split: Option<u32>,
    /// How a shard is rerun, for the refusal's message (e.g. `sweep EXP --shard`).
    pub rerun: &'a str,
    /// Discard the merge's own timing journal first.
    pub fresh: bool,
}

/// Merges the finished shards of `plan` into the outcome of the whole sweep; `results` is the
/// results folder (its `cache/` holds the ground truths, its `.journal/` the merge's timing).
pub fn merge_shards(
    spec: &Spec,
    backend: &mut dyn Backend,
    plan: &MergePlan,
    results: &Path,
    progress: &crate::experiment::progress::Progress,
) -> anyhow::Result<Outcome> {
    let (dirs, rerun) = (plan.dirs, plan.rerun);
    let context = context_key(spec, backend.adapter());
    let identity = sweep_identity(spec, &context);
    let mut problems = String::new();
    let mut shards = Vec::new();
    for dir in dirs {
        match read_shard(dir, &identity, &context) {
            Ok(s) => shards.push(s),
            Err(e) => {
                let _ = writeln!(problems, "{e}");
            }
        }
    }
    let counts: Vec<u32> = shards.iter().map(|s| s.shard.count).collect();
    let count = split_count(plan.split, &counts, dirs);
    if counts.iter().any(|&n| n != count) {
        let listed: Vec<String> = shards
            .iter()
            .map(|s| format!("{} ({})", s.shard, s.dir.display()))
            .collect();
        let _ = writeln!(
            problems,
            "shards of different splits (merging {count}): {}",
            listed.join(", ")
        );
    }
    let groups = expand(spec);
    let owner = assign(spec, &groups, count);

    // Every run key, with the shards holding it.
    let mut found: HashMap<&str, Vec<(usize, usize)>> = HashMap::new();
    for (s, shard) in shards.iter().enumerate() {
        for (i, r) in shard.records.iter().enumerate() {
            found.entry(r.run_key.as_str()).or_default().push((s, i));
        }
    }
    // Per shard: (runs missing, what) lines.
    let mut missing: HashMap<u32, Vec<(usize, String)>> = HashMap::new();
    let mut duplicated: Vec<String> = Vec::new();
    let fig_n = figure_samples(spec);
    // Per group key: its records, split and figure (groups at the figures' ray count).
    let mut taken: HashMap<String, (Vec<Record>, GroupRow, Option<Figure>)> = HashMap::new();
    for (g, &own) in groups.iter().zip(&owner) {
        let gk = g.key(&context);
        let mut records = Vec::new();
        let mut from = None;
        let mut absent = Vec::new();
        for run in &g.runs {
            match found.get(run.key(&context).as_str()).map(Vec::as_slice) {
                None | Some([]) => absent.push(run.seed.to_string()),
                Some([(s, i)]) => {
                    records.push(shards[*s].records[*i].clone());
                    from = Some(*s);
                }
                Some(many) => {
                    let holders: Vec<String> = many
                        .iter()
                        .map(|(s, _)| format!("{} ({})", shards[*s].shard, shards[*s].dir.display()))
                        .collect();
                    duplicated.push(format!(
                        "{} seed={}: in {}",
                        run.config(),
                        run.seed,
                        holders.join(" and ")
                    ));
                }
            }
        }
        if !absent.is_empty() {
            let (seeds, runs) = (absent.join(", "), absent.len());
            missing
                .entry(own)
                .or_default()
                .push((runs, format!("{} seeds=[{seeds}]", g.config())));
        }
        let Some(s) = from.filter(|_| records.len() == g.runs.len()) else {
            continue;
        };
        let Some(row) = shards[s].groups.get(&gk) else {
            missing
                .entry(own)
                .or_default()
                .push((0, format!("{}: its bias/variance split", g.config())));
            continue;
        };
        let rendered = records.iter().any(|r| r.status == Status::Ok);
        let figure = (g.head().samples == fig_n)
            .then(|| shards[s].journal.figure(&gk))
            .flatten();
        if g.head().samples == fig_n && rendered && figure.is_none() {
            missing
                .entry(own)
                .or_default()
                .push((0, format!("{}: its figure", g.config())));
            continue;
        }
        taken.insert(gk, (records, row.clone(), figure));
    }
    if !missing.is_empty() {
        let mut owners: Vec<&u32> = missing.keys().collect();
        owners.sort();
        for own in owners {
            let shard = Shard { index: own + 1, count };
            let lines: Vec<String> = missing[own].iter().map(|(_, l)| l.clone()).collect();
            let runs: usize = missing[own].iter().map(|(n, _)| n).sum();
            let what = match missing[own].iter().filter(|(n, _)| *n == 0).count() {
                0 => format!("{runs} runs missing"),
                f => format!("{runs} runs and {f} group files (`.journal/figures`, {GROUPS}) missing"),
            };
            let _ = writeln!(
                problems,
                "shard {shard} is incomplete ({what}); rerun it: {rerun} {shard}"
            );
            list_lines(&mut problems, &lines);
        }
    }
    if !duplicated.is_empty() {
        let _ = writeln!(problems, "{} runs are in more than one shard:", duplicated.len());
        list_lines(&mut problems, &duplicated);
    }
    if !problems.is_empty() {
        return Err(MergeRefused(format!("cannot merge the shards:\n{}", problems.trim_end())).into());
    }

    let mut out = empty_outcome(spec)?;
    out.resumed = shards.iter().map(|s| s.manifest.resumed).sum();
    for ((lights, radius), share) in by_reference(&groups) {
        let reference = Reference::build(spec, backend, lights, radius, &results.join("cache"), &context)?;
        for g in share {
            let gk = g.key(&context);
            let (records, row, figure) = taken.remove(&gk).expect("checked above");
            if let Some(f) = figure {
                keep_figure(&mut out, &reference, g.config(), f);
            }
            out.failures += records.iter().filter(|r| r.status != Status::Ok).count();
            out.records.extend(records);
            out.groups.push(GroupStats {
                key: g.head().key(&context),
                config: g.config(),
                split: row.split(),
            });
        }
        out.references.push(reference);
    }
    let mut journal = Journal::open(&results.join(".journal"), plan.fresh)?;
    time_phase(spec, backend, &groups, &mut out, &context, &mut journal, progress)?;
    Ok(out)
}
