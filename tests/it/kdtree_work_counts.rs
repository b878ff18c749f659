//! The kd-tree's work counters on both backends (`accel::work`; `work_nodes` and `work_prims` in
//! kdtree.wgsl). Both walk the same tree the same way and count alike, with one difference: the
//! planes' thickness. The f64 walk treats a plane as a slab `walk::DELTA` (1e-9) of the largest
//! coordinate thick on either side, the f32 walk as one `KD_DELTA` (2e-5) of it. A segment that
//! ends, or starts, inside the GPU's slab of a plane but outside the CPU's enters the leaf across
//! the plane on the GPU only and tests its triangles there; f32 cannot do otherwise (a point
//! closer to a plane than f32 resolves has no side).
//!
//! The classroom's lights hang at z = 2.9, a spatial median of the room's height that the tree
//! stores as the f32 2.9000001 (9.5e-8 m above them: inside the GPU's slab, outside the CPU's),
//! directly under the lamps, whose bottom fans fill the four leaves above that plane with 96
//! triangles each. Every unoccluded shadow ray ends there, so the GPU tests up to 384 more
//! triangles per shadow ray than the CPU: 417 against 121 (3.4x) at 15 % more nodes (32 x 32,
//! frame 0 of the walk). Re-walking those rays in f64 with the GPU's slab gives the GPU's counts
//! to the ray (142.92 nodes and 417.28 triangles per shadow ray), and with the lights 1 cm lower
//! the two backends agree within 1 %. A thinner GPU slab would not remove it: light and plane lie
//! less than one f32 step apart in the frame's coordinates (with `KD_DELTA` at 1e-9 the GPU still
//! tests 1.5x the CPU's triangles). Neither walk mailboxes: a triangle in several leaves is
//! tested once per leaf on both.
//!
//! Here, on a small scene of the same make (a floor of two large triangles that straddle many
//! leaves, 300 small occluders, a lamp's fan of 96 triangles), the light is put in three places:
//! in the middle of a leaf (the slab acts at no segment's end: both backends count alike), on the
//! stored plane under the lamp's leaf (inside both slabs: the CPU too tests the leaf across) and
//! 1e-6 below it (inside the GPU's slab only: the GPU tests the lamp's leaf once more per
//! unoccluded shadow ray, which predicts the ratio).

use crate::common;

use glam::DVec3;
use penumbra::accel::kdtree::{self, walk, KdSettings, KdTree};
use penumbra::accel::work::Work;
use penumbra::accel::AccelSettings;
use penumbra::mesh::Triangles;
use penumbra::render::cpu::CpuBackend;
use penumbra::render::{Backend, Frame, Sampling, View};
use penumbra::sampling::rng::Seeded;
use penumbra::sampling::{DiskScheme, Pattern};
use penumbra::scene::camera::{Camera, Projection};
use penumbra::scene::procedural::classroom;
use penumbra::scene::{Light, Mesh, Scene, Shading};

/// Triangles of the lamp's fan (the classroom's lamps have two fans of 48 meeting at the axis).
const FAN: usize = 96;

/// Centre of the fan: off every plane the spatial median can choose near it.
const LAMP: DVec3 = DVec3::new(0.3141, 0.2718, 0.8);

/// How far below the stored plane the light hangs when only the GPU's slab reaches the plane.
const BELOW: f64 = 1e-6;

/// Allowed difference between the backends' counts (of the CPU's) where no segment ends inside
/// the GPU's slab: a ray still enters an extra leaf on the GPU where it passes within the slab of
/// the edge of a leaf it does not enter, and f32 decides a grazing triangle or plane now and then
/// otherwise than f64 (the kd-tree's allowance in tests/it/accelerators.rs; under 0.1 % here, 0.7 %
/// in the classroom with its lights 1 cm off the plane).
const TOLERANCE: f64 = 0.01;

/// The plane half-thickness of the f32 walk, relative to the largest local coordinate in play,
/// read from kdtree.wgsl.
fn gpu_delta() -> f64 {
    let at = kdtree::WGSL
        .find("const KD_DELTA: f32 = ")
        .expect("kdtree.wgsl declares KD_DELTA")
        + 22;
    let text = &kdtree::WGSL[at..];
    text[..text.find(';').unwrap()].parse().unwrap()
}

/// The least world-space half-thickness the GPU's planes can have over `tree`: its slab is
/// `KD_DELTA` of the largest coordinate in the frame's local coordinates (centred on the camera's
/// look-at point), the box's corners among them, which is at least half the box's longest side.
fn gpu_slab(tree: &KdTree) -> f64 {
    gpu_delta() * (tree.bounds.1 - tree.bounds.0).max_element() / 2.0
}

/// An inner node on a path down the tree: axis, plane, whether the path goes to the upper side.
type Step = (usize, f64, bool);

/// The leaf of `tree` holding `p` (the upper one where `p` lies on a plane), its box, and the
/// inner nodes above it.
fn leaf_of(tree: &KdTree, p: DVec3) -> (usize, (DVec3, DVec3), Vec<Step>) {
    let (mut node, mut b, mut path) = (0, tree.bounds, vec![]);
    while let Some((axis, s, left)) = tree.split(node) {
        let up = p[axis] >= s;
        path.push((axis, s, up));
        if up {
            b.0[axis] = s;
        } else {
            b.1[axis] = s;
        }
        node = left + up as usize;
    }
    (node, b, path)
}

/// Triangle entries of the leaves whose boxes, grown by `slab`, hold `p`.
fn entries_near(tree: &KdTree, p: DVec3, slab: f64) -> usize {
    let mut stack = vec![(0, tree.bounds)];
    let mut entries = 0;
    while let Some((node, b)) = stack.pop() {
        if (p - b.0).min_element() < -slab || (b.1 - p).min_element() < -slab {
            continue;
        }
        match tree.split(node) {
            Some((axis, s, left)) => {
                let (mut lo, mut hi) = (b, b);
                lo.1[axis] = s;
                hi.0[axis] = s;
                stack.extend([(left, lo), (left + 1, hi)]);
            }
            None => entries += tree.nodes[node].items().1,
        }
    }
    entries
}

/// The classroom's four lights: each lies outside the CPU's slab of the plane above it and
/// inside the GPU's, and the leaves within the GPU's slab hold the four quadrants of the lamp's
/// two 48-triangle fans (which all meet the lamp's axis, itself on two planes): 384 entries where
/// the CPU's hold none.
#[test]
fn the_classroom_lights_sit_inside_the_gpu_slab_under_the_lamp_fans() {
    let g = classroom::classroom();
    let tree = KdTree::build(&g.triangles(), KdSettings::default());
    let slab = gpu_slab(&tree);
    assert_eq!(g.lights.len(), 4);
    for light in &g.lights {
        let Light::Point { position: p, .. } = *light else {
            panic!("point lights")
        };
        let cpu = walk::delta(&tree, p);
        let (_, b, _) = leaf_of(&tree, p);
        let gap = b.1.z - p.z;
        assert!(gap > 0.0 && gap < 1e-7, "{p}: the plane above lies {gap:e} m away");
        assert!(
            gap > 10.0 * cpu && gap < slab / 100.0,
            "{p}: {gap:e} vs slabs {cpu:e}, {slab:e}"
        );
        assert_eq!(entries_near(&tree, p, cpu), 0, "{p}: the CPU's leaves at the light");
        assert_eq!(
            entries_near(&tree, p, slab),
            4 * 96,
            "{p}: the GPU's leaves at the light"
        );
    }
}

/// A floor of two triangles straddling many leaves, 300 small occluders above it and a lamp's
/// fan of [`FAN`] triangles about [`LAMP`], all one mesh.
fn triangles() -> Triangles {
    let v = DVec3::new;
    let mut t = vec![
        [v(-1., -1., 0.), v(1., -1., 0.), v(1., 1., 0.)],
        [v(-1., -1., 0.), v(1., 1., 0.), v(-1., 1., 0.)],
    ];
    let mut r = Seeded(3);
    for _ in 0..300 {
        let c = v(r.range(-0.8, 0.8), r.range(-0.8, 0.8), r.range(0.1, 0.5));
        let (a, b) = (r.unit() * 0.02, r.unit() * 0.02);
        t.push([c, c + a, c + b]);
    }
    let rim = |j: usize| {
        let a = std::f64::consts::TAU * j as f64 / FAN as f64;
        LAMP + v(0.1 * a.cos(), 0.1 * a.sin(), 0.0)
    };
    t.extend((0..FAN).map(|j| [LAMP, rim(j), rim(j + 1)]));
    let n = t.len();
    Triangles {
        positions: t,
        object_of: vec![0; n],
    }
}

/// The scene with one point light at `light`, indexed by the default kd-tree.
fn scene(light: DVec3, shading: Shading) -> Scene {
    let t = triangles();
    let mesh = Mesh {
        source: "floor, occluders and a lamp".into(),
        file_fnv1a: 0,
        albedo: 0.5,
        mirror: 0.0,
        triangles: t.positions.len(),
        skipped: Default::default(),
    };
    let s = Scene::analytic(
        vec![],
        vec![],
        vec![Light::Point {
            position: light,
            power: 10.0,
        }],
    )
    .with_meshes(vec![mesh], t, AccelSettings::named("kdtree").unwrap())
    .with_shading(shading);
    let stats = s.accel.as_ref().unwrap().stats();
    assert_eq!(
        stats.parameters,
        KdSettings::default().describe(),
        "the tree analysed here"
    );
    s
}

/// The small scene's tree and where its light goes: (on the plane under the lamp's leaf, just
/// below it, inside a leaf), the lamp's leaf's entries and the nodes a walk descends from the
/// plane's node to that leaf (inner nodes and the leaf).
struct Lights {
    on: DVec3,
    below: DVec3,
    inside: DVec3,
    lamp_entries: usize,
    lamp_nodes: usize,
}

fn lights() -> Lights {
    let tree = KdTree::build(&triangles(), KdSettings::default());
    // The leaf just under the fan holds it all (every fan triangle meets the centre); its floor
    // is a plane.
    let (leaf, b, path) = leaf_of(&tree, LAMP - DVec3::Z * 1e-4);
    let lamp_entries = tree.nodes[leaf].items().1;
    assert_eq!(lamp_entries, FAN, "the lamp's leaf holds the fan and nothing else");
    let plane = path
        .iter()
        .position(|&(axis, s, up)| axis == 2 && s == b.0.z && up)
        .expect("a plane under the lamp's leaf");
    let on = DVec3::new(LAMP.x, LAMP.y, b.0.z);
    let below = on - DVec3::Z * BELOW;
    let (slab, cpu) = (gpu_slab(&tree), walk::delta(&tree, on));
    assert!(
        BELOW > 100.0 * cpu && BELOW < slab / 10.0,
        "{BELOW} vs slabs {cpu:e}, {slab:e}"
    );
    // Below the plane, the light's leaf is empty and its other faces lie far outside the slab: a
    // shadow ray's last stretch inside the plane's slab spans slab * tan(theta) across, under 10
    // slabs for every receiver here (all lie 0.26 below the light or lower, at most 1.9 away).
    let (under, ub, _) = leaf_of(&tree, below);
    assert_eq!(tree.nodes[under].items().1, 0);
    let clear = |p: DVec3, b: (DVec3, DVec3)| (p - b.0).min(b.1 - p);
    let c = clear(below, ub);
    assert!(c.x > 50.0 * slab && c.y > 50.0 * slab, "{c} vs slab {slab:e}");
    let inside = DVec3::new(below.x, below.y, (ub.0.z + ub.1.z) / 2.0);
    assert!(clear(inside, ub).min_element() > 50.0 * slab);
    Lights {
        on,
        below,
        inside,
        lamp_entries,
        lamp_nodes: path.len() - plane,
    }
}

fn camera() -> Camera {
    Camera {
        position: DVec3::new(0.2, -2.0, 2.6),
        look_at: DVec3::new(0.0, 0.0, 0.2),
        up: DVec3::Z,
        projection: Projection::Perspective { fov_y_deg: 50.0 },
    }
}

fn render(b: &mut dyn Backend, s: &Scene) -> Frame {
    let cam = camera();
    let view = View {
        camera: &cam,
        width: 48,
        height: 40,
    };
    let sampling = Sampling {
        scheme: DiskScheme::Jittered,
        pattern: Pattern::PerPixel,
        seed: 5,
        frame: 0,
    };
    b.render(s, view, sampling).unwrap()
}

/// What a backend counts with the light at `light`: the camera rays' work, the shadow rays'
/// (a frame with shadows less one without), shadow rays and unoccluded ones.
struct Counts {
    camera: Work,
    shadow: Work,
    rays: u64,
    unoccluded: u64,
}

fn counts(b: &mut dyn Backend, light: DVec3) -> Counts {
    let camera = render(b, &scene(light, Shading::OPENGL)).work().expect("counted");
    let f = render(b, &scene(light, Shading::default()));
    let all = f.work().expect("counted");
    Counts {
        camera,
        shadow: Work {
            queries: all.queries - camera.queries,
            nodes: all.nodes - camera.nodes,
            primitives: all.primitives - camera.primitives,
        },
        rays: f.rays.shadow_total(),
        unoccluded: f.visibility[0].iter().filter(|&&v| v == 1.0).count() as u64,
    }
}

fn per_ray(w: Work, rays: u64) -> String {
    format!(
        "{:.2} nodes, {:.2} triangles",
        w.nodes as f64 / rays as f64,
        w.primitives as f64 / rays as f64
    )
}

/// Where `got` lies within [`TOLERANCE`] of `want` (a share of `of`), counter by counter.
fn within(got: Work, want: Work, of: Work) -> bool {
    let near = |a: u64, b: u64, of: u64| a.abs_diff(b) as f64 <= TOLERANCE * of as f64;
    got.queries == want.queries
        && near(got.nodes, want.nodes, of.nodes)
        && near(got.primitives, want.primitives, of.primitives)
}

/// On the CPU alone, exactly: the light on the stored plane puts the lamp's leaf inside the f64
/// walk's slab too, which then tests the fan once per unoccluded shadow ray (occluded ones stop
/// before the leaf, the last in their walk) and descends to it from the plane's node; the light
/// 1e-6 below leaves it out, and the camera rays are the same.
#[test]
fn a_light_on_a_plane_costs_the_cpu_the_leaf_across_it() {
    let l = lights();
    let on = counts(&mut CpuBackend::default(), l.on);
    let below = counts(&mut CpuBackend::default(), l.below);
    eprintln!(
        "CPU, {} shadow rays ({} unoccluded): light on the plane {}, below it {} per shadow ray",
        on.rays,
        on.unoccluded,
        per_ray(on.shadow, on.rays),
        per_ray(below.shadow, below.rays)
    );
    assert_eq!((on.rays, on.unoccluded), (below.rays, below.unoccluded));
    assert!(
        on.unoccluded > 200 && on.unoccluded < on.rays,
        "{} of {}",
        on.unoccluded,
        on.rays
    );
    assert_eq!(on.camera, below.camera);
    let u = on.unoccluded;
    assert_eq!(
        on.shadow.primitives - below.shadow.primitives,
        l.lamp_entries as u64 * u
    );
    assert_eq!(on.shadow.nodes - below.shadow.nodes, l.lamp_nodes as u64 * u);
}

/// With the light inside a leaf, far outside both slabs of every plane, and with it on the
/// stored plane, inside both: the GPU counts what the CPU counts, camera and shadow rays alike.
#[test]
fn where_no_segment_ends_in_one_slab_only_both_backends_count_alike() {
    let Some(mut gpu) = common::gpu() else { return };
    let l = lights();
    gpu.count_work(true);
    for (place, light) in [("inside a leaf", l.inside), ("on the plane", l.on)] {
        let g = counts(&mut *gpu, light);
        let c = counts(&mut CpuBackend::default(), light);
        eprintln!(
            "light {place}: camera rays GPU {} / CPU {} per ray; shadow rays GPU {} / CPU {} per ray",
            per_ray(g.camera, g.camera.queries),
            per_ray(c.camera, c.camera.queries),
            per_ray(g.shadow, g.rays),
            per_ray(c.shadow, c.rays)
        );
        assert_eq!(
            (g.rays, g.unoccluded),
            (c.rays, c.unoccluded),
            "{place}: the same rays and hits"
        );
        assert!(
            within(g.camera, c.camera, c.camera),
            "{place}: camera {:?} vs {:?}",
            g.camera,
            c.camera
        );
        assert!(
            within(g.shadow, c.shadow, c.shadow),
            "{place}: shadow {:?} vs {:?}",
            g.shadow,
            c.shadow
        );
    }
    gpu.count_work(false);
}

/// The light 1e-6 below the plane: outside the CPU's slab, inside the GPU's. The GPU's shadow rays
/// test the lamp's leaf once more per unoccluded ray than the CPU's and descend to it: counts and
/// ratio as predicted, within [`TOLERANCE`] of the CPU's counts for the rest of the walk; the
/// camera rays agree, and the GPU counts what it counts with the light on the plane (it cannot
/// tell the two apart).
#[test]
fn a_light_just_below_a_plane_costs_the_gpu_the_leaf_across_it() {
    let Some(mut gpu) = common::gpu() else { return };
    let l = lights();
    gpu.count_work(true);
    let g = counts(&mut *gpu, l.below);
    let g_on = counts(&mut *gpu, l.on);
    gpu.count_work(false);
    let c = counts(&mut CpuBackend::default(), l.below);
    let u = c.unoccluded;
    let predicted = Work {
        queries: c.shadow.queries,
        nodes: c.shadow.nodes + l.lamp_nodes as u64 * u,
        primitives: c.shadow.primitives + l.lamp_entries as u64 * u,
    };
    let ratio = |a: u64, b: u64| a as f64 / b as f64;
    eprintln!(
        "light 1e-6 below the plane, {} shadow rays ({u} unoccluded): GPU {} / CPU {} per shadow ray; \
         triangles x{:.3} (predicted x{:.3}), nodes x{:.3} (predicted x{:.3})",
        c.rays,
        per_ray(g.shadow, g.rays),
        per_ray(c.shadow, c.rays),
        ratio(g.shadow.primitives, c.shadow.primitives),
        ratio(predicted.primitives, c.shadow.primitives),
        ratio(g.shadow.nodes, c.shadow.nodes),
        ratio(predicted.nodes, c.shadow.nodes)
    );
    assert_eq!((g.rays, g.unoccluded), (c.rays, c.unoccluded), "the same rays and hits");
    assert!(
        ratio(predicted.primitives, c.shadow.primitives) > 2.0,
        "the lamp's leaf dominates the shadow rays' tests"
    );
    assert!(
        within(g.camera, c.camera, c.camera),
        "camera {:?} vs {:?}",
        g.camera,
        c.camera
    );
    assert!(
        within(g.shadow, predicted, c.shadow),
        "shadow: GPU {:?}, predicted {predicted:?} (CPU {:?})",
        g.shadow,
        c.shadow
    );
    assert!(
        within(g_on.shadow, g.shadow, c.shadow),
        "{:?} vs {:?}",
        g_on.shadow,
        g.shadow
    );
}
