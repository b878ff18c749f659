//! Ambient occlusion of one receiver on the CPU, in f64: rays into the hemisphere of its normal
//! (the scene's [`AoDirections`]), any-hit up to the scene's maximum distance, weighted as the
//! scene asks ([`Weighting`]).

use super::shading::{blocked, Receiver};
use crate::sampling::Site;
use crate::scene::ambient::{AmbientOcclusion, AoDirections, Weighting};
use crate::scene::Scene;
use glam::{DVec2, DVec3};

/// Stream index of ambient-occlusion directions (lights use 0 .. MAX_LIGHTS).
pub const AMBIENT_STREAM: u32 = 0x414f;

/// An orthonormal basis (t, b) completing unit `n` (Duff et al. 2017, branchless).
pub fn tangent_basis(n: DVec3) -> (DVec3, DVec3) {
    let sign = 1f64.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        DVec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        DVec3::new(b, sign + n.y * n.y * a, -n.y),
    )
}

/// A unit-disk point lifted to the hemisphere around +z: Malley's vertical projection (cosine
/// distributed) or the equal-area map (uniform by solid angle, z = 1 - r^2).
pub fn lift(s: DVec2, weighting: Weighting) -> DVec3 {
    let r2 = s.length_squared().min(1.0);
    match weighting {
        Weighting::Cosine => DVec3::new(s.x, s.y, (1.0 - r2).sqrt()),
        Weighting::Plain => {
            let k = (2.0 - r2).sqrt();
            DVec3::new(s.x * k, s.y * k, 1.0 - r2)
        }
    }
}

/// The receiver's ambient-occlusion value and the rays it traced. `shared` holds the disk points
/// every receiver uses (shared pattern); otherwise they come from `stream`.
pub fn occlusion(
    scene: &Scene,
    r: &Receiver,
    ao: &AmbientOcclusion,
    shared: Option<&[DVec2]>,
    site: Site,
) -> (f64, u64) {
    let origin = r.origin();
    let open = |d: DVec3| !blocked(scene, origin, d, ao.max_distance, r);
    match &ao.directions {
        AoDirections::Grid { lines, .. } => {
            // Each line oriented into the normal's hemisphere; cosine weights where asked.
            let (mut seen, mut total) = (0.0, 0.0);
            for &w in lines.iter() {
                let c = w.dot(r.n);
                let d = if c < 0.0 { -w } else { w };
                let weight = match ao.weighting {
                    Weighting::Plain => 1.0,
                    Weighting::Cosine => c.abs(),
                };
                total += weight;
                if open(d) {
                    seen += weight;
                }
            }
            (if total > 0.0 { seen / total } else { 1.0 }, lines.len() as u64)
        }
        AoDirections::Disk(scheme) => {
            let (t, b) = tangent_basis(r.n);
            let mut seen = 0u32;
            for k in 0..ao.rays {
                let s = match shared {
                    Some(points) => points[k as usize],
                    None => scheme.point(ao.rays, k, site),
                };
                let l = lift(s, ao.weighting);
                if open(t * l.x + b * l.y + r.n * l.z) {
                    seen += 1;
                }
            }
            (seen as f64 / ao.rays as f64, ao.rays as u64)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bases_are_orthonormal_and_lifts_stay_on_the_hemisphere() {
        for n in [DVec3::Z, -DVec3::Z, DVec3::X, DVec3::new(0.3, -0.4, 0.866).normalize()] {
            let (t, b) = tangent_basis(n);
            for (u, v) in [(t, b), (t, n), (b, n)] {
                assert!(u.dot(v).abs() < 1e-12);
            }
            assert!((t.length() - 1.0).abs() < 1e-12 && (b.length() - 1.0).abs() < 1e-12);
        }
        for s in [DVec2::ZERO, DVec2::new(0.6, -0.8), DVec2::new(0.1, 0.2)] {
            for w in [Weighting::Plain, Weighting::Cosine] {
                let d = lift(s, w);
                assert!((d.length() - 1.0).abs() < 1e-12 && d.z >= 0.0, "{s} {w:?}: {d}");
            }
        }
    }
}
