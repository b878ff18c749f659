//! The resumable journal: completed groups are appended (records and bias/variance stats) and
//! flushed as they finish, so an interrupted sweep picks up where it stopped. A group is taken
//! from the journal only if every one of its run keys is there: a changed scene, mesh file, view,
//! ground truth, axis or device gives different keys and the group is rendered again. Timed
//! frames are journaled apart, under the timing settings' key, when the timing phase finishes.

use super::run::{num, Group, GroupStats, Record, RUN_COLUMNS};
use super::timing::ConfigTiming;
use crate::metrics::BiasVariance;
use std::collections::HashMap;
use std::fs::{self, OpenOptions};
use std::io::Write;
use std::path::{Path, PathBuf};

const GROUP_COLUMNS: [&str; 5] = ["group_key", "seeds", "bias2", "bias2_ci95", "variance"];
const TIMING_COLUMNS: [&str; 5] = ["key", "settings", "frame_seconds", "primary_seconds", "clock"];

/// Appending journal in a folder (`runs.csv`, `groups.csv`, `timings.csv`).
pub struct Journal {
    dir: PathBuf,
    runs: HashMap<String, Record>,
    groups: HashMap<String, BiasVariance>,
    timings: HashMap<(String, String), ConfigTiming>,
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
            timings: HashMap::new(),
        };
        for row in read_rows(&j.dir.join("runs.csv"), &RUN_COLUMNS) {
            j.runs.insert(row[0].clone(), Record(row));
        }
        let float = |s: &str| if s.is_empty() { Some(f64::NAN) } else { s.parse().ok() };
        for row in read_rows(&j.dir.join("groups.csv"), &GROUP_COLUMNS) {
            if let (Ok(seeds), Some(bias2), Some(bias2_ci), Some(variance)) =
                (row[1].parse(), float(&row[2]), float(&row[3]), float(&row[4]))
            {
                let bv = BiasVariance {
                    seeds,
                    bias2,
                    bias2_ci,
                    variance,
                };
                j.groups.insert(row[0].clone(), bv);
            }
        }
        let list = |s: &str| -> Option<Vec<f64>> { s.split_whitespace().map(|x| x.parse().ok()).collect() };
        for row in read_rows(&j.dir.join("timings.csv"), &TIMING_COLUMNS) {
            if let (Some(frame_seconds), Some(primary_seconds)) = (list(&row[2]), list(&row[3])) {
                let t = ConfigTiming {
                    frame_seconds,
                    primary_seconds,
                    clock: row[4].clone(),
                };
                j.timings.insert((row[0].clone(), row[1].clone()), t);
            }
        }
        Ok(j)
    }

    /// The timed frames journaled for `key` under timing settings `settings`.
    pub fn timing(&self, key: &str, settings: &str) -> Option<&ConfigTiming> {
        self.timings.get(&(key.to_string(), settings.to_string()))
    }

    /// Appends timed configurations and flushes them to disk.
    pub fn append_timings(&mut self, settings: &str, timings: &[(String, ConfigTiming)]) -> anyhow::Result<()> {
        let join = |v: &[f64]| v.iter().map(|x| format!("{x:e}")).collect::<Vec<_>>().join(" ");
        let rows = timings.iter().map(|(key, t)| {
            vec![
                key.clone(),
                settings.to_string(),
                join(&t.frame_seconds),
                join(&t.primary_seconds),
                t.clock.clone(),
            ]
        });
        append_rows(&self.dir.join("timings.csv"), &TIMING_COLUMNS, rows)?;
        for (key, t) in timings {
            self.timings.insert((key.clone(), settings.to_string()), t.clone());
        }
        Ok(())
    }

    /// The records and stats of `group` if it completed in an earlier sweep with the same seeds.
    pub fn completed(&self, group: &Group, context: &str) -> Option<(Vec<Record>, GroupStats)> {
        let &split = self.groups.get(&group.key(context))?;
        let records: Option<Vec<Record>> = group
            .runs
            .iter()
            .map(|r| self.runs.get(&r.key(context)).cloned())
            .collect();
        Some((
            records?,
            GroupStats {
                key: group.head().key(context),
                config: group.config(),
                split,
            },
        ))
    }

    /// Appends a completed group under its key `group_key` ([`Group::key`]) and flushes it to
    /// disk (a group already journaled, such as one rendered again for the figures, is not
    /// written twice).
    pub fn append(&mut self, group_key: &str, records: &[Record], stats: &GroupStats) -> anyhow::Result<()> {
        if self.groups.contains_key(group_key) {
            return Ok(());
        }
        append_rows(
            &self.dir.join("runs.csv"),
            &RUN_COLUMNS,
            records.iter().map(|r| r.0.clone()),
        )?;
        let s = &stats.split;
        let row = vec![
            group_key.to_string(),
            s.seeds.to_string(),
            num(s.bias2),
            num(s.bias2_ci),
            num(s.variance),
        ];
        append_rows(&self.dir.join("groups.csv"), &GROUP_COLUMNS, std::iter::once(row))?;
        self.groups.insert(group_key.to_string(), *s);
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
