//! Whether a frame-time experiment's scenes and structures fit in the memory available, by each
//! structure's own lower bound, before anything is generated or built.

use super::scenes::Generator;
use crate::accel::memory::bytes;
use crate::accel::AccelSettings;
use crate::config::{ConfigError, Seg, Source};
use crate::key_path;
use std::collections::BTreeMap;

/// Bytes of one copy of a generated scene per triangle: three f64 corners and an object id.
const SCENE_BYTES_PER_TRIANGLE: u64 = 80;

/// Every structure (`candidates`, the first of each kept) fits in the memory available over every
/// scene of `generator`, with a copy of the scene per way it follows a moving part where one
/// `moves`; `tables` are the file's `[accel.NAME]` tables (an error is put where a structure's
/// parameters are given).
pub fn check_memory(
    source: &Source,
    generator: &Generator,
    candidates: &[Vec<AccelSettings>],
    moves: bool,
    tables: &BTreeMap<String, toml::Table>,
) -> Result<(), ConfigError> {
    let counts = generator.counts();
    let available = crate::accel::memory::available();
    // One scene is held at a time, with its triangle list, a copy per structure and every
    // structure built over it (with a moving part, once per way it follows the part); before
    // that, one structure's tuning candidates together.
    let variants = |s: &AccelSettings| {
        if moves {
            crate::accel::registered(s.name).map_or(1, |r| r.updates.len())
        } else {
            1
        }
    };
    for (k, &n) in counts.iter().enumerate() {
        let copies = candidates
            .iter()
            .map(|c| variants(&c[0]))
            .sum::<usize>()
            .max(candidates.iter().map(Vec::len).max().unwrap_or(1));
        let scene = (2 + copies) as u64 * SCENE_BYTES_PER_TRIANGLE * n as u64;
        let each =
            |c: &Vec<AccelSettings>| -> Vec<u64> { c.iter().map(|s| crate::accel::memory::estimate(s, n)).collect() };
        let kept: u64 = candidates
            .iter()
            .map(|c| variants(&c[0]) as u64 * each(c).into_iter().max().unwrap_or(0))
            .sum();
        let tuning = candidates
            .iter()
            .map(|c| each(c).into_iter().sum::<u64>())
            .max()
            .unwrap_or(0);
        let structures = kept.max(tuning);
        if let Some(budget) = available.filter(|b| scene + structures > b.bytes) {
            let at: Vec<Seg> = match generator {
                Generator::Classroom => key_path!["structures"].to_vec(),
                Generator::RandomTriangles { .. } => key_path!["scene", "triangles", k].to_vec(),
            };
            return Err(source.error(
                    &at,
                    format!(
                        "{n} triangles with every structure built over them need at least {} ({} of scene copies, {} of structures), more than {}",
                        bytes(scene + structures),
                        bytes(scene),
                        bytes(structures),
                        budget.describe()
                    ),
                ));
        }
    }
    for (i, s) in candidates
        .iter()
        .enumerate()
        .flat_map(|(i, c)| c.iter().map(move |s| (i, s)))
    {
        for &n in &counts {
            crate::accel::memory::check(s, n, available).map_err(|e| {
                let at = if tables.contains_key(s.name) {
                    key_path!["accel", s.name]
                } else {
                    key_path!["structures", i]
                };
                source.error(&at, e)
            })?;
        }
    }
    Ok(())
}
