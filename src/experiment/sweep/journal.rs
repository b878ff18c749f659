//! The resumable journal: completed groups are appended (records and bias/variance stats) and
//! flushed as they finish, so an interrupted sweep picks up where it stopped. A group is taken
//! from the journal only if every one of its run keys is there: a changed scene, mesh file, view,
//! ground truth, axis or device gives different keys and the group is rendered again. Timed
//! frames are journaled apart, under the timing settings' key, when the timing phase finishes.

use super::record::Record;
use super::run::{Group, GroupStats};
use super::timing::ConfigTiming;
use crate::metrics::BiasVariance;
use crate::output::table::{append_rows, float, read_rows};
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use std::fs;
use std::path::{Path, PathBuf};

/// A completed group's bias/variance split (groups.csv).
#[derive(Serialize, Deserialize)]
struct GroupRow {
    group_key: String,
    seeds: usize,
    #[serde(with = "float")]
    bias2: f64,
    #[serde(with = "float")]
    bias2_ci95: f64,
    #[serde(with = "float")]
    variance: f64,
}

/// One timed frame of a configuration (timings.csv). A configuration's frames are appended
/// together, numbered from 0; a later set under the same key and settings replaces an earlier
/// one, and a set with fewer than `frames` rows (a torn write) is not taken.
#[derive(Serialize, Deserialize)]
struct FrameRow {
    key: String,
    settings: String,
    frames: usize,
    frame: usize,
    #[serde(with = "float")]
    frame_seconds: f64,
    /// NaN where the clock does not split passes.
    #[serde(with = "float")]
    primary_seconds: f64,
    clock: String,
}

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
        let runs = read_rows::<Record>(&dir.join("runs.csv"))
            .into_iter()
            .map(|r| (r.run_key.clone(), r))
            .collect();
        let groups = read_rows::<GroupRow>(&dir.join("groups.csv"))
            .into_iter()
            .map(|g| {
                let split = BiasVariance {
                    seeds: g.seeds,
                    bias2: g.bias2,
                    bias2_ci: g.bias2_ci95,
                    variance: g.variance,
                };
                (g.group_key, split)
            })
            .collect();
        let mut sets: HashMap<(String, String), (usize, ConfigTiming)> = HashMap::new();
        for f in read_rows::<FrameRow>(&dir.join("timings.csv")) {
            let set = sets
                .entry((f.key, f.settings))
                .or_insert_with(|| (0, ConfigTiming::empty()));
            if f.frame == 0 {
                *set = (f.frames, ConfigTiming::empty());
            }
            let (frames, t) = set;
            if f.frame != t.frame_seconds.len() || f.frames != *frames {
                *frames = usize::MAX;
                continue;
            }
            t.frame_seconds.push(f.frame_seconds);
            if !f.primary_seconds.is_nan() {
                t.primary_seconds.push(f.primary_seconds);
            }
            t.clock = f.clock;
        }
        let timings = sets
            .into_iter()
            .filter(|(_, (frames, t))| *frames == t.frame_seconds.len())
            .map(|(k, (_, t))| (k, t))
            .collect();
        Ok(Journal {
            dir: dir.to_path_buf(),
            runs,
            groups,
            timings,
        })
    }

    /// The timed frames journaled for `key` under timing settings `settings`.
    pub fn timing(&self, key: &str, settings: &str) -> Option<&ConfigTiming> {
        self.timings.get(&(key.to_string(), settings.to_string()))
    }

    /// Appends timed configurations and flushes them to disk.
    pub fn append_timings(&mut self, settings: &str, timings: &[(String, ConfigTiming)]) -> anyhow::Result<()> {
        let rows = timings.iter().flat_map(|(key, t)| {
            t.frame_seconds.iter().enumerate().map(move |(i, &s)| FrameRow {
                key: key.clone(),
                settings: settings.to_string(),
                frames: t.frame_seconds.len(),
                frame: i,
                frame_seconds: s,
                primary_seconds: t.primary_seconds.get(i).copied().unwrap_or(f64::NAN),
                clock: t.clock.clone(),
            })
        });
        append_rows(&self.dir.join("timings.csv"), rows)?;
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
        append_rows(&self.dir.join("runs.csv"), records)?;
        let s = &stats.split;
        let row = GroupRow {
            group_key: group_key.to_string(),
            seeds: s.seeds,
            bias2: s.bias2,
            bias2_ci95: s.bias2_ci,
            variance: s.variance,
        };
        append_rows(&self.dir.join("groups.csv"), [row])?;
        self.groups.insert(group_key.to_string(), *s);
        Ok(())
    }
}
