//! What is rendered: cameras, shapes (spheres, planes, triangle meshes) and point and disk
//! lights, in metres, with the acceleration structure over the meshes' triangles.
//!
//! [`Scene::load`] reads a TOML file ([`description`]) and validates it into this model, so that
//! everything downstream can assume finite positions, unit normals and positive radii.

pub mod ambient;
pub mod camera;
pub mod description;
pub(crate) mod load;
pub mod procedural;

pub mod shape;

use crate::accel::{self, AccelSettings, Accelerator};
use crate::mesh::Triangles;
use camera::{Camera, Projection};
use glam::DVec3;
use std::collections::BTreeMap;
use std::sync::Arc;

pub use shape::{Mesh, Plane, Shape, Sphere};

/// A one-sided Lambertian disk light, the soft-shadow paper's light source.
#[derive(Clone, Debug, PartialEq)]
pub struct DiskLight {
    /// Centre.
    pub center: DVec3,
    /// Unit emitting direction.
    pub normal: DVec3,
    /// Radius (> 0).
    pub radius: f64,
    /// Radiant power in watts.
    pub power: f64,
    /// Shadow rays per receiver point (>= 1).
    pub samples: u32,
}

impl DiskLight {
    /// An orthonormal basis (u, v) of the light's plane; sample (x, y) on the unit disk lands at
    /// `center + radius (x u + y v)`. Built the same way on the GPU (Duff et al. 2017).
    pub fn basis(&self) -> (DVec3, DVec3) {
        let n = self.normal;
        let sign = 1f64.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        (
            DVec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
            DVec3::new(b, sign + n.y * n.y * a, -n.y),
        )
    }
}

/// A light source.
#[derive(Clone, Debug, PartialEq)]
pub enum Light {
    /// Ideal point light: a hard shadow, one shadow ray.
    Point {
        /// Position.
        position: DVec3,
        /// Radiant power, watts.
        power: f64,
    },
    /// Disk light: a soft shadow, `samples` shadow rays.
    Disk(DiskLight),
}

impl Light {
    /// Shadow rays per receiver point that faces the light.
    pub fn samples(&self) -> u32 {
        match self {
            Light::Point { .. } => 1,
            Light::Disk(d) => d.samples,
        }
    }
}

/// A validated scene.
#[derive(Clone, Debug)]
pub struct Scene {
    /// Cameras by name.
    pub cameras: BTreeMap<String, Camera>,
    /// Objects; an object's id is its index here.
    pub shapes: Vec<Shape>,
    /// Lights.
    pub lights: Vec<Light>,
    /// Every mesh triangle in world space, with the id of the mesh object it belongs to.
    pub triangles: Triangles,
    /// Which acceleration structure indexes `triangles`, and its parameters.
    pub accel_settings: AccelSettings,
    /// The parameters the scene file gives each structure (`[accel.NAME]`); a structure it does
    /// not name takes its defaults ([`Scene::settings_for`]).
    pub accel_tables: BTreeMap<&'static str, AccelSettings>,
    /// That structure (None without triangles).
    pub accel: Option<Arc<dyn Accelerator>>,
    /// The ambient-occlusion pass, where the scene asks for one.
    pub ambient: Option<ambient::AmbientOcclusion>,
    /// Which light transport the frame simulates beyond the camera rays.
    pub shading: Shading,
}

/// Lights a scene may hold ([`crate::sampling::MAX_LIGHTS`]); a scene file with more is refused
/// where it lists them.
pub use crate::sampling::MAX_LIGHTS;

/// The light transport a scene asks for (the visibility-field paper's two shadings, Section 6):
/// OpenGL-like is `shadows = false` (local diffuse shading from every light, no rays beyond the
/// camera's); Whitted is `mirror_depth > 0` (mirror reflections from meshes that declare a mirror
/// weight, with shadow rays to every light at every vertex). The default, shadow rays from the
/// camera's hits and no reflections, is the soft-shadow paper's.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shading {
    /// Whether lights are tested for occlusion by shadow rays.
    pub shadows: bool,
    /// Most mirror bounces traced after the camera ray (0: none).
    pub mirror_depth: u32,
}

impl Default for Shading {
    fn default() -> Self {
        Shading {
            shadows: true,
            mirror_depth: 0,
        }
    }
}

impl Shading {
    /// Primary rays and unoccluded local shading only.
    pub const OPENGL: Shading = Shading {
        shadows: false,
        mirror_depth: 0,
    };

    /// Deepest mirror chain a scene may ask for.
    pub const MAX_MIRROR_DEPTH: u32 = 16;

    /// Whitted's model with mirror chains up to `depth` bounces.
    pub fn whitted(depth: u32) -> Shading {
        Shading {
            shadows: true,
            mirror_depth: depth,
        }
    }
}

impl Scene {
    /// A scene of analytic shapes and lights only: the spheres' ids first, then the planes'.
    pub fn analytic(spheres: Vec<Sphere>, planes: Vec<Plane>, lights: Vec<Light>) -> Scene {
        let shapes = spheres
            .into_iter()
            .map(Shape::Sphere)
            .chain(planes.into_iter().map(Shape::Plane))
            .collect();
        Scene {
            cameras: BTreeMap::new(),
            shapes,
            lights,
            triangles: Triangles::default(),
            accel_settings: AccelSettings::default(),
            accel_tables: BTreeMap::new(),
            accel: None,
            ambient: None,
            shading: Shading::default(),
        }
    }

    /// Sets the light transport simulated.
    pub fn with_shading(mut self, shading: Shading) -> Scene {
        self.shading = shading;
        self
    }

    /// Whether any object reflects (a mirror weight above zero): without one, a mirror pass
    /// would trace nothing, so the plan has none.
    pub fn has_mirrors(&self) -> bool {
        self.shapes.iter().any(|s| s.mirror() > 0.0)
    }

    /// Asks for (or, with `None`, drops) the ambient-occlusion pass.
    pub fn with_ambient(mut self, ambient: Option<ambient::AmbientOcclusion>) -> Scene {
        self.ambient = ambient;
        self
    }

    /// Sets the cameras.
    pub fn with_cameras(mut self, cameras: BTreeMap<String, Camera>) -> Scene {
        self.cameras = cameras;
        self
    }

    /// Adds triangle meshes, whose world-space `triangles` name their mesh by its index in
    /// `meshes`, and indexes every triangle with the structure `settings` names.
    pub fn with_meshes(self, meshes: Vec<Mesh>, triangles: Triangles, settings: AccelSettings) -> Scene {
        self.try_with_meshes(meshes, triangles, settings)
            .expect("the structure builds over these meshes (use try_with_meshes for untrusted input)")
    }

    /// [`Scene::with_meshes`], or the error of a structure that cannot index them.
    pub fn try_with_meshes(
        mut self,
        meshes: Vec<Mesh>,
        mut triangles: Triangles,
        settings: AccelSettings,
    ) -> anyhow::Result<Scene> {
        assert_eq!(
            triangles.object_of.len(),
            triangles.positions.len(),
            "one owner per triangle"
        );
        assert!(
            triangles.object_of.iter().all(|&m| (m as usize) < meshes.len()),
            "every triangle names one of the meshes given"
        );
        let base = self.shapes.len() as u32;
        triangles.object_of.iter_mut().for_each(|m| *m += base);
        self.shapes.extend(meshes.into_iter().map(Shape::Mesh));
        self.triangles.positions.extend(triangles.positions);
        self.triangles.object_of.extend(triangles.object_of);
        self.try_with_accelerator(settings)
    }

    /// The parameters the scene gives each structure.
    pub fn with_accel_tables(mut self, tables: BTreeMap<&'static str, AccelSettings>) -> Scene {
        self.accel_tables = tables;
        self
    }

    /// Structure `r`'s parameters in this scene: its `[accel.NAME]` table, or its defaults.
    pub fn settings_for(&self, r: &accel::Registered) -> AccelSettings {
        self.accel_tables
            .get(r.name)
            .cloned()
            .unwrap_or_else(|| AccelSettings::default_for(r))
    }

    /// The same scene with its triangles indexed by the structure `settings` names.
    pub fn with_accelerator(self, settings: AccelSettings) -> Scene {
        self.try_with_accelerator(settings)
            .expect("the structure builds over this scene (use try_with_accelerator for untrusted input)")
    }

    /// [`Scene::with_accelerator`], or the error of a structure that cannot index this scene
    /// (a limit it exceeds).
    pub fn try_with_accelerator(mut self, settings: AccelSettings) -> anyhow::Result<Scene> {
        self.accel = accel::build(&self.triangles, &settings)?;
        self.accel_settings = settings;
        Ok(self)
    }

    /// The spheres, in id order.
    pub fn spheres(&self) -> impl Iterator<Item = &Sphere> {
        self.shapes.iter().filter_map(|s| match s {
            Shape::Sphere(s) => Some(s),
            _ => None,
        })
    }

    /// Shapes a query tests one by one (spheres and planes; a mesh's triangles are the
    /// structure's to test).
    pub fn analytic_shapes(&self) -> usize {
        self.shapes.iter().filter(|s| !matches!(s, Shape::Mesh(_))).count()
    }

    /// The planes, in id order.
    pub fn planes(&self) -> impl Iterator<Item = &Plane> {
        self.shapes.iter().filter_map(|s| match s {
            Shape::Plane(p) => Some(p),
            _ => None,
        })
    }

    /// The spheres, mutable (ids unchanged).
    pub fn spheres_mut(&mut self) -> impl Iterator<Item = &mut Sphere> {
        self.shapes.iter_mut().filter_map(|s| match s {
            Shape::Sphere(s) => Some(s),
            _ => None,
        })
    }

    /// The meshes, in id order.
    pub fn meshes(&self) -> impl Iterator<Item = &Mesh> {
        self.shapes.iter().filter_map(|s| match s {
            Shape::Mesh(m) => Some(m),
            _ => None,
        })
    }

    /// Plane `i` (counting planes only) and its object id.
    pub fn plane(&self, i: usize) -> Option<(u32, &Plane)> {
        self.shapes
            .iter()
            .enumerate()
            .filter_map(|(id, s)| match s {
                Shape::Plane(p) => Some((id as u32, p)),
                _ => None,
            })
            .nth(i)
    }

    /// The same scene moved by `offset`: a robustness probe (issue: hard cases stay stable).
    pub fn translated(&self, offset: DVec3) -> Scene {
        self.transformed(|p| p + offset, 1.0)
    }

    /// The same scene scaled by `s` about the origin; light powers scale by s^2 so irradiance is kept.
    pub fn scaled(&self, s: f64) -> Scene {
        self.transformed(|p| p * s, s)
    }

    fn transformed(&self, f: impl Fn(DVec3) -> DVec3, scale: f64) -> Scene {
        let mut out = self.clone();
        for c in out.cameras.values_mut() {
            c.position = f(c.position);
            c.look_at = f(c.look_at);
            if let Projection::Orthographic { width } = &mut c.projection {
                *width *= scale;
            }
        }
        out.shapes = self.shapes.iter().map(|s| s.transformed(&f, scale)).collect();
        out.triangles.positions = self.triangles.positions.iter().map(|t| t.map(&f)).collect();
        out = out.with_accelerator(self.accel_settings.clone());
        for l in &mut out.lights {
            match l {
                Light::Point { position, power } => {
                    *position = f(*position);
                    *power *= scale * scale;
                }
                Light::Disk(d) => {
                    d.center = f(d.center);
                    d.radius *= scale;
                    d.power *= scale * scale;
                }
            }
        }
        out
    }
}

/// Largest shadow-ray count per light: keeps per-pixel loops and ray budgets bounded.
pub const MAX_SAMPLES: u32 = 65_536;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn light_basis_is_orthonormal_and_right_handed() {
        for n in [DVec3::Z, DVec3::NEG_Z, DVec3::new(0.3, -0.4, 0.2).normalize(), DVec3::X] {
            let d = DiskLight {
                center: DVec3::ZERO,
                normal: n,
                radius: 1.0,
                power: 1.0,
                samples: 1,
            };
            let (u, v) = d.basis();
            assert!((u.length() - 1.0).abs() < 1e-12 && (v.length() - 1.0).abs() < 1e-12);
            assert!(u.dot(v).abs() < 1e-12 && u.dot(n).abs() < 1e-12 && v.dot(n).abs() < 1e-12);
            assert!((u.cross(v) - n).length() < 1e-12);
        }
    }
}
