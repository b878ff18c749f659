//! The scene file as written: serde structures with unknown keys rejected.

use serde::Deserialize;
use std::collections::BTreeMap;

/// A scene file: cameras, analytic shapes and lights.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// Named cameras; experiments pick one for measuring and one for pictures.
    pub cameras: BTreeMap<String, CameraDesc>,
    /// Analytic spheres.
    #[serde(default)]
    pub spheres: Vec<SphereDesc>,
    /// Infinite planes (the ground).
    #[serde(default)]
    pub planes: Vec<PlaneDesc>,
    /// Light sources.
    #[serde(default)]
    pub lights: Vec<LightDesc>,
    /// Triangle meshes from OBJ files.
    #[serde(default)]
    pub meshes: Vec<MeshDesc>,
    /// The acceleration structure over the meshes' triangles (`crate::accel::REGISTRY`).
    #[serde(default)]
    pub accelerator: crate::accel::AccelName,
    /// Each structure's parameters, `[accel.NAME]` (`crate::accel::settings`): the chosen
    /// structure's, and those a sweep over structures builds.
    #[serde(default)]
    pub accel: BTreeMap<String, toml::Table>,
    /// The ambient-occlusion pass, if the scene asks for one.
    pub ambient_occlusion: Option<AmbientDesc>,
    /// The light transport simulated (shadow rays, mirror reflections).
    #[serde(default)]
    pub shading: ShadingDesc,
}

/// `[shading]` as written ([`crate::scene::Shading`]).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShadingDesc {
    /// Shadow rays to the lights (false: OpenGL-like unoccluded local shading).
    #[serde(default = "yes")]
    pub shadows: bool,
    /// Mirror bounces after the camera ray (Whitted); 0 for none.
    #[serde(default)]
    pub mirror_depth: u32,
}

impl Default for ShadingDesc {
    fn default() -> Self {
        ShadingDesc {
            shadows: true,
            mirror_depth: 0,
        }
    }
}

fn yes() -> bool {
    true
}

/// `[ambient_occlusion]` as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AmbientDesc {
    /// `"grid"` (the visibility field's directions) or a disk scheme's name.
    pub directions: String,
    /// Rays per receiver; with `"grid"`, 2 L^2 + 1 for a level L (513: L = 16).
    pub rays: u32,
    /// `"plain"` (default) or `"cosine"`.
    #[serde(default)]
    pub weighting: crate::scene::ambient::Weighting,
    /// Farthest occluder counted (metres); none when absent.
    pub max_distance: Option<f64>,
}

/// A mesh as written: an OBJ file (relative to the scene file), some of its groups, and a
/// transform applied as scale, then rotations about x, y, z (degrees), then translation.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshDesc {
    /// OBJ file.
    pub path: std::path::PathBuf,
    /// Groups to keep (`g` names); all when empty.
    #[serde(default)]
    pub groups: Vec<String>,
    /// Uniform scale (file units to metres).
    #[serde(default = "one")]
    pub scale: f64,
    /// Rotation about x, y, z in degrees, applied in that order.
    #[serde(default)]
    pub rotate: [f64; 3],
    /// Translation in metres.
    #[serde(default)]
    pub translate: [f64; 3],
    /// Lambertian albedo in [0, 1].
    #[serde(default = "default_albedo")]
    pub albedo: f64,
    /// Mirror weight in [0, 1] (Whitted's k_r); reflections are traced where `[shading]` asks.
    #[serde(default)]
    pub mirror: f64,
}

fn one() -> f64 {
    1.0
}

/// A camera as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraDesc {
    /// `perspective` or `orthographic`.
    pub projection: ProjectionDesc,
    /// Eye, or centre of the orthographic image plane, in metres.
    pub position: [f64; 3],
    /// Point looked at.
    pub look_at: [f64; 3],
    /// Up direction.
    #[serde(default = "default_up")]
    pub up: [f64; 3],
    /// Vertical field of view in degrees (perspective only).
    pub fov_y: Option<f64>,
    /// Horizontal extent in metres (orthographic only).
    pub width: Option<f64>,
}

fn default_up() -> [f64; 3] {
    [0.0, 0.0, 1.0]
}

/// Camera projection names.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq)]
#[serde(rename_all = "kebab-case")]
pub enum ProjectionDesc {
    /// Pinhole.
    Perspective,
    /// Parallel rays.
    Orthographic,
}

/// A sphere as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SphereDesc {
    /// Centre, metres.
    pub center: [f64; 3],
    /// Radius, metres.
    pub radius: f64,
    /// Lambertian albedo in [0, 1].
    #[serde(default = "default_albedo")]
    pub albedo: f64,
}

/// A plane as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlaneDesc {
    /// Any point on the plane.
    pub point: [f64; 3],
    /// Normal (need not be unit length); the lit side.
    pub normal: [f64; 3],
    /// Lambertian albedo in [0, 1].
    #[serde(default = "default_albedo")]
    pub albedo: f64,
}

fn default_albedo() -> f64 {
    0.8
}

/// A light as written; `type` selects the kind.
#[derive(Debug, Clone, Deserialize)]
#[serde(tag = "type", rename_all = "kebab-case", deny_unknown_fields)]
pub enum LightDesc {
    /// An ideal point light: one shadow ray.
    Point {
        /// Position, metres.
        position: [f64; 3],
        /// Radiant power, watts.
        power: f64,
    },
    /// A one-sided Lambertian disk emitting along `normal`.
    Disk {
        /// Centre, metres.
        center: [f64; 3],
        /// Emitting direction.
        normal: [f64; 3],
        /// Radius, metres (the paper's bulb: 0.02).
        radius: f64,
        /// Radiant power, watts.
        power: f64,
        /// Shadow rays per receiver point.
        samples: u32,
    },
}
