//! Scenes made by deterministic generators rather than read from files: the visibility-field
//! paper's random-triangle scenes (Fig. 5) and its classroom walkthrough (Fig. 6), whose models
//! are not available, rebuilt from stated rules so that every figure can be regenerated.

pub mod classroom;
mod parts;
pub mod random;

pub use parts::Part;

use super::camera::Camera;
use super::{Light, Mesh, Scene};
use crate::accel::AccelSettings;
use crate::mesh::Triangles;
use std::collections::BTreeMap;

/// A generated scene: named parts (one mesh object each), lights, and the camera path it is
/// walked along.
#[derive(Clone, Debug)]
pub struct Generated {
    /// What made it, in a few words (generator and its parameters).
    pub description: String,
    /// Parts, each one mesh object with its own material.
    pub parts: Vec<Part>,
    /// Lights.
    pub lights: Vec<Light>,
}

impl Generated {
    /// Triangles over all parts.
    pub fn triangle_count(&self) -> usize {
        self.parts.iter().map(|p| p.triangles.len()).sum()
    }

    /// Every part's triangles, tagged with the part's index.
    pub fn triangles(&self) -> Triangles {
        let mut t = Triangles::default();
        for (i, p) in self.parts.iter().enumerate() {
            t.positions.extend_from_slice(&p.triangles);
            t.object_of.extend(std::iter::repeat_n(i as u32, p.triangles.len()));
        }
        t
    }

    /// The part called `name`, with its index (its object id in [`Generated::scene`]).
    pub fn part(&self, name: &str) -> Option<(usize, &Part)> {
        self.parts.iter().enumerate().find(|(_, p)| p.name == name)
    }

    /// The scene: parts as meshes (object id = part index), the lights, `cameras`, indexed by
    /// the structure `settings` names.
    pub fn scene(&self, cameras: BTreeMap<String, Camera>, settings: AccelSettings) -> anyhow::Result<Scene> {
        let meshes = self
            .parts
            .iter()
            .map(|p| Mesh {
                source: format!("{} ({})", p.name, self.description),
                file_fnv1a: 0,
                albedo: p.albedo,
                mirror: p.mirror,
                triangles: p.triangles.len(),
                skipped: Default::default(),
            })
            .collect();
        Scene::analytic(vec![], vec![], self.lights.clone())
            .with_cameras(cameras)
            .try_with_meshes(meshes, self.triangles(), settings)
    }
}
