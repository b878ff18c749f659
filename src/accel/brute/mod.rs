//! Brute force: every triangle tested against every ray, on the CPU and on the GPU. No build,
//! no tree, nothing to get wrong: the independent path other structures are checked against
//! (select it with `accelerator = "brute"`; it costs O(triangles) per ray).

use super::{brute_force, intersect, work, Accelerator, BuildStats, GpuStructure, GpuTri, TriHit};
use crate::geometry::LocalFrame;
use crate::mesh::Triangles;
use glam::DVec3;
use std::time::Duration;

/// Its WGSL: `accel_closest` and `accel_any` as loops over every triangle.
pub const WGSL: &str = include_str!("brute.wgsl");

/// Brute force has no parameters (`[accel.brute]` is empty).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BruteSettings {}

impl super::settings::Params for BruteSettings {
    fn check(&self) -> Result<(), (&'static str, String)> {
        Ok(())
    }
}

/// The triangles, in input order.
#[derive(Clone, Debug)]
pub struct Brute {
    triangles: Triangles,
}

impl Brute {
    /// Keeps a copy of `triangles`.
    pub fn build(triangles: &Triangles) -> Brute {
        Brute {
            triangles: triangles.clone(),
        }
    }
}

impl Accelerator for Brute {
    fn name(&self) -> &'static str {
        "brute"
    }

    fn closest(&self, origin: DVec3, dir: DVec3, tmax: f64, skip: u32) -> Option<TriHit> {
        work::add(0, self.triangles.positions.len() as u64);
        if skip == u32::MAX {
            return brute_force(&self.triangles, origin, dir).filter(|h| h.t < tmax);
        }
        let mut best: Option<TriHit> = None;
        for (i, tri) in self.triangles.positions.iter().enumerate() {
            match intersect(origin, dir, tri) {
                Some(t) if i as u32 != skip && t > 0.0 && t < tmax && best.is_none_or(|b| t < b.t) => {
                    best = Some(TriHit { t, triangle: i as u32 });
                }
                _ => {}
            }
        }
        best
    }

    fn any_hit(&self, origin: DVec3, dir: DVec3, tmax: f64, skip: u32) -> bool {
        let mut tests = 0;
        let hit = self.triangles.positions.iter().enumerate().any(|(i, tri)| {
            tests += 1;
            i as u32 != skip && intersect(origin, dir, tri).is_some_and(|t| t > 0.0 && t < tmax)
        });
        work::add(0, tests);
        hit
    }

    fn stats(&self) -> BuildStats {
        let n = self.triangles.positions.len();
        BuildStats {
            parameters: "none".into(),
            build_time: Duration::ZERO,
            gpu_bytes: (n * std::mem::size_of::<GpuTri>()) as u64,
            memory_bytes: 0,
            triangles: n,
            description: format!("brute force over {n} triangles (48 GPU bytes per triangle)"),
        }
    }

    fn gpu(&self, frame: &LocalFrame) -> anyhow::Result<GpuStructure> {
        let tris: Vec<GpuTri> = self
            .triangles
            .positions
            .iter()
            .enumerate()
            .map(|(i, t)| GpuTri::new(t, i as u32, frame))
            .collect();
        Ok(GpuStructure {
            buffers: vec![("brute-force triangle buffer", bytemuck::cast_slice(&tris).to_vec())],
            walk_iterations: tris.len() as u32 + 1,
        })
    }

    fn update(
        &mut self,
        method: super::UpdateMethod,
        moved: &Triangles,
        _object: u32,
        _step: DVec3,
    ) -> anyhow::Result<super::Updated> {
        match method {
            super::UpdateMethod::Rebuild => *self = Brute::build(moved),
            m => return Err(super::unknown_update(self, m)),
        }
        Ok(super::Updated::Rebuilt)
    }
}
