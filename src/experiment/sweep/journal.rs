//! The resumable journal: completed groups are appended (records and bias/variance stats) and
//! flushed as they finish, so an interrupted sweep picks up where it stopped. A group is taken
//! from the journal only if every one of its run keys is there: a changed scene, mesh file, view,
//! ground truth, axis or device gives different keys and the group is rendered again. Timed
//! frames are journaled apart, under the timing settings' key, when the timing phase finishes.
//! Groups at the figures' ray count also keep what the figures need ([`Figure`]), so they resume
//! like any other.

use super::record::Record;
use super::run::{Group, GroupStats};
use super::timing::ConfigTiming;
use crate::files::write_atomic;
use crate::metrics::BiasVariance;
use crate::output::table::{append_sealed, float, read_sealed};
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use std::fs;
use std::path::{Path, PathBuf};

/// A completed group's bias/variance split (groups.csv), under its key ([`Group::key`]).
#[derive(Clone, Serialize, Deserialize)]
pub(super) struct GroupRow {
    pub(super) group_key: String,
    seeds: usize,
    #[serde(with = "float")]
    bias2: f64,
    #[serde(with = "float")]
    bias2_ci95: f64,
    #[serde(with = "float")]
    variance: f64,
}

impl GroupRow {
    pub(super) fn new(group_key: &str, s: &BiasVariance) -> GroupRow {
        GroupRow {
            group_key: group_key.to_string(),
            seeds: s.seeds,
            bias2: s.bias2,
            bias2_ci95: s.bias2_ci,
            variance: s.variance,
        }
    }

    pub(super) fn split(&self) -> BiasVariance {
        BiasVariance {
            seeds: self.seeds,
            bias2: self.bias2,
            bias2_ci: self.bias2_ci95,
            variance: self.variance,
        }
    }
}

/// What the report's figures take from a group at the figures' ray count: the measuring image
/// of its first rendered seed and, on on-axis scenes, the bin means of its seed-averaged radial
/// profile (the rest of a profile follows from the image and the receivers).
#[derive(Clone, Debug, PartialEq)]
pub struct Figure {
    /// Measuring-view visibility of the first rendered seed.
    pub image: Vec<f32>,
    /// [`crate::metrics::RadialProfile::mean`] over the group's seeds, on on-axis scenes.
    pub profile_means: Option<Vec<f64>>,
}

const FIGURE_MAGIC: &[u8; 8] = b"PNBFIG01";

impl Figure {
    /// Writes the figure atomically to `path`: magic, pixel count, pixels (f32), bin count
    /// (u64::MAX without a profile), bin means (f64), all little-endian.
    pub fn save(&self, path: &Path) -> anyhow::Result<()> {
        let mut bytes = FIGURE_MAGIC.to_vec();
        bytes.extend_from_slice(&(self.image.len() as u64).to_le_bytes());
        self.image
            .iter()
            .for_each(|v| bytes.extend_from_slice(&v.to_le_bytes()));
        let bins = self.profile_means.as_ref().map_or(u64::MAX, |m| m.len() as u64);
        bytes.extend_from_slice(&bins.to_le_bytes());
        for m in self.profile_means.iter().flatten() {
            bytes.extend_from_slice(&m.to_le_bytes());
        }
        write_atomic(path, &bytes)
    }

    /// The figure saved at `path`; `None` when it is missing or not a whole figure file.
    pub fn load(path: &Path) -> Option<Figure> {
        let bytes = fs::read(path).ok()?;
        let rest = bytes.strip_prefix(FIGURE_MAGIC)?;
        let (n, rest) = take_u64(rest)?;
        let (pixels, rest) = rest.split_at_checked(usize::try_from(n).ok()?.checked_mul(4)?)?;
        let image = pixels
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes(c.try_into().expect("4 bytes")))
            .collect();
        let (bins, rest) = take_u64(rest)?;
        let profile_means = match bins {
            u64::MAX if rest.is_empty() => None,
            b if rest.len() as u64 == b.checked_mul(8)? => Some(
                rest.chunks_exact(8)
                    .map(|c| f64::from_le_bytes(c.try_into().expect("8 bytes")))
                    .collect(),
            ),
            _ => return None,
        };
        Some(Figure { image, profile_means })
    }
}

fn take_u64(bytes: &[u8]) -> Option<(u64, &[u8])> {
    let (head, rest) = bytes.split_at_checked(8)?;
    Some((u64::from_le_bytes(head.try_into().ok()?), rest))
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
    frame_s: f64,
    /// NaN where the clock does not split passes.
    #[serde(with = "float")]
    primary_s: f64,
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
        Journal::read(dir)
    }

    /// What the journal in `dir` holds, without creating it (an absent journal holds nothing).
    pub fn read(dir: &Path) -> anyhow::Result<Journal> {
        let runs = read_sealed::<Record>(&dir.join("runs.csv"))?
            .into_iter()
            .map(|r| (r.run_key.clone(), r))
            .collect();
        let groups = read_sealed::<GroupRow>(&dir.join("groups.csv"))?
            .into_iter()
            .map(|g| (g.group_key.clone(), g.split()))
            .collect();
        let mut sets: HashMap<(String, String), (usize, ConfigTiming)> = HashMap::new();
        for f in read_sealed::<FrameRow>(&dir.join("timings.csv"))? {
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
            t.frame_seconds.push(f.frame_s);
            if !f.primary_s.is_nan() {
                t.primary_seconds.push(f.primary_s);
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
                frame_s: s,
                primary_s: t.primary_seconds.get(i).copied().unwrap_or(f64::NAN),
                clock: t.clock.clone(),
            })
        });
        append_sealed(&self.dir.join("timings.csv"), rows)?;
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
        append_sealed(&self.dir.join("runs.csv"), records)?;
        append_sealed(&self.dir.join("groups.csv"), [GroupRow::new(group_key, &stats.split)])?;
        self.groups.insert(group_key.to_string(), stats.split);
        Ok(())
    }

    /// Where the figure of the group keyed `group_key` is kept.
    pub fn figure_path(&self, group_key: &str) -> PathBuf {
        self.dir.join("figures").join(format!("{group_key}.bin"))
    }

    /// The figure kept for the group keyed `group_key`, if any.
    pub fn figure(&self, group_key: &str) -> Option<Figure> {
        Figure::load(&self.figure_path(group_key))
    }

    /// Keeps a group's figure (before its rows are appended, so a journaled group at the
    /// figures' ray count always has one).
    pub fn save_figure(&self, group_key: &str, figure: &Figure) -> anyhow::Result<()> {
        figure.save(&self.figure_path(group_key))
    }
}
