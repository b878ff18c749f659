//! What every merge of shards shares: the refusal (exit status 4), the shard folders `--merge`
//! names, the command that reruns a shard, and how a refusal lists what is missing.

use super::shard::{Shard, MAX_SHARDS};
use crate::experiment::cli::{BadInput, Cli};
use clap::ValueEnum;
use serde::de::DeserializeOwned;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

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
