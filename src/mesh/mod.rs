//! Triangle meshes placed in a scene: loaded from OBJ or OFF, transformed to metres, cleaned of
//! triangles that can never be hit.

pub mod file;
pub mod obj;
pub mod off;

pub use file::{load, MeshFile, MeshFileError};

use glam::{DMat4, DVec3};

/// World-space triangles of every mesh in a scene, with the mesh each belongs to.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Triangles {
    /// Corner positions (f64, world space).
    pub positions: Vec<[DVec3; 3]>,
    /// Owner per triangle: in a [`crate::scene::Scene`], the id of its mesh object.
    pub object_of: Vec<u32>,
}

/// Counts of triangles dropped because no ray can hit them.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Skipped {
    /// Zero-area (collinear or repeated corners).
    pub degenerate: usize,
    /// A NaN or infinite coordinate.
    pub non_finite: usize,
}

/// Transforms triangles by `m` and keeps those with finite corners and non-zero area.
/// Zero area is judged relative to the triangle's size (|e1 x e2| <= 1e-12 |e1| |e2|).
pub fn clean(triangles: impl IntoIterator<Item = [[f64; 3]; 3]>, m: &DMat4) -> (Vec<[DVec3; 3]>, Skipped) {
    let mut skipped = Skipped::default();
    let mut out = Vec::new();
    for t in triangles {
        let p = t.map(|c| m.transform_point3(DVec3::from_array(c)));
        if !p.iter().all(|c| c.is_finite()) {
            skipped.non_finite += 1;
            continue;
        }
        let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
        if e1.cross(e2).length() <= 1e-12 * e1.length() * e2.length() || e1.length() == 0.0 || e2.length() == 0.0 {
            skipped.degenerate += 1;
            continue;
        }
        out.push(p);
    }
    (out, skipped)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn degenerate_and_non_finite_triangles_are_dropped() {
        let good = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let collinear = [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [2.0, 2.0, 2.0]];
        let point = [[1.0, 1.0, 1.0]; 3];
        let nan = [[f64::NAN, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let inf = [[f64::INFINITY, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let m = DMat4::from_scale(DVec3::splat(2.0));
        let (kept, skipped) = clean([good, collinear, point, nan, inf], &m);
        assert_eq!(kept.len(), 1);
        assert_eq!(kept[0][1], DVec3::new(2.0, 0.0, 0.0));
        assert_eq!(
            skipped,
            Skipped {
                degenerate: 2,
                non_finite: 2
            }
        );
    }
}
