//! The resumable journal: completed groups are appended (records and bias/variance stats) and
//! flushed as they finish, so an interrupted sweep picks up where it stopped. A group is taken
//! from the journal only if every one of its run keys is there: a changed scene, view, ground
//! truth or axis gives different keys and the group is rendered again.

use super::run::{num, Group, Record, RUN_COLUMNS};
use super::runner::GroupStats;
use std::collections::HashMap;
use std::fs::{self, OpenOptions};
use std::io::Write;
use std::path::{Path, PathBuf};

const GROUP_COLUMNS: [&str; 4] = ["group_key", "seeds", "bias2", "variance"];

/// Appending journal in a folder (`runs.csv`, `groups.csv`).
pub struct Journal {
    dir: PathBuf,
    runs: HashMap<String, Record>,
    groups: HashMap<String, (usize, f64, f64)>,
}

impl Journal {
    /// Opens (creating) the journal; `fresh` discards what it held.
    pub fn open(dir: &Path, fresh: bool) -> anyhow::Result<Journal> {
        if fresh && dir.exists() {
            fs::remove_dir_all(dir)?;
        }
        fs::create_dir_all(dir)?;
        let mut j = Journal {
            dir: dir.to_path_buf(),
            runs: HashMap::new(),
            groups: HashMap::new(),
        };
        for row in read_rows(&j.dir.join("runs.csv"), &RUN_COLUMNS) {
            j.runs.insert(row[0].clone(), Record(row));
        }
        for row in read_rows(&j.dir.join("groups.csv"), &GROUP_COLUMNS) {
            if let (Ok(k), Ok(b), Ok(v)) = (row[1].parse(), row[2].parse::<f64>(), row[3].parse::<f64>()) {
                j.groups.insert(row[0].clone(), (k, b, v));
            }
        }
        Ok(j)
    }

    /// The records and stats of `group` if it completed in an earlier sweep.
    pub fn completed(&self, group_key: &str, group: &Group, context: &str) -> Option<(Vec<Record>, GroupStats)> {
        let &(seeds, bias2, variance) = self.groups.get(group_key)?;
        let records: Option<Vec<Record>> = group
            .runs
            .iter()
            .map(|r| self.runs.get(&r.key(context)).cloned())
            .collect();
        Some((
            records?,
            GroupStats {
                key: group_key.to_string(),
                run: *group.head(),
                seeds,
                bias2,
                variance,
            },
        ))
    }

    /// Appends a completed group and flushes it to disk (a group already journaled, such as one
    /// rendered again for the figures, is not written twice).
    pub fn append(&mut self, records: &[Record], stats: &GroupStats) -> anyhow::Result<()> {
        if self.groups.contains_key(&stats.key) {
            return Ok(());
        }
        append_rows(
            &self.dir.join("runs.csv"),
            &RUN_COLUMNS,
            records.iter().map(|r| r.0.clone()),
        )?;
        let row = vec![
            stats.key.clone(),
            stats.seeds.to_string(),
            num(stats.bias2),
            num(stats.variance),
        ];
        append_rows(&self.dir.join("groups.csv"), &GROUP_COLUMNS, std::iter::once(row))?;
        self.groups
            .insert(stats.key.clone(), (stats.seeds, stats.bias2, stats.variance));
        Ok(())
    }
}

/// Rows of a CSV journal whose header matches `columns`; a torn last line (from a crash) and
/// rows of the wrong width are dropped.
fn read_rows(path: &Path, columns: &[&str]) -> Vec<Vec<String>> {
    let Ok(text) = fs::read_to_string(path) else {
        return vec![];
    };
    let complete = &text[..text.rfind('\n').map_or(0, |i| i + 1)];
    let mut reader = csv::ReaderBuilder::new()
        .flexible(true)
        .from_reader(complete.as_bytes());
    match reader.headers() {
        Ok(h) if h.iter().eq(columns.iter().copied()) => {}
        _ => return vec![],
    }
    reader
        .records()
        .filter_map(Result::ok)
        .filter(|r| r.len() == columns.len())
        .map(|r| r.iter().map(String::from).collect())
        .collect()
}

fn append_rows(path: &Path, columns: &[&str], rows: impl Iterator<Item = Vec<String>>) -> anyhow::Result<()> {
    let new = !path.exists();
    let mut f = OpenOptions::new().create(true).append(true).open(path)?;
    let mut w = csv::WriterBuilder::new().from_writer(Vec::new());
    if new {
        w.write_record(columns)?;
    }
    for r in rows {
        w.write_record(&r)?;
    }
    f.write_all(&w.into_inner()?)?;
    f.sync_data()?;
    Ok(())
}
