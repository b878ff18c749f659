//! Following a moving part: obvhs' refit of the BVH and the visibility field's own update must
//! answer every query over the moved scene as brute force does, after small steps and after a
//! move far from where the structures were built (the refit keeps a topology that no longer
//! fits, which may slow it but must not change its answers).

use crate::common::rays::{point_on, random_segments, Ray, Rng};
use glam::DVec3;
use penumbra::accel::bvh::Bvh;
use penumbra::accel::vlf::{VisibilityField, VlfSettings};
use penumbra::accel::{brute_force, Accelerator, Preset};
use penumbra::mesh::Triangles;
use penumbra::scene::procedural::classroom::classroom;

/// Segments through the whole room and segments from random points to points on the moving
/// part's triangles (so many of them hit it).
fn queries(current: &Triangles, object: u32, seed: u32) -> Vec<Ray> {
    let mut rng = Rng(seed);
    let mut rays = random_segments(current, 1500, &mut rng);
    let part: Vec<&[DVec3; 3]> = current
        .positions
        .iter()
        .zip(&current.object_of)
        .filter(|(_, &o)| o == object)
        .map(|(t, _)| t)
        .collect();
    for _ in 0..1500 {
        let target = point_on(part[rng.index(part.len())], &mut rng);
        let from = DVec3::new(rng.range(-4.5, 4.5), rng.range(-3.5, 3.5), rng.range(0.1, 3.0));
        let d = target - from;
        rays.push((from, d.normalize(), d.length() * 1.5, u32::MAX));
    }
    rays
}

/// Queries on which `a` disagrees with brute force over `current`.
fn disagreements(a: &dyn Accelerator, current: &Triangles, rays: &[Ray]) -> usize {
    rays.iter()
        .filter(|&&(o, d, tmax, skip)| {
            let exact = brute_force(current, o, d).filter(|h| h.t < tmax);
            let got = a.closest(o, d, tmax, skip);
            let same = match (exact, got) {
                (None, None) => true,
                (Some(e), Some(g)) => (e.t - g.t).abs() <= 1e-9 * e.t.max(1.0),
                _ => false,
            };
            !same || a.any_hit(o, d, tmax, skip) != exact.is_some()
        })
        .count()
}

/// Rolls the ball three times (two small steps, then far across the room), refitting the BVH
/// and updating a field built with `settings`; both must answer as brute force after each move.
fn roll_the_ball(settings: VlfSettings) {
    let g = classroom();
    let (object, _) = g.part("chrome-ball").unwrap();
    let object = object as u32;
    let mut current = g.triangles();
    let mut bvh = Bvh::build(&current, Preset::Fast);
    let mut field = VisibilityField::build(&current, settings).unwrap();
    let mut hits_on_ball = 0;
    for (k, step) in [
        DVec3::new(0.0, -0.05, 0.0),
        DVec3::new(0.0, -0.05, 0.0),
        DVec3::new(1.5, -1.0, 0.8),
    ]
    .into_iter()
    .enumerate()
    {
        for (t, &o) in current.positions.iter_mut().zip(&current.object_of) {
            if o == object {
                *t = t.map(|p| p + step);
            }
        }
        bvh.refit(&current);
        field.move_object(object, |p| p + step).unwrap();
        let rays = queries(&current, object, 11 + k as u32);
        hits_on_ball += rays
            .iter()
            .filter(|r| {
                brute_force(&current, r.0, r.1).is_some_and(|h| current.object_of[h.triangle as usize] == object)
            })
            .count();
        assert_eq!(disagreements(&bvh, &current, &rays), 0, "refit BVH, move {k}");
        assert_eq!(
            disagreements(&field, &current, &rays),
            0,
            "updated field {settings:?}, move {k}"
        );
    }
    assert!(hits_on_ball > 1000, "the queries reach the moving ball: {hits_on_ball}");
}

#[test]
fn refit_bvh_and_coarse_updated_field_answer_as_brute_force_after_the_ball_rolls_away() {
    roll_the_ball(VlfSettings {
        level: 4,
        tiles: 32,
        depth: 3,
        ..VlfSettings::default()
    });
}

#[test]
fn the_walkthrough_field_updated_answers_as_brute_force_after_the_ball_rolls_away() {
    roll_the_ball(VlfSettings {
        depth: 5,
        ..VlfSettings::default()
    });
}

/// Refitting unmoved triangles gives back the built boxes exactly where the build did not
/// pre-split triangles (obvhs' fastest to medium presets), and boxes holding the built ones
/// where it did (slow, very-slow: a fragment's box grows back to its triangle's).
#[test]
fn a_refit_of_unmoved_triangles_gives_back_the_built_boxes() {
    let t = classroom().triangles();
    for (preset, exact) in [(Preset::Medium, true), (Preset::VerySlow, false)] {
        let built = Bvh::build(&t, preset);
        let mut refit = built.clone();
        refit.refit(&t);
        let mut grown = 0;
        for (a, b) in built.tree.nodes.iter().zip(&refit.tree.nodes) {
            assert!(
                b.aabb.min.cmple(a.aabb.min).all() && b.aabb.max.cmpge(a.aabb.max).all(),
                "{preset:?}: a refit box never shrinks below the built one's"
            );
            grown += (a.aabb.min != b.aabb.min || a.aabb.max != b.aabb.max) as usize;
        }
        if exact {
            assert_eq!(grown, 0, "{preset:?}: no pre-split, so every box is rebuilt exactly");
        } else {
            assert!(
                grown > 0,
                "{preset:?} pre-splits large triangles, whose leaves grow back"
            );
        }
    }
}
