//! A triangle mesh loaded from an OBJ file; `mesh.wgsl` holds its triangles' GPU form. Its
//! triangles are in the scene's triangle list, intersected through the accelerator.

use crate::mesh::Skipped;

/// A mesh of the scene.
#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    /// Where it came from, for messages.
    pub source: String,
    /// FNV-1a of the file's bytes: keys cached and resumed results, so an edited file is re-run.
    pub file_fnv1a: u64,
    /// Lambertian albedo.
    pub albedo: f64,
    /// Mirror weight in [0, 1]: radiance leaving is (1 - mirror) x diffuse + mirror x reflected.
    pub mirror: f64,
    /// Triangles kept.
    pub triangles: usize,
    /// Triangles dropped as unhittable.
    pub skipped: Skipped,
}
