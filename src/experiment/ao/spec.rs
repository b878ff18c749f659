//! The ambient-occlusion experiment file: meshes x acceleration structures, each mesh scaled
//! into the unit ball and seen by a camera that frames the ball, AO along the visibility field's
//! grid lines from every camera hit (the visibility-field paper's Table 1 set-up).

use crate::accel::{kdtree::KdSettings, vlf::VlfSettings, AccelSettings, Preset};
use crate::config::{ConfigError, Source};
use crate::experiment::kind::Kind;
use crate::key_path;
use crate::mesh::{clean, Triangles};
use crate::scene::ambient::{grid_level, AmbientOcclusion, AoDirections, Weighting};
use glam::{DMat4, DVec3};
use serde::Deserialize;
use std::path::{Path, PathBuf};

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct File {
    kind: Kind,
    name: String,
    width: u32,
    height: u32,
    rays: u32,
    #[serde(default)]
    weighting: Weighting,
    max_distance: f64,
    repeats: u32,
    structures: Vec<String>,
    tuning: Tuning,
    meshes: Vec<MeshEntry>,
}

/// The small tuning sweep run per mesh before the timed frames, as the paper tuned each method
/// per scene (CRT: BSP depth and leaf size; VLF-RT: tile-BSP depth): every candidate renders
/// `frames` frames at `width` x `height`, and the fastest median is kept.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Tuning {
    /// Tuning image size.
    pub width: u32,
    /// Tuning image size.
    pub height: u32,
    /// Timed frames per candidate.
    pub frames: u32,
    /// kd-tree maximum depths tried.
    pub kdtree_depths: Vec<u32>,
    /// kd-tree leaf sizes tried.
    pub kdtree_leaves: Vec<u32>,
    /// Visibility-field tile-BSP depths tried.
    pub vlf_depths: Vec<u32>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct MeshEntry {
    name: String,
    path: PathBuf,
    #[serde(default)]
    groups: Vec<String>,
    paper: Option<PaperRow>,
}

/// The paper's Table 1 row of the scene a mesh stands in for: CRT and VLF-RT seconds at their
/// best depths.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct PaperRow {
    /// The paper's scene, e.g. "Cow (5.8K)".
    pub scene: String,
    /// CRT seconds.
    pub crt_seconds: f64,
    /// CRT's best BSP depth.
    pub crt_depth: u32,
    /// VLF-RT seconds.
    pub vlf_seconds: f64,
    /// VLF-RT's best tile-BSP depth.
    pub vlf_depth: u32,
}

/// One mesh of the experiment, loaded and scaled into the unit ball.
#[derive(Clone, Debug)]
pub struct AoMesh {
    /// Label.
    pub name: String,
    /// The mesh file.
    pub path: PathBuf,
    /// FNV-1a of the file.
    pub file_fnv1a: u64,
    /// Its triangles, centred on their bounding box and scaled so the farthest vertex is at 1.
    pub triangles: Triangles,
    /// The paper's row, where the paper has this mesh.
    pub paper: Option<PaperRow>,
}

/// A validated ambient-occlusion experiment.
#[derive(Clone, Debug)]
pub struct AoSpec {
    /// Results folder name.
    pub name: String,
    /// The experiment file.
    pub path: PathBuf,
    /// Image size.
    pub width: u32,
    /// Image size.
    pub height: u32,
    /// The pass every frame runs.
    pub ao: AmbientOcclusion,
    /// Timed frames per mesh and structure (after one untimed frame that also gives the image).
    pub repeats: u32,
    /// Registered structures to compare, each at its best settings ([`best_settings`], then
    /// the tuning sweep's pick per mesh).
    pub structures: Vec<&'static str>,
    /// The per-mesh tuning sweep.
    pub tuning: Tuning,
    /// The meshes.
    pub meshes: Vec<AoMesh>,
}

/// Each structure at its best settings before the per-mesh tuning: obvhs' slowest, best BVH
/// build, the kd-tree's best on the cow and bull (`KdSettings::default`) and the paper's
/// visibility field (513 lines, 128 x 128 tiles, depth 4).
pub fn best_settings(structure: &'static str) -> AccelSettings {
    AccelSettings {
        name: structure,
        bvh_preset: Preset::VerySlow,
        vlf: VlfSettings::default(),
        kdtree: KdSettings::default(),
    }
}

/// `positions` centred on their bounding box and scaled into the unit ball.
pub fn into_unit_ball(positions: Vec<[DVec3; 3]>) -> Triangles {
    let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
    for p in positions.iter().flatten() {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    let c = 0.5 * (lo + hi);
    let r = positions
        .iter()
        .flatten()
        .map(|p| p.distance(c))
        .fold(0.0, f64::max)
        .max(1e-300);
    let positions: Vec<[DVec3; 3]> = positions.iter().map(|t| t.map(|p| (p - c) / r)).collect();
    Triangles {
        object_of: vec![0; positions.len()],
        positions,
    }
}

impl AoSpec {
    /// Reads and validates an ambient-occlusion experiment and its meshes.
    pub fn load(path: &Path) -> Result<AoSpec, ConfigError> {
        AoSpec::from_source(&Source::read(path)?)
    }

    /// Validates an ambient-occlusion experiment read from `source` and loads its meshes.
    pub fn from_source(source: &Source) -> Result<AoSpec, ConfigError> {
        let path = source.path.as_path();
        let f: File = source.parse()?;
        let err = |p: &[crate::config::Seg], m: String| source.error(p, m);
        if f.kind != Kind::Ao {
            return Err(err(
                &key_path!["kind"],
                "an ambient-occlusion experiment has kind = \"ao\"".into(),
            ));
        }
        for (k, v) in [("width", f.width), ("height", f.height)] {
            if !(1..=16384).contains(&v) {
                return Err(err(&key_path![k], format!("must be in 1..=16384, got {v}")));
            }
        }
        let level = grid_level(f.rays).ok_or_else(|| {
            err(
                &key_path!["rays"],
                format!(
                    "the grid has 2 L^2 + 1 lines (513 for the paper's level 16), got {}",
                    f.rays
                ),
            )
        })?;
        if !(f.max_distance.is_finite() && f.max_distance > 0.0) {
            return Err(err(
                &key_path!["max_distance"],
                format!("must be positive, got {}", f.max_distance),
            ));
        }
        if f.repeats == 0 {
            return Err(err(&key_path!["repeats"], "at least one timed frame".into()));
        }
        let t = &f.tuning;
        for (k, v) in [("width", t.width), ("height", t.height)] {
            if !(1..=16384).contains(&v) {
                return Err(err(&key_path!["tuning", k], format!("must be in 1..=16384, got {v}")));
            }
        }
        if t.frames == 0 {
            return Err(err(&key_path!["tuning", "frames"], "at least one timed frame".into()));
        }
        for (k, values, lo, hi) in [
            ("kdtree_depths", &t.kdtree_depths, 0, crate::accel::kdtree::MAX_DEPTH),
            ("kdtree_leaves", &t.kdtree_leaves, 0, 1 << 16),
            ("vlf_depths", &t.vlf_depths, 0, 6),
        ] {
            if values.is_empty() {
                return Err(err(&key_path!["tuning", k], "list at least one value".into()));
            }
            if let Some((i, v)) = values.iter().enumerate().find(|(_, v)| !(lo..=hi).contains(*v)) {
                return Err(err(
                    &key_path!["tuning", k, i],
                    format!("must lie in {lo}..={hi}, got {v}"),
                ));
            }
        }
        let structures = crate::experiment::structure_names(source, &f.structures)?;
        let dir = path.parent().unwrap_or(Path::new("."));
        let mut meshes = Vec::new();
        for (i, m) in f.meshes.iter().enumerate() {
            let file = dir.join(&m.path);
            let at = key_path!["meshes", i, "path"];
            let raw = crate::mesh::load(&file)
                .map_err(|e| err(&at, e.to_string()))?
                .select(&m.groups, &file)
                .map_err(|e| err(&key_path!["meshes", i, "groups"], e.to_string()))?;
            let bytes = std::fs::read(&file).map_err(|e| err(&at, e.to_string()))?;
            let (kept, _) = clean(raw, &DMat4::IDENTITY);
            if kept.is_empty() {
                return Err(err(&at, format!("{} has no triangle a ray can hit", file.display())));
            }
            meshes.push(AoMesh {
                name: m.name.clone(),
                path: file,
                file_fnv1a: crate::fingerprint::fnv1a(&bytes),
                triangles: into_unit_ball(kept),
                paper: m.paper.clone(),
            });
        }
        if meshes.is_empty() {
            return Err(err(&key_path!["meshes"], "list at least one mesh".into()));
        }
        Ok(AoSpec {
            name: f.name,
            path: path.to_path_buf(),
            width: f.width,
            height: f.height,
            ao: AmbientOcclusion {
                directions: AoDirections::grid(level),
                rays: f.rays,
                weighting: f.weighting,
                max_distance: f.max_distance,
            },
            repeats: f.repeats,
            structures,
            tuning: f.tuning,
            meshes,
        })
    }
}
