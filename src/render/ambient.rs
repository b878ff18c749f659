//! Ambient occlusion of one receiver on the CPU, in f64: rays into the hemisphere of its normal
//! (the scene's [`AoDirections`]), any-hit up to the scene's maximum distance, weighted as the
//! scene asks ([`Weighting`]).

use super::shading::{blocked, blocked_by_shapes, Receiver};
use crate::accel::Query;
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

/// Ray `k` of receiver `r`: its direction and weight. `shared` holds the disk points every
/// receiver uses (shared pattern); otherwise they come from `site`'s stream.
fn ray(ao: &AmbientOcclusion, r: &Receiver, k: u32, shared: Option<&[DVec2]>, site: Site) -> (DVec3, f64) {
    match &ao.directions {
        AoDirections::Grid { lines, .. } => {
            // The line oriented into the normal's hemisphere; cosine weights where asked.
            let w = lines[k as usize];
            let c = w.dot(r.n);
            let weight = match ao.weighting {
                Weighting::Plain => 1.0,
                Weighting::Cosine => c.abs(),
            };
            (if c < 0.0 { -w } else { w }, weight)
        }
        AoDirections::Disk(scheme) => {
            let (t, b) = tangent_basis(r.n);
            let s = match shared {
                Some(points) => points[k as usize],
                None => scheme.point(ao.rays, k, site),
            };
            let l = lift(s, ao.weighting);
            (t * l.x + b * l.y + r.n * l.z, 1.0)
        }
    }
}

/// Rays per receiver: one per grid line, or the disk scheme's count.
fn rays_per_receiver(ao: &AmbientOcclusion) -> u32 {
    match &ao.directions {
        AoDirections::Grid { lines, .. } => lines.len() as u32,
        AoDirections::Disk(_) => ao.rays,
    }
}

/// Weight seen and weight cast, summed ray by ray in ray order (so either way of issuing the
/// rays gives the same value to the bit).
#[derive(Clone, Copy, Default)]
struct Tally {
    seen: f64,
    total: f64,
}

impl Tally {
    fn add(&mut self, weight: f64, open: bool) {
        self.total += weight;
        if open {
            self.seen += weight;
        }
    }

    fn value(self) -> f64 {
        if self.total > 0.0 {
            self.seen / self.total
        } else {
            1.0
        }
    }
}

/// The receiver's ambient-occlusion value and the rays it traced, one query at a time.
/// `shared` holds the disk points every receiver uses (shared pattern); otherwise they come from
/// `site`'s stream.
pub fn occlusion(
    scene: &Scene,
    r: &Receiver,
    ao: &AmbientOcclusion,
    shared: Option<&[DVec2]>,
    site: Site,
) -> (f64, u64) {
    let origin = r.origin();
    let mut tally = Tally::default();
    let rays = rays_per_receiver(ao);
    for k in 0..rays {
        let (d, weight) = ray(ao, r, k, shared, site);
        tally.add(weight, !blocked(scene, origin, d, ao.max_distance, r));
    }
    (tally.value(), rays as u64)
}

/// [`occlusion`] of many receivers (each with its site), with the rays issued direction-major:
/// ray `k` of every receiver as one bundle for the scene's structure
/// ([`crate::accel::Accelerator::any_hits`]), then ray `k + 1`. Values equal [`occlusion`]'s.
pub fn occlusion_bundled(
    scene: &Scene,
    receivers: &[(&Receiver, Site)],
    ao: &AmbientOcclusion,
    shared: Option<&[DVec2]>,
) -> Vec<(f64, u64)> {
    let origins: Vec<DVec3> = receivers.iter().map(|(r, _)| r.origin()).collect();
    let mut tallies = vec![Tally::default(); receivers.len()];
    let mut bundle: Vec<Query> = Vec::with_capacity(receivers.len());
    let mut asked: Vec<(usize, f64)> = Vec::with_capacity(receivers.len());
    let mut hits = vec![false; receivers.len()];
    let rays = rays_per_receiver(ao);
    for k in 0..rays {
        bundle.clear();
        asked.clear();
        for (i, &(r, site)) in receivers.iter().enumerate() {
            let (dir, weight) = ray(ao, r, k, shared, site);
            if blocked_by_shapes(scene, origins[i], dir, ao.max_distance, r) {
                tallies[i].add(weight, false);
                continue;
            }
            bundle.push(Query {
                origin: origins[i],
                dir,
                tmax: ao.max_distance,
                skip: r.triangle,
            });
            asked.push((i, weight));
        }
        let hits = &mut hits[..bundle.len()];
        match &scene.accel {
            Some(a) => a.any_hits(&bundle, hits),
            None => hits.fill(false),
        }
        for (&(i, weight), &hit) in asked.iter().zip(hits.iter()) {
            tallies[i].add(weight, !hit);
        }
    }
    tallies.iter().map(|t| (t.value(), rays as u64)).collect()
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
