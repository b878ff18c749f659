//! What every scene-file export shares: the files it writes and the line they open with, how
//! far planes reach, a mesh's world-space triangles, the refusal of what renders otherwise
//! where lights are surfaces, and the view record.

use super::view::{ExportedView, PixelFilter};
use crate::files::Refused;
use crate::render::cpu::closest_hit;
use crate::render::shading::disk_unreachable;
use crate::scene::camera::Camera;
use crate::scene::{DiskLight, Light, Scene, Shape};
use glam::DVec3;
use rayon::prelude::*;

/// Planes become squares reaching this many times the scene's extent from their point: past
/// what the shipped views see, and no further, because renderers place hits on a large flat
/// shape only to about its size x 2^-24 (measured with Mitsuba 3's `rectangle` on the sphere
/// scene's measuring view: hits 1.2e-5 m off at 100 times the extent, 301 m, which moved the
/// penumbra by 0.02 pixels and its mean signed error by +0.0008).
pub const PLANE_REACH: f64 = 4.0;

/// Radiance of a one-sided Lambertian disk of `radius` that emits `power` watts: penumbra's
/// disk light as an area emitter.
pub fn disk_radiance(power: f64, radius: f64) -> f64 {
    power / (std::f64::consts::PI.powi(2) * radius * radius)
}

/// An exported scene: the scene file's name and text, and the meshes it names (file name, PLY
/// bytes).
pub struct Export {
    /// The scene file's name in the export folder (`scene.xml`, `scene.pbrt`).
    pub name: &'static str,
    /// The scene file's text.
    pub text: String,
    /// `meshes/NAME.ply` files.
    pub meshes: Vec<(String, Vec<u8>)>,
}

impl Export {
    /// Every file of the export: the scene file, then the meshes.
    pub fn into_files(self) -> Vec<(String, Vec<u8>)> {
        let mut files = vec![(self.name.to_string(), self.text.into_bytes())];
        files.extend(self.meshes);
        files
    }
}

/// The line both scene files open with (as a comment): which scene file and its fingerprint,
/// camera and size.
pub fn provenance(view: &ExportedView) -> String {
    format!(
        "penumbra export of {} (FNV-1a {}), camera `{}`, {} x {}",
        view.scene
            .file_name()
            .map_or(String::new(), |n| n.to_string_lossy().into_owned()),
        view.scene_fnv1a,
        view.camera,
        view.width,
        view.height
    )
}

/// The world-space triangles of shape `id` (a mesh), as penumbra traces them.
pub fn mesh_triangles(scene: &Scene, id: usize) -> Vec<[DVec3; 3]> {
    scene
        .triangles
        .positions
        .iter()
        .zip(&scene.triangles.object_of)
        .filter(|(_, &o)| o as usize == id)
        .map(|(t, _)| *t)
        .collect()
}

/// A plane as a square of half-side `reach` around its point: in-plane axes u, v with
/// u x v = the plane's normal, so the square faces where the plane does.
pub fn plane_square(point: DVec3, normal: DVec3, reach: f64) -> [DVec3; 4] {
    let u = normal.any_orthonormal_vector();
    let v = normal.cross(u);
    [
        point - (u + v) * reach,
        point + (u - v) * reach,
        point + (u + v) * reach,
        point + (v - u) * reach,
    ]
}

/// The largest distance from the origin of anything the view or the lights involve (metres).
pub fn extent(scene: &Scene, camera: &Camera) -> f64 {
    let mut r = camera.position.length().max(camera.look_at.length());
    for s in &scene.shapes {
        r = r.max(match s {
            Shape::Sphere(s) => s.center.length() + s.radius,
            Shape::Plane(p) => p.point.length(),
            Shape::Mesh(_) => 0.0,
        });
    }
    for t in &scene.triangles.positions {
        r = t.iter().fold(r, |r, v| r.max(v.length()));
    }
    for l in &scene.lights {
        r = r.max(match l {
            Light::Point { position, .. } => position.length(),
            Light::Disk(d) => d.center.length() + d.radius,
        });
    }
    r.max(1.0)
}

/// Refuses what a renderer whose disk lights are surfaces renders otherwise than penumbra,
/// whose lights are neither seen nor block anything: a view that sees a light's disk
/// ([`refuse_visible_lights`]) and a light that may shadow another on what the view sees
/// ([`refuse_lights_shadowing_lights`]).
pub fn refuse_lights_as_surfaces(
    scene: &Scene,
    camera: &Camera,
    view: &ExportedView,
    renderer: &str,
) -> anyhow::Result<()> {
    refuse_visible_lights(scene, camera, view, renderer)?;
    refuse_lights_shadowing_lights(scene, camera, view, renderer)
}

/// Image positions (offsets from a pixel's top-left corner) a renderer with this pixel filter
/// sends camera rays through: the centre, or under a box filter a 5 x 5 lattice over the
/// square, edges and corners included.
fn pixel_positions(filter: PixelFilter) -> Vec<(f64, f64)> {
    match filter {
        PixelFilter::Centre => vec![(0.5, 0.5)],
        PixelFilter::Box => (0..25)
            .map(|k| ((k % 5) as f64 * 0.25, (k / 5) as f64 * 0.25))
            .collect(),
    }
}

/// Whether the camera ray (origin, dir) meets disk light `d` before any surface.
fn sees_disk(scene: &Scene, origin: DVec3, dir: DVec3, d: &DiskLight) -> bool {
    let denom = dir.dot(d.normal);
    if denom == 0.0 {
        return false;
    }
    let t = (d.center - origin).dot(d.normal) / denom;
    t > 0.0
        && (origin + dir * t - d.center).length() <= d.radius
        && closest_hit(scene, origin, dir).is_none_or(|h| (h.p - origin).dot(dir) > t)
}

/// Refuses a view in which a camera ray the pixel filter traces meets a disk light before any
/// surface, or that sees the disk's centre (a disk smaller than the lattice's spacing is seen
/// where its centre is): such a disk is a surface in `renderer` and nothing in penumbra.
pub fn refuse_visible_lights(
    scene: &Scene,
    camera: &Camera,
    view: &ExportedView,
    renderer: &str,
) -> anyhow::Result<()> {
    let (w, h) = (view.width, view.height);
    let positions = pixel_positions(view.pixel);
    for (k, light) in scene.lights.iter().enumerate() {
        let Light::Disk(d) = light else { continue };
        let seen: usize = (0..h)
            .into_par_iter()
            .map(|y| {
                (0..w)
                    .filter(|&x| {
                        positions.iter().any(|&(dx, dy)| {
                            let ray = camera.ray_at(x as f64 + dx, y as f64 + dy, w, h);
                            sees_disk(scene, ray.origin, ray.direction, d)
                        })
                    })
                    .count()
            })
            .sum();
        let centre_seen = centre_in_view(camera, w, h, d.center).is_some_and(|(origin, dir)| {
            closest_hit(scene, origin, dir).is_none_or(|hit| (hit.p - origin).dot(dir) > (d.center - origin).dot(dir))
        });
        if seen > 0 || centre_seen {
            return Err(Refused(format!(
                "{}: camera `{}` sees light {k}'s disk ({}), which {renderer} renders as a surface and penumbra does not; choose a view that does not see it",
                view.scene.display(),
                view.camera,
                if seen > 0 {
                    format!("the camera rays of {seen} pixels meet it")
                } else {
                    "its centre, between the pixels' rays".to_string()
                }
            ))
            .into());
        }
    }
    Ok(())
}

/// The camera ray (origin, unit direction) towards `p` when `p` lies in front of the camera and
/// inside its view.
fn centre_in_view(camera: &Camera, width: u32, height: u32, p: DVec3) -> Option<(DVec3, DVec3)> {
    let (f, (hx, hy), orthographic) = camera.gpu_terms(width, height);
    let d = p - camera.position;
    let z = d.dot(f.forward);
    if z <= 0.0 {
        return None;
    }
    let (sx, sy) = if orthographic {
        (d.dot(f.right), d.dot(f.up))
    } else {
        (d.dot(f.right) / z, d.dot(f.up) / z)
    };
    if sx.abs() > hx || sy.abs() > hy {
        return None;
    }
    Some(if orthographic {
        (camera.position + sx * f.right + sy * f.up, f.forward)
    } else {
        (camera.position, d.normalize())
    })
}

/// Refuses a scene in which a disk light may shadow another light (disk or point) on a receiver
/// the view sees: in `renderer` a disk light is a surface that blocks the others' shadow rays,
/// in penumbra it blocks nothing. Conservative: every segment from the receiver to light b's
/// disk stays within b's radius of the segment to b's centre, so disk a (within its radius of
/// its centre) can block one only if its centre comes within the sum of the radii of that
/// segment.
pub fn refuse_lights_shadowing_lights(
    scene: &Scene,
    camera: &Camera,
    view: &ExportedView,
    renderer: &str,
) -> anyhow::Result<()> {
    let disks: Vec<(usize, &DiskLight)> = scene
        .lights
        .iter()
        .enumerate()
        .filter_map(|(k, l)| match l {
            Light::Disk(d) => Some((k, d)),
            Light::Point { .. } => None,
        })
        .collect();
    if disks.is_empty() || scene.lights.len() < 2 {
        return Ok(());
    }
    let (w, h) = (view.width, view.height);
    let receivers: Vec<(DVec3, DVec3)> = (0..h)
        .into_par_iter()
        .flat_map_iter(|y| {
            (0..w).filter_map(move |x| {
                let ray = camera.ray(x, y, w, h);
                closest_hit(scene, ray.origin, ray.direction).map(|r| (r.p, r.n))
            })
        })
        .collect();
    for &(a, da) in &disks {
        for (b, source) in scene.lights.iter().enumerate() {
            if a == b {
                continue;
            }
            // Where light b's shadow rays end: its disk (centre, radius) or its point.
            let (centre, radius) = match source {
                Light::Disk(d) => (d.center, d.radius),
                Light::Point { position, .. } => (*position, 0.0),
            };
            let lit = |p: DVec3, n: DVec3| match source {
                Light::Disk(d) => !disk_unreachable(p, n, d),
                Light::Point { position, .. } => n.dot(*position - p) > 0.0,
            };
            let shadowed = receivers
                .par_iter()
                .filter(|&&(p, n)| lit(p, n) && segment_distance(da.center, p, centre) < da.radius + radius)
                .count();
            if shadowed > 0 {
                return Err(Refused(format!(
                    "{}: light {a}'s disk may shadow light {b} on {shadowed} pixels of camera `{}`; {renderer}'s lights are surfaces that block other lights, penumbra's block nothing; move them apart or export one",
                    view.scene.display(),
                    view.camera
                ))
                .into());
            }
        }
    }
    Ok(())
}

/// Distance from `c` to the segment [p, q].
fn segment_distance(c: DVec3, p: DVec3, q: DVec3) -> f64 {
    let d = q - p;
    let t = ((c - p).dot(d) / d.length_squared()).clamp(0.0, 1.0);
    (p + d * t - c).length()
}

/// What an export of `camera` at this size records, for a renderer with this pixel filter and
/// shadow-ray lift ([`super::judge::Lift`]).
pub fn view_of(
    scene_path: &std::path::Path,
    scene_bytes: &[u8],
    camera: &str,
    width: u32,
    height: u32,
    pixel: PixelFilter,
    lift: &str,
) -> ExportedView {
    ExportedView {
        scene: scene_path.to_path_buf(),
        scene_fnv1a: ExportedView::fingerprint(scene_bytes),
        camera: camera.into(),
        width,
        height,
        plane: 0,
        pixel,
        lift: lift.into(),
    }
}
