//! What a frame-time experiment's scenes are made by (`[scene]`): the classroom, or random
//! triangles at several counts from one seed; generated one at a time.

use crate::config::{ConfigError, Source};
use crate::key_path;
use crate::scene::procedural::{classroom, random, Generated};

/// Most triangles a random-triangle scene may ask for.
pub const MAX_TRIANGLES: usize = 16 << 20;

/// What a scene of the experiment is made by.
#[derive(Clone, Debug, PartialEq)]
pub enum Generator {
    /// [`classroom::classroom`].
    Classroom,
    /// [`random::random_triangles`] at each count, from one seed.
    RandomTriangles {
        /// Triangle counts, ascending.
        counts: Vec<usize>,
        /// Generator seed.
        seed: u32,
    },
}

impl Generator {
    /// The generator `name` of `[scene]` with its triangle counts and seed, checked.
    pub fn read(source: &Source, name: &str, triangles: &[usize], seed: u32) -> Result<Generator, ConfigError> {
        let err = |p: &[crate::config::Seg], m: String| source.error(p, m);
        Ok(match name {
            "classroom" => {
                if !triangles.is_empty() {
                    return Err(err(
                        &key_path!["scene", "triangles"],
                        "the classroom has its own triangles; counts apply to random-triangles".into(),
                    ));
                }
                Generator::Classroom
            }
            "random-triangles" => {
                let counts = triangles.to_vec();
                if counts.is_empty() {
                    return Err(err(
                        &key_path!["scene", "triangles"],
                        "list at least one triangle count".into(),
                    ));
                }
                if let Some(i) = (0..counts.len()).find(|&i| counts[i] == 0 || (i > 0 && counts[i] <= counts[i - 1])) {
                    return Err(err(
                        &key_path!["scene", "triangles", i],
                        "counts must be positive and ascending".into(),
                    ));
                }
                if let Some(i) = counts.iter().position(|&n| n > MAX_TRIANGLES) {
                    return Err(err(
                        &key_path!["scene", "triangles", i],
                        format!("at most {MAX_TRIANGLES} triangles"),
                    ));
                }
                Generator::RandomTriangles { counts, seed }
            }
            other => {
                return Err(err(
                    &key_path!["scene", "generator"],
                    format!("unknown generator `{other}`; known: classroom, random-triangles"),
                ))
            }
        })
    }

    /// Triangles in each scene, in scene order.
    pub fn counts(&self) -> Vec<usize> {
        match self {
            Generator::Classroom => vec![classroom::TRIANGLES],
            Generator::RandomTriangles { counts, .. } => counts.clone(),
        }
    }

    /// How many scenes it makes.
    pub fn count(&self) -> usize {
        match self {
            Generator::Classroom => 1,
            Generator::RandomTriangles { counts, .. } => counts.len(),
        }
    }

    /// Scene `i`, generated now.
    pub fn scene(&self, i: usize) -> Generated {
        match self {
            Generator::Classroom => classroom::classroom(),
            Generator::RandomTriangles { counts, seed } => random::random_triangles(counts[i], *seed),
        }
    }

    /// The smallest scene it makes, with every named part its scenes have.
    pub fn probe(&self) -> Generated {
        match self {
            Generator::Classroom => classroom::classroom(),
            Generator::RandomTriangles { seed, .. } => random::random_triangles(1, *seed),
        }
    }
}
