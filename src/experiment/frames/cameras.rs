//! Where a frame-time experiment's frames place the camera (`[path]`): its viewpoints, and for
//! each either its path, frame after frame, or independent seeded draws.

use super::scenes::Generator;
use crate::config::{ConfigError, Seg, Source};
use crate::key_path;
use crate::scene::camera::Camera;
use crate::scene::procedural::{classroom, random};

/// Most frames per viewpoint a path may have.
pub const MAX_FRAMES: u32 = 100_000;

/// How a viewpoint's frames place the camera.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Cameras {
    /// Along the viewpoint's path, frame after frame (the paper's walkthrough and orbit):
    /// consecutive frames are correlated, so a median over them takes a moving-block interval.
    Path,
    /// Each frame an independent draw from the viewpoint's cameras, seeded
    /// ([`random::random_camera`], [`classroom::random_camera`]): a median over them takes the
    /// exact order-statistic interval, which decides a claim with far fewer frames.
    Random {
        /// Seed of the draws (`[path] seed`).
        seed: u32,
    },
}

impl Cameras {
    /// `path` or `random`, as the file names it.
    pub fn name(self) -> &'static str {
        match self {
            Cameras::Path => "path",
            Cameras::Random { .. } => "random",
        }
    }
}

impl Cameras {
    /// `[path] cameras` and `seed`, checked (a seed draws random cameras).
    pub fn read(source: &Source, cameras: Option<&str>, seed: Option<u32>) -> Result<Cameras, ConfigError> {
        let err = |p: &[Seg], m: String| source.error(p, m);
        Ok(match (cameras, seed) {
            (None | Some("path"), None) => Cameras::Path,
            (None | Some("path"), Some(_)) => {
                return Err(err(
                    &key_path!["path", "seed"],
                    "a seed draws random cameras: set `cameras = \"random\"` or remove it".into(),
                ))
            }
            (Some("random"), seed) => Cameras::Random {
                seed: seed.unwrap_or(1),
            },
            (Some(other), _) => {
                return Err(err(
                    &key_path!["path", "cameras"],
                    format!("unknown `{other}`; known: path, random"),
                ))
            }
        })
    }

    /// The camera of `frame` (of `frames`) of `viewpoint` of `generator`'s scenes, on its path or
    /// drawn at random; none where the viewpoint has no such camera.
    pub fn camera(self, generator: &Generator, viewpoint: &str, frame: u32, frames: u32) -> Option<Camera> {
        match (generator, self) {
            (Generator::Classroom, Cameras::Path) => Some(classroom::camera_path(frame, frames)),
            (Generator::Classroom, Cameras::Random { seed }) => Some(classroom::random_camera(seed, frame)),
            (Generator::RandomTriangles { .. }, Cameras::Path) => random::camera_path(viewpoint, frame),
            (Generator::RandomTriangles { .. }, Cameras::Random { seed }) => {
                random::random_camera(viewpoint, seed, frame)
            }
        }
    }
}

/// `[path] viewpoints` of `generator`'s scenes, checked: the classroom has one walk; random
/// triangles name theirs.
pub fn viewpoints(source: &Source, generator: &Generator, listed: &[String]) -> Result<Vec<String>, ConfigError> {
    let err = |p: &[Seg], m: String| source.error(p, m);
    Ok(match generator {
        Generator::Classroom => {
            if !listed.is_empty() {
                return Err(err(
                    &key_path!["path", "viewpoints"],
                    "the classroom has one walk; viewpoints apply to random-triangles".into(),
                ));
            }
            vec!["walk".to_string()]
        }
        Generator::RandomTriangles { .. } => {
            if listed.is_empty() {
                return Err(err(
                    &key_path!["path", "viewpoints"],
                    format!("list viewpoints from: {}", random::VIEWPOINTS.join(", ")),
                ));
            }
            for (i, v) in listed.iter().enumerate() {
                if !random::VIEWPOINTS.contains(&v.as_str()) {
                    return Err(err(
                        &key_path!["path", "viewpoints", i],
                        format!("unknown viewpoint `{v}`; known: {}", random::VIEWPOINTS.join(", ")),
                    ));
                }
                if listed[..i].contains(v) {
                    return Err(err(
                        &key_path!["path", "viewpoints", i],
                        format!("`{v}` is listed twice"),
                    ));
                }
            }
            listed.to_vec()
        }
    })
}
