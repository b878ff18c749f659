//! The command line's values, `--filter AXIS=VALUE` and `--shard K/N`: what each is and how its
//! text reads. The command line (`cli`) holds them and the experiment core
//! (`core`) acts on them, so they sit below both.

use std::path::{Path, PathBuf};

/// One `AXIS=VALUE` filter, as written; checked against a kind's
/// axes by the experiment core's `filter::select`.
#[derive(Clone, Debug, PartialEq)]
pub struct Filter {
    /// The axis name.
    pub axis: String,
    /// The value as written.
    pub value: String,
}

impl std::str::FromStr for Filter {
    type Err = String;

    fn from_str(s: &str) -> Result<Filter, String> {
        let (axis, value) = s
            .split_once('=')
            .ok_or_else(|| format!("`{s}`: a filter is AXIS=VALUE (the axes are listed by --dry-run)"))?;
        let (axis, value) = (axis.trim(), value.trim());
        if axis.is_empty() || value.is_empty() {
            return Err(format!("`{s}`: a filter is AXIS=VALUE, both non-empty"));
        }
        Ok(Filter {
            axis: axis.into(),
            value: value.into(),
        })
    }
}

impl std::fmt::Display for Filter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}={}", self.axis, self.value)
    }
}

/// `--filter`'s help.
pub const FILTER_HELP: &str = "Run only the work whose AXIS has VALUE (each kind's axes are listed by \
--dry-run: a sweep's scheme, pattern, samples, light_radius, lights, accelerator, seed; ao's mesh, \
structure, issue; frames' scene, shading, viewpoint; fps' scene, lights, resolution; realtime's variant, scheme, \
rays, frames, accumulation, filter, seed); repeat to keep \
several values or restrict several axes";

/// Most shards an experiment splits into.
pub const MAX_SHARDS: u32 = 10_000;

/// The K-th of N shares (1 <= K <= N), as `--shard K/N` and Slurm's array index give it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Shard {
    /// K, from 1.
    pub index: u32,
    /// N.
    pub count: u32,
}

impl std::str::FromStr for Shard {
    type Err = String;

    fn from_str(s: &str) -> Result<Shard, String> {
        let bad = || format!("expected K/N with 1 <= K <= N <= {MAX_SHARDS} (e.g. 2/8), got `{s}`");
        let (k, n) = s.split_once('/').ok_or_else(bad)?;
        let (index, count) = (k.trim().parse::<u32>(), n.trim().parse::<u32>());
        match (index, count) {
            (Ok(index), Ok(count)) if (1..=count).contains(&index) && count <= MAX_SHARDS => Ok(Shard { index, count }),
            _ => Err(bad()),
        }
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

impl Shard {
    /// The shard's folder under a results folder: `shards/K-of-N`.
    pub fn dir(&self, results: &Path) -> PathBuf {
        results.join("shards").join(format!("{}-of-{}", self.index, self.count))
    }
}
