//! The shapes a scene is made of, one enum as in pbrt-v4's `Shape`: the scene, both backends
//! and the exact reference match on it. An object's id is its index in [`crate::scene::Scene::shapes`].
//!
//! Analytic shapes (spheres, planes) are intersected one by one; a mesh's triangles are
//! intersected through the scene's acceleration structure ([`crate::accel`]), which holds the
//! triangles of every mesh. Each kind's f32 twin is the WGSL file beside its Rust file.

mod mesh;
mod plane;
mod sphere;

pub use mesh::Mesh;
pub use plane::Plane;
pub use sphere::Sphere;

use glam::DVec3;

/// One object of a scene.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    /// An analytic sphere.
    Sphere(Sphere),
    /// An infinite plane.
    Plane(Plane),
    /// A triangle mesh (its triangles live in the scene's triangle list).
    Mesh(Mesh),
}

/// A surface point found by a closest-hit query, before orientation towards the viewer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Surface {
    /// Position (re-projected onto analytic surfaces).
    pub point: DVec3,
    /// Unit geometric normal.
    pub normal: DVec3,
}

impl Shape {
    /// The kind's name, as in the render plan and scene files.
    pub fn kind(&self) -> &'static str {
        match self {
            Shape::Sphere(_) => "sphere",
            Shape::Plane(_) => "plane",
            Shape::Mesh(_) => "mesh",
        }
    }

    /// Lambertian albedo.
    pub fn albedo(&self) -> f64 {
        match self {
            Shape::Sphere(s) => s.albedo,
            Shape::Plane(p) => p.albedo,
            Shape::Mesh(m) => m.albedo,
        }
    }

    /// Share of light reflected as by a perfect mirror (Whitted's k_r): meshes may declare one,
    /// analytic shapes are diffuse.
    pub fn mirror(&self) -> f64 {
        match self {
            Shape::Mesh(m) => m.mirror,
            _ => 0.0,
        }
    }

    /// The nearest t > 0 along unit `dir` where an analytic shape is met (None for meshes: the
    /// accelerator answers for them).
    pub fn first_t(&self, origin: DVec3, dir: DVec3) -> Option<f64> {
        match self {
            Shape::Sphere(s) => s.first_t(origin, dir),
            Shape::Plane(p) => p.t(origin, dir).filter(|t| *t > 0.0),
            Shape::Mesh(_) => None,
        }
    }

    /// Whether an analytic shape meets the open segment origin + t dir, 0 < t < `len`.
    pub fn blocks(&self, origin: DVec3, dir: DVec3, len: f64) -> bool {
        let inside = |t: f64| t > 0.0 && t < len;
        match self {
            Shape::Sphere(s) => s.roots(origin, dir).is_some_and(|(t0, t1)| inside(t0) || inside(t1)),
            Shape::Plane(p) => p.t(origin, dir).is_some_and(inside),
            Shape::Mesh(_) => false,
        }
    }

    /// The surface of an analytic shape at a computed hit point `raw`, re-projected onto it.
    pub fn surface(&self, raw: DVec3) -> Option<Surface> {
        match self {
            Shape::Sphere(s) => {
                let point = s.reproject(raw);
                Some(Surface {
                    point,
                    normal: (point - s.center) / s.radius,
                })
            }
            Shape::Plane(p) => Some(Surface {
                point: p.reproject(raw),
                normal: p.normal,
            }),
            Shape::Mesh(_) => None,
        }
    }

    /// The same shape with every point mapped by `f`, lengths scaled by `scale` (a similarity).
    pub(crate) fn transformed(&self, f: &impl Fn(DVec3) -> DVec3, scale: f64) -> Shape {
        match self {
            Shape::Sphere(s) => Shape::Sphere(Sphere {
                center: f(s.center),
                radius: s.radius * scale,
                ..*s
            }),
            Shape::Plane(p) => Shape::Plane(Plane {
                point: f(p.point),
                ..*p
            }),
            Shape::Mesh(m) => Shape::Mesh(m.clone()),
        }
    }
}
