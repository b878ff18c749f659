//! `--merge`: the finished shards put back together. A shard is taken only with its manifest
//! (written last), only if it ran the same units under the same context, and only the unit files
//! it lists, unchanged; anything missing, duplicated or foreign is refused (exit status 4) with
//! the command that reruns the shard.

use super::declaration::{context, dealt, identity, unit_key, Declaration};
use super::journal::{Measured, UnitFile, UnitJournal};
use super::shard::{Shard, MAX_SHARDS};
use crate::experiment::cli::{BadInput, Cli};
use crate::experiment::contract::RunContext;
use crate::fingerprint::fnv1a;
use clap::ValueEnum;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

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
    /// The keys' context ([`super::declaration::context`]): inputs, axes, device and build.
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

/// A shard's manifest file.
pub const SHARD_MANIFEST: &str = "shard.toml";

/// The outcomes of every unit, from the shards `run.cli.merge` names, with the machines they ran
/// on; or a refusal listing what is missing, duplicated or foreign and the shards to rerun.
pub(super) fn merge_units<D: Declaration>(
    spec: &D,
    run: &mut RunContext,
) -> anyhow::Result<(Measured<D::Outcome>, Vec<String>)> {
    let (dirs, given) = shard_dirs(&run.cli.merge, run.home)?;
    let units = spec.units();
    let context = context(spec, run.backend.adapter())?;
    let identity = identity(spec, &context, run.backend.adapter(), &units);
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
    let (owner, _) = dealt(&units, count);
    let mut held: HashMap<&str, Vec<usize>> = HashMap::new();
    for (s, (_, _, m)) in shards.iter().enumerate() {
        for f in &m.units {
            held.entry(f.key.as_str()).or_default().push(s);
        }
    }
    let rerun = rerun_command(run.cli);
    let mut missing: Vec<Vec<String>> = vec![Vec::new(); count as usize];
    let mut duplicated = Vec::new();
    let mut outcomes = Vec::new();
    let mut failed = 0;
    for (unit, &own) in units.iter().zip(&owner) {
        let key = unit_key(spec, &context, run.backend.adapter(), unit);
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
                    Some(o) => {
                        failed += spec.failed(&o);
                        outcomes.push(o)
                    }
                    None => {
                        let _ = writeln!(
                            problems,
                            "{}: the unit `{}` is not the file shard {shard} wrote (missing or changed since); \
                             rerun it: {rerun} {shard}",
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
    let measured = Measured {
        outcomes,
        resumed,
        failed,
        files: Vec::new(),
    };
    Ok((measured, machines))
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

/// The shards given cannot make the experiment: the message lists what is missing, duplicated or
/// mismatched, and the shards to rerun.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct MergeRefused(pub String);

/// The shard folders `--merge` names, and N where it was given: a number alone stands for every
/// shard of an N-way split under the results folder `out`.
pub fn shard_dirs(merge: &[PathBuf], out: &Path) -> anyhow::Result<(Vec<PathBuf>, Option<u32>)> {
    let count = match merge {
        [one] => one.to_str().and_then(|s| s.parse::<u32>().ok()),
        _ => None,
    };
    match count {
        Some(0) => Err(BadInput("--merge N needs N >= 1".into()).into()),
        Some(n) if n > MAX_SHARDS => Err(BadInput(format!("--merge N: at most {MAX_SHARDS} shards")).into()),
        Some(n) => Ok((
            (1..=n).map(|index| Shard { index, count: n }.dir(out)).collect(),
            Some(n),
        )),
        None => Ok((merge.to_vec(), None)),
    }
}

/// N of a folder named `K-of-N`.
pub fn split_of_name(dir: &Path) -> Option<u32> {
    let name = dir.file_name()?.to_str()?;
    name.split_once("-of-")?.1.parse().ok()
}

/// The split the shards form: `given` (`--merge N`), else the first shard's, else the first
/// folder name's, else 1.
pub fn split_count(given: Option<u32>, counts: &[u32], dirs: &[PathBuf]) -> u32 {
    given
        .or(counts.first().copied())
        .or_else(|| dirs.iter().find_map(|d| split_of_name(d)))
        .unwrap_or(1)
}

/// `text` as one shell word.
fn shell_word(text: &str) -> String {
    let plain = |c: char| c.is_ascii_alphanumeric() || "/._-=,:+@%".contains(c);
    if !text.is_empty() && text.chars().all(plain) {
        text.to_string()
    } else {
        format!("'{}'", text.replace('\'', r"'\''"))
    }
}

/// How to rerun one shard of this experiment (`... --shard`, K/N to follow), for the merge's
/// refusal.
pub fn rerun_command(cli: &Cli) -> String {
    let mut words = vec!["sweep".to_string(), cli.experiment.display().to_string()];
    if let Some(out) = &cli.out {
        words.extend(["--out".into(), out.display().to_string()]);
    }
    if let Some(b) = cli.backend {
        let name = b.to_possible_value().expect("a named value").get_name().to_string();
        words.extend(["--backend".into(), name]);
    }
    for f in &cli.filter {
        words.extend(["--filter".into(), f.to_string()]);
    }
    if let Some(t) = &cli.tuning {
        words.extend(["--tuning".into(), t.display().to_string()]);
    }
    words.push("--shard".into());
    words.iter().map(|w| shell_word(w)).collect::<Vec<_>>().join(" ")
}

/// Lines of a refusal listing units of work: at most this many, then a count of the rest.
const LISTED: usize = 40;

/// Appends `lines` to a refusal, indented, at most [`LISTED`] of them.
pub fn list_lines(out: &mut String, lines: &[String]) {
    for r in lines.iter().take(LISTED) {
        let _ = writeln!(out, "    {r}");
    }
    if lines.len() > LISTED {
        let _ = writeln!(out, "    ... and {} more", lines.len() - LISTED);
    }
}

/// Fields of two `name=value;...` context texts whose values differ.
pub fn differing_fields(a: &str, b: &str) -> Vec<String> {
    let fields = |s: &str| -> Vec<(String, String)> {
        s.split(';')
            .map(|f| f.split_once('=').unwrap_or((f, "")))
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect()
    };
    let (fa, fb) = (fields(a), fields(b));
    let mut out: Vec<String> = fa
        .iter()
        .filter(|(k, v)| fb.iter().find(|(kb, _)| kb == k).is_none_or(|(_, vb)| vb != v))
        .map(|(k, _)| k.clone())
        .collect();
    if out.is_empty() && a != b {
        out.push("context".into());
    }
    out
}

/// The manifest `name` a finished shard in `dir` wrote last (the folder holding only folders and
/// regular files), and the shard its key `shard` names; or why the shard cannot be taken.
pub fn read_shard_manifest<M: DeserializeOwned>(
    dir: &Path,
    name: &str,
    shard_of: impl Fn(&M) -> &str,
) -> Result<(Shard, M), String> {
    if !dir.is_dir() {
        return Err(format!("{}: no such shard folder", dir.display()));
    }
    // A shard is read back whole: a link or pipe in it would read outside it or block.
    crate::files::check_plain_tree(dir).map_err(|e| e.to_string())?;
    let path = dir.join(name);
    let text = crate::files::read_regular_text(&path)
        .map_err(|_| format!("{}: no {name}: the shard has not finished", dir.display()))?;
    let m: M = toml::from_str(&text).map_err(|e| format!("{}: unreadable: {e}", path.display()))?;
    let shard = shard_of(&m)
        .parse()
        .map_err(|e| format!("{}: key `shard`: {e}", path.display()))?;
    Ok((shard, m))
}
