//! The visibility field (`accel::vlf`, default settings: 513 directions, 128 x 128 tiles, depth
//! 4, uniform splits) on every shipped OFF mesh (assets/meshes: cow, mech-holes-shark, bull,
//! camel, man): for each mesh and each ray kind of `common::rays` (random segments, AO rays along
//! the grid directions, AO rays in random directions, shadow rays to a 4 cm disk light, camera
//! rays), 100K seeded rays, any-hit and closest-hit. An answer is right when it is brute
//! force's: hit or miss identical, the same triangle, t within 1e-6 relative.
//!
//! Brute force over every triangle for all 2.5M rays would take the CI machine minutes, so:
//! - all 100K rays of each kind are compared with obvhs' BVH (`accel::Bvh`, itself checked
//!   against brute force in accelerators.rs and mesh_scene.rs); where the two disagree, brute
//!   force decides (a BVH slip or an exact tie between two triangles is not the field's fault;
//!   the number of such rays is printed and must stay small);
//! - every 32nd ray (3125 per kind and mesh, 78K in all) is compared directly with brute force
//!   (`accel::brute::Brute` for closest hits, a loop over every triangle for any-hit).
//!
//! Runtime (release, the 2-core CI machine class, rayon on both cores): about 40 s for the whole
//! file, most of it the five 513-direction builds and the brute-force subset.
//! `a_corrupted_field_fails_the_mesh_check` shows the comparison catches a field that lost
//! entries.

use crate::common;

use crate::common::rays::*;
use penumbra::accel::brute::Brute;
use penumbra::accel::vlf::{VisibilityField, VlfSettings};
use penumbra::accel::{intersect, Accelerator, Bvh, Preset, TriHit};
use penumbra::mesh::Triangles;
use rayon::prelude::*;
use std::time::Instant;

/// The shipped OFF meshes (assets/meshes, PROVENANCE.md there).
const MESHES: [&str; 5] = ["cow", "mech-holes-shark", "bull", "camel", "man"];

/// Rays per kind and mesh.
const RAYS: usize = 100_000;

/// Every `BRUTE_STRIDE`-th ray is also checked against brute force.
const BRUTE_STRIDE: usize = 32;

/// Whether `got` is the answer `want`: both misses, or the same triangle at t within 1e-6
/// relative.
fn same(got: Option<TriHit>, want: Option<TriHit>) -> bool {
    match (got, want) {
        (None, None) => true,
        (Some(g), Some(w)) => g.triangle == w.triangle && (g.t - w.t).abs() <= 1e-6 * w.t.abs(),
        _ => false,
    }
}

/// Any-hit by brute force: some triangle other than `skip` with 0 < t < tmax.
fn brute_any(t: &Triangles, (o, d, tmax, skip): Ray) -> bool {
    t.positions
        .iter()
        .enumerate()
        .any(|(i, tri)| i as u32 != skip && intersect(o, d, tri).is_some_and(|t| t > 0.0 && t < tmax))
}

/// Counts of wrong answers: closest against the BVH (brute force deciding disagreements),
/// any-hit against the same, closest and any-hit against brute force on the subset, and how
/// many rays brute force had to decide.
#[derive(Default, Debug, Clone, Copy, PartialEq, Eq)]
struct Wrong {
    closest: usize,
    any: usize,
    brute_closest: usize,
    brute_any: usize,
    decided: usize,
}

impl std::ops::Add for Wrong {
    type Output = Wrong;
    fn add(self, o: Wrong) -> Wrong {
        Wrong {
            closest: self.closest + o.closest,
            any: self.any + o.any,
            brute_closest: self.brute_closest + o.brute_closest,
            brute_any: self.brute_any + o.brute_any,
            decided: self.decided + o.decided,
        }
    }
}

/// Checks `field` on `rays` (in parallel), printing the first few wrong answers.
fn wrong(field: &VisibilityField, bvh: &Bvh, brute: &Brute, t: &Triangles, rays: &[Ray], label: &str) -> Wrong {
    let shown = std::sync::atomic::AtomicUsize::new(0);
    let show = |what: &str, r: &Ray, got: String, want: String| {
        if shown.fetch_add(1, std::sync::atomic::Ordering::Relaxed) < 3 {
            eprintln!(
                "{label} {what}: o={:?} d={:?} tmax={} skip={}: got {got}, want {want}",
                r.0, r.1, r.2, r.3
            );
        }
    };
    rays.par_iter()
        .enumerate()
        .map(|(k, &r @ (o, d, tmax, skip))| {
            let mut w = Wrong::default();
            let got = field.closest(o, d, tmax, skip);
            let mut want = bvh.closest(o, d, tmax, skip);
            if !same(got, want) {
                // The BVH is not the reference; brute force is.
                w.decided = 1;
                want = brute.closest(o, d, tmax, skip);
                if !same(got, want) {
                    w.closest = 1;
                    show("closest", &r, format!("{got:?}"), format!("{want:?}"));
                }
            }
            let any = field.any_hit(o, d, tmax, skip);
            if any != want.is_some() {
                w.any = 1;
                show("any-hit", &r, format!("{any}"), format!("{}", want.is_some()));
            }
            if k % BRUTE_STRIDE == 0 {
                let exact = brute.closest(o, d, tmax, skip);
                if !same(got, exact) {
                    w.brute_closest = 1;
                    show("closest (brute)", &r, format!("{got:?}"), format!("{exact:?}"));
                }
                let exact_any = brute_any(t, r);
                if any != exact_any {
                    w.brute_any = 1;
                    show("any-hit (brute)", &r, format!("{any}"), format!("{exact_any}"));
                }
            }
            w
        })
        .reduce(Wrong::default, |a, b| a + b)
}

/// The five ray kinds, `RAYS` of each, seeded by mesh and kind.
fn rays(t: &Triangles, field: &VisibilityField, seed: u32) -> Vec<(&'static str, Vec<Ray>)> {
    let dirs = &field.frame.directions;
    let r = |k: u32| Rng(seed.wrapping_mul(7919).wrapping_add(k * 104_729 + 1));
    vec![
        ("segments", random_segments(t, RAYS, &mut r(1))),
        ("ao-grid", ao_grid(t, dirs, RAYS, &mut r(2))),
        ("ao-random", ao_random(t, RAYS, &mut r(3))),
        ("shadow", shadow_rays(t, RAYS, &mut r(4))),
        ("camera", camera_rays(t, RAYS, &mut r(5))),
    ]
}

/// Every shipped mesh, every ray kind: the field answers what brute force answers.
#[test]
fn off_meshes_match_brute_force() {
    let start = Instant::now();
    let mut failures = Vec::new();
    for (m, name) in MESHES.iter().enumerate() {
        let t0 = Instant::now();
        let t = common::off_mesh(name);
        let field = VisibilityField::build(&t, VlfSettings::default()).unwrap();
        let bvh = Bvh::build(&t, Preset::Medium);
        let brute = Brute::build(&t);
        let built = t0.elapsed().as_secs_f64();
        for (kind, rays) in rays(&t, &field, m as u32 + 1) {
            let hits = rays.par_iter().filter(|r| bvh.any_hit(r.0, r.1, r.2, r.3)).count();
            let w = wrong(&field, &bvh, &brute, &t, &rays, &format!("{name} {kind}"));
            eprintln!(
                "{name} {kind}: {} rays, {:.1} % hit, {} decided by brute force; wrong: {w:?}",
                rays.len(),
                100.0 * hits as f64 / rays.len() as f64,
                w.decided
            );
            // Hit and miss both exercised.
            assert!(hits > 0 || kind == "segments", "{name} {kind}: no ray hits");
            if (w.closest, w.any, w.brute_closest, w.brute_any) != (0, 0, 0, 0) {
                failures.push(format!("{name} {kind}: {w:?}"));
            }
            // A BVH that disagreed with the field on many rays would mean the reference was
            // mostly brute force: keep the split honest.
            assert!(
                w.decided < rays.len() / 1000,
                "{name} {kind}: {} rays decided",
                w.decided
            );
        }
        eprintln!(
            "{name}: {} triangles, built in {built:.1} s, checked in {:.1} s; {}",
            t.positions.len(),
            t0.elapsed().as_secs_f64() - built,
            field.stats().description
        );
    }
    eprintln!("all meshes: {:.1} s", start.elapsed().as_secs_f64());
    assert!(failures.is_empty(), "wrong answers:\n{}", failures.join("\n"));
}

/// The check above fails on a broken field: the cow's field with the first id of every
/// non-split tile list marked removed (as if those entries were never rasterised)
/// gives wrong closest hits in every ray kind, caught both against the BVH and by the
/// brute-force subset alone (10K rays per kind: 50-470 wrong closest hits per kind, 2-17 of
/// them in the subset).
#[test]
fn a_corrupted_field_fails_the_mesh_check() {
    let t = common::off_mesh("cow");
    let mut field = VisibilityField::build(&t, VlfSettings::default()).unwrap();
    let bvh = Bvh::build(&t, Preset::Medium);
    let brute = Brute::build(&t);
    let mut broken = 0;
    for k in 0..field.base.offsets.tiles() {
        let (start, end, split) = field.base.offsets.block(k);
        if !split && end > start {
            field.base.kill_at(start);
            broken += 1;
        }
    }
    assert!(broken > 0);
    let mut any = 0;
    for (kind, rays) in rays(&t, &field, 99) {
        let rays = &rays[..RAYS / 10];
        let w = wrong(&field, &bvh, &brute, &t, rays, &format!("corrupted cow {kind}"));
        eprintln!("corrupted cow {kind}: {w:?}");
        // Both paths catch it on their own: the BVH comparison and the brute-force subset.
        assert!(
            w.closest > 0 && w.brute_closest > 0,
            "{kind}: a corrupted field went unnoticed: {w:?}"
        );
        any += w.any;
    }
    // Any-hit too (camera rays mostly hit something behind the lost triangle, so summed).
    assert!(any > 0);
}
