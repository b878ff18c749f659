//! Reading a scene file: the TOML ([`super::description`]) validated into a [`Scene`], every
//! error located by file, line and key.

use super::ambient::{grid_level, AmbientOcclusion, AoDirections};
use super::camera::{Camera, Projection};
use super::description::{AmbientDesc, LightDesc, ProjectionDesc, SceneFile};
use super::{DiskLight, Light, Mesh, Plane, Scene, Shading, Sphere, MAX_SAMPLES};
use crate::accel::{self, AccelSettings};
use crate::config::{ConfigError, Seg, Source};
use crate::key_path;
use crate::mesh::{clean, Triangles};
use crate::sampling::DiskScheme;
use glam::{DMat4, DQuat, DVec3};
use std::collections::BTreeMap;
use std::path::Path;

impl Scene {
    /// Reads and validates a scene file.
    pub fn load(path: &Path) -> Result<Scene, ConfigError> {
        Scene::from_source(&Source::read(path)?)
    }

    /// Validates a scene file's text.
    pub fn from_source(source: &Source) -> Result<Scene, ConfigError> {
        let file: SceneFile = source.parse()?;
        Scene::from_file(&file, source)
    }

    /// Validates a parsed scene file; errors are located in `source`.
    pub fn from_file(file: &SceneFile, source: &Source) -> Result<Scene, ConfigError> {
        let v = Validator { source };
        let mut cameras = BTreeMap::new();
        for (name, c) in &file.cameras {
            let at = |k: &str| key_path!["cameras", name.as_str(), k];
            let position = v.point(&c.position, &at("position"))?;
            let look_at = v.point(&c.look_at, &at("look_at"))?;
            let up = v.point(&c.up, &at("up"))?;
            let projection = match c.projection {
                ProjectionDesc::Perspective => {
                    let fov = c.fov_y.ok_or_else(|| {
                        source.error(&at("projection"), "a perspective camera needs `fov_y` (degrees)")
                    })?;
                    if !(fov > 0.0 && fov < 180.0) {
                        return Err(source.error(&at("fov_y"), format!("must be in (0, 180) degrees, got {fov}")));
                    }
                    Projection::Perspective { fov_y_deg: fov }
                }
                ProjectionDesc::Orthographic => {
                    let w = c.width.ok_or_else(|| {
                        source.error(&at("projection"), "an orthographic camera needs `width` (metres)")
                    })?;
                    v.positive(w, &at("width"))?;
                    Projection::Orthographic { width: w }
                }
            };
            let camera = Camera {
                position,
                look_at,
                up,
                projection,
            };
            if camera.frame().is_none() {
                return Err(source.error(
                    &at("up"),
                    "`up` must not be parallel to the viewing direction, and `look_at` must differ from `position`",
                ));
            }
            cameras.insert(name.clone(), camera);
        }
        let mut spheres = Vec::new();
        let chosen = accel::registered(&file.accelerator.0).ok_or_else(|| {
            source.error(
                &key_path!["accelerator"],
                format!(
                    "unknown acceleration structure `{}`; known: {}",
                    file.accelerator.0,
                    accel::names().join(", ")
                ),
            )
        })?;
        let tables: BTreeMap<&'static str, AccelSettings> =
            accel::settings::read_tables(source, &key_path!["accel"], &file.accel, false)?
                .into_iter()
                .map(|(name, mut one)| (name, one.remove(0)))
                .collect();
        let settings = tables
            .get(chosen.name)
            .cloned()
            .unwrap_or_else(|| AccelSettings::default_for(chosen));
        for (i, s) in file.spheres.iter().enumerate() {
            spheres.push(Sphere {
                center: v.point(&s.center, &key_path!["spheres", i, "center"])?,
                radius: v.positive(s.radius, &key_path!["spheres", i, "radius"])?,
                albedo: v.albedo(s.albedo, &key_path!["spheres", i, "albedo"])?,
            });
        }
        let mut planes = Vec::new();
        for (i, p) in file.planes.iter().enumerate() {
            planes.push(Plane {
                point: v.point(&p.point, &key_path!["planes", i, "point"])?,
                normal: v.direction(&p.normal, &key_path!["planes", i, "normal"])?,
                albedo: v.albedo(p.albedo, &key_path!["planes", i, "albedo"])?,
            });
        }
        if file.lights.len() > super::MAX_LIGHTS {
            return Err(source.error(
                &key_path!["lights", super::MAX_LIGHTS],
                format!(
                    "{} lights listed; a scene may hold at most {}",
                    file.lights.len(),
                    super::MAX_LIGHTS
                ),
            ));
        }
        let mut lights = Vec::new();
        for (i, l) in file.lights.iter().enumerate() {
            let at = |k: &str| key_path!["lights", i, k];
            lights.push(match l {
                LightDesc::Point { position, power } => Light::Point {
                    position: v.point(position, &at("position"))?,
                    power: v.non_negative(*power, &at("power"))?,
                },
                LightDesc::Disk {
                    center,
                    normal,
                    radius,
                    power,
                    samples,
                } => Light::Disk(DiskLight {
                    center: v.point(center, &at("center"))?,
                    normal: v.direction(normal, &at("normal"))?,
                    radius: v.positive(*radius, &at("radius"))?,
                    power: v.non_negative(*power, &at("power"))?,
                    samples: v.samples(*samples, &at("samples"))?,
                }),
            });
        }
        let mut meshes = Vec::new();
        let mut triangles = Triangles::default();
        let dir = source.path.parent().unwrap_or(std::path::Path::new("."));
        for (i, m) in file.meshes.iter().enumerate() {
            let at = |k: &str| key_path!["meshes", i, k];
            v.positive(m.scale, &at("scale"))?;
            v.point(&m.rotate, &at("rotate"))?;
            let translate = v.point(&m.translate, &at("translate"))?;
            let albedo = v.albedo(m.albedo, &at("albedo"))?;
            let mirror = v.fraction(m.mirror, &at("mirror"), "mirror weight")?;
            let path = dir.join(&m.path);
            let raw = crate::mesh::load(&path)
                .map_err(|e| source.error(&at("path"), e.to_string()))?
                .select(&m.groups, &path)
                .map_err(|e| source.error(&at("groups"), e.to_string()))?;
            let [rx, ry, rz] = m.rotate.map(f64::to_radians);
            let rotation = DQuat::from_rotation_z(rz) * DQuat::from_rotation_y(ry) * DQuat::from_rotation_x(rx);
            let transform = DMat4::from_scale_rotation_translation(DVec3::splat(m.scale), rotation, translate);
            let (kept, skipped) = clean(raw, &transform);
            if kept.is_empty() {
                return Err(source.error(
                    &at("path"),
                    format!("{} holds no triangle a ray can hit", path.display()),
                ));
            }
            if skipped.degenerate + skipped.non_finite > 0 {
                tracing::warn!(
                    "{}: skipped {} degenerate and {} non-finite triangles (they can never be hit)",
                    path.display(),
                    skipped.degenerate,
                    skipped.non_finite
                );
            }
            triangles.object_of.extend(std::iter::repeat_n(i as u32, kept.len()));
            let bytes = std::fs::read(&path).map_err(|e| source.error(&at("path"), e.to_string()))?;
            meshes.push(Mesh {
                source: path.display().to_string(),
                file_fnv1a: crate::fingerprint::fnv1a(&bytes),
                albedo,
                mirror,
                triangles: kept.len(),
                skipped,
            });
            triangles.positions.extend(kept);
        }
        let ambient = match &file.ambient_occlusion {
            Some(a) => Some(ambient(a, &v)?),
            None => None,
        };
        let depth = file.shading.mirror_depth;
        if depth > Shading::MAX_MIRROR_DEPTH {
            return Err(source.error(
                &key_path!["shading", "mirror_depth"],
                format!("at most {} bounces are traced, got {depth}", Shading::MAX_MIRROR_DEPTH),
            ));
        }
        Scene::analytic(spheres, planes, lights)
            .with_cameras(cameras)
            .with_ambient(ambient)
            .with_shading(Shading {
                shadows: file.shading.shadows,
                mirror_depth: depth,
            })
            .with_accel_tables(tables)
            .try_with_meshes(meshes, triangles, settings)
            .map_err(|e| source.error(&key_path!["accelerator"], format!("{e:#}")))
    }
}

/// Largest coordinate, size or scale a scene file may give (metres): a scene 20,000 km across
/// is already beyond what f32 on the GPU resolves at a pixel; past it sizes are nonsense that
/// would only exhaust memory or the exact answer's quadrature.
pub const MAX_EXTENT: f64 = crate::mesh::file::MAX_COORDINATE;

struct Validator<'a> {
    source: &'a Source,
}

impl Validator<'_> {
    fn point(&self, p: &[f64; 3], at: &[Seg]) -> Result<DVec3, ConfigError> {
        if p.iter().all(|x| x.is_finite() && x.abs() <= MAX_EXTENT) {
            Ok(DVec3::from_array(*p))
        } else {
            Err(self.source.error(
                at,
                format!("coordinates must be finite and within +-{MAX_EXTENT:e} m, got {p:?}"),
            ))
        }
    }

    fn direction(&self, p: &[f64; 3], at: &[Seg]) -> Result<DVec3, ConfigError> {
        self.point(p, at)?
            .try_normalize()
            .ok_or_else(|| self.source.error(at, "direction must be non-zero"))
    }

    fn positive(&self, x: f64, at: &[Seg]) -> Result<f64, ConfigError> {
        if x.is_finite() && x > 0.0 && x <= MAX_EXTENT {
            Ok(x)
        } else {
            Err(self
                .source
                .error(at, format!("must be positive and at most {MAX_EXTENT:e}, got {x}")))
        }
    }

    fn non_negative(&self, x: f64, at: &[Seg]) -> Result<f64, ConfigError> {
        if x.is_finite() && x >= 0.0 {
            Ok(x)
        } else {
            Err(self
                .source
                .error(at, format!("must be non-negative and finite, got {x}")))
        }
    }

    fn albedo(&self, x: f64, at: &[Seg]) -> Result<f64, ConfigError> {
        self.fraction(x, at, "albedo")
    }

    fn fraction(&self, x: f64, at: &[Seg], what: &str) -> Result<f64, ConfigError> {
        if (0.0..=1.0).contains(&x) {
            Ok(x)
        } else {
            Err(self.source.error(at, format!("{what} must be in [0, 1], got {x}")))
        }
    }

    fn samples(&self, n: u32, at: &[Seg]) -> Result<u32, ConfigError> {
        if (1..=MAX_SAMPLES).contains(&n) {
            Ok(n)
        } else {
            Err(self
                .source
                .error(at, format!("shadow-ray count must be in 1..={MAX_SAMPLES}, got {n}")))
        }
    }
}

/// The `[ambient_occlusion]` table, checked.
fn ambient(a: &AmbientDesc, v: &Validator) -> Result<AmbientOcclusion, ConfigError> {
    let at = |k: &str| key_path!["ambient_occlusion", k];
    if !(1..=MAX_SAMPLES).contains(&a.rays) {
        return Err(v
            .source
            .error(&at("rays"), format!("must be in 1..={MAX_SAMPLES}, got {}", a.rays)));
    }
    let directions = if a.directions == "grid" {
        let level = grid_level(a.rays).ok_or_else(|| {
            let near: Vec<String> = (1..=64u32)
                .map(|l| 2 * l * l + 1)
                .filter(|n| n.abs_diff(a.rays) < a.rays / 2 + 20)
                .map(|n| n.to_string())
                .collect();
            v.source.error(
                &at("rays"),
                format!(
                    "the grid has 2 L^2 + 1 lines for a level L (513 for the paper's 16); got {}, nearby: {}",
                    a.rays,
                    near.join(", ")
                ),
            )
        })?;
        AoDirections::grid(level)
    } else {
        let scheme = a.directions.parse::<DiskScheme>().map_err(|_| {
            v.source.error(
                &at("directions"),
                format!(
                    "`{}` is neither \"grid\" nor a disk scheme ({})",
                    a.directions,
                    DiskScheme::ALL
                        .iter()
                        .map(|s| s.to_string())
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            )
        })?;
        if !scheme.is_built_in() {
            return Err(v.source.error(
                &at("directions"),
                format!("`{scheme}`: points files are swept by sweep experiments; ambient occlusion takes a built-in scheme"),
            ));
        }
        if a.rays > scheme.max_samples() {
            return Err(v.source.error(
                &at("rays"),
                format!(
                    "{scheme} gives at most {} directions, got {}",
                    scheme.max_samples(),
                    a.rays
                ),
            ));
        }
        AoDirections::Disk(scheme)
    };
    let max_distance = match a.max_distance {
        Some(d) => v.positive(d, &at("max_distance"))?,
        None => f64::INFINITY,
    };
    Ok(AmbientOcclusion {
        directions,
        rays: a.rays,
        weighting: a.weighting,
        max_distance,
        issue: Default::default(),
    })
}
