//! What every scene-file export shares: the files it writes, how far planes reach, a mesh's
//! world-space triangles, the refusal of views that see a light's disk, and the view record.

use super::view::{ExportedView, PixelFilter};
use crate::files::Refused;
use crate::render::cpu::closest_hit;
use crate::scene::camera::Camera;
use crate::scene::{Light, Scene, Shape};
use glam::DVec3;

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

/// Refuses a view in which a pixel's camera ray meets a disk light before any surface: such a
/// disk is a surface in `renderer` and nothing in penumbra.
pub fn refuse_visible_lights(
    scene: &Scene,
    camera: &Camera,
    view: &ExportedView,
    renderer: &str,
) -> anyhow::Result<()> {
    for (k, light) in scene.lights.iter().enumerate() {
        let Light::Disk(d) = light else { continue };
        let mut seen = 0u64;
        for y in 0..view.height {
            for x in 0..view.width {
                let ray = camera.ray(x, y, view.width, view.height);
                let denom = ray.direction.dot(d.normal);
                if denom == 0.0 {
                    continue;
                }
                let t = (d.center - ray.origin).dot(d.normal) / denom;
                let on_disk = t > 0.0 && (ray.origin + ray.direction * t - d.center).length() <= d.radius;
                let before = closest_hit(scene, ray.origin, ray.direction)
                    .is_none_or(|h| (h.p - ray.origin).dot(ray.direction) > t);
                seen += (on_disk && before) as u64;
            }
        }
        if seen > 0 {
            return Err(Refused(format!(
                "{}: {seen} pixels of camera `{}` see light {k}'s disk, which {renderer} renders as a surface and penumbra does not; choose a view that does not see it",
                view.scene.display(),
                view.camera
            ))
            .into());
        }
    }
    Ok(())
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
