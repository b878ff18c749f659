//! The ambient-occlusion experiment file: meshes x acceleration structures, each mesh scaled
//! into the unit ball and seen by a camera that frames the ball, AO along the visibility field's
//! grid lines from every camera hit (the visibility-field paper's Table 1 set-up).

use crate::accel::settings::candidates;
use crate::accel::{AccelSettings, Issue};
use crate::config::{ConfigError, Source};
use crate::experiment::comparison::{Claim, Comparison, SettingsPlaces};
use crate::experiment::header::{plain_name, Header};
use crate::experiment::tuning::KeptTuning;
use crate::key_path;
use crate::mesh::file::MAX_FILE_TRIANGLES;
use crate::mesh::{clean, Triangles};
use crate::scene::ambient::{grid_level, AmbientOcclusion, AoDirections, Weighting};
use glam::{DMat4, DVec3};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

crate::experiment_file! {
    /// An ambient-occlusion experiment's file: the shared header and these keys.
    struct File {
        width: u32,
        height: u32,
        rays: u32,
        #[serde(default)]
        weighting: Weighting,
        max_distance: f64,
        structures: Vec<String>,
        #[serde(default = "single")]
        issue: Vec<Issue>,
        tuning: Tuning,
        claim: Claim,
        #[serde(default)]
        accel: BTreeMap<String, toml::Table>,
        meshes: Vec<MeshEntry>,
    }
}

fn single() -> Vec<Issue> {
    vec![Issue::Single]
}

/// The small tuning sweep run per mesh before the timed frames, as the paper tuned each method
/// per scene (CRT: BSP depth and leaf size; VLF-RT: tile-BSP depth): a structure's candidates
/// are the lists of its `[accel.NAME]` table, or its own grid where the file gives no table;
/// each is timed at `width` x `height` in `repeats` interleaved rounds, and the first listed is
/// kept unless a later one is decidedly faster ([`crate::timing::tuning::keep`]).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Tuning {
    /// Tuning image size.
    pub width: u32,
    /// Tuning image size.
    pub height: u32,
    /// Interleaved rounds per candidate.
    pub repeats: u32,
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
    /// The shared keys (`[timing]`: the timed frames of every mesh and structure).
    pub header: Header,
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
    /// Registered structures to compare, each with its tuning candidates (one: not tuned).
    pub structures: Vec<(&'static str, Vec<AccelSettings>)>,
    /// How the AO rays are issued, each timed for every structure (`issue = ["single",
    /// "bundled"]`; the paper's measurement, single, where the file says nothing). Tuning uses
    /// single rays.
    pub issues: Vec<Issue>,
    /// The per-mesh tuning sweep.
    pub tuning: Tuning,
    /// The claim the verdict answers.
    pub claim: Claim,
    /// The meshes.
    pub meshes: Vec<AoMesh>,
    /// Settings kept by an earlier run (`--tuning`), taken instead of tuning again.
    pub reused: Option<KeptTuning>,
    /// Where each structure's settings are, for a build refused mid-run.
    pub places: SettingsPlaces,
}

/// `positions` centred on their bounding box and scaled into the unit ball.
pub fn into_unit_ball(positions: Vec<[DVec3; 3]>) -> Triangles {
    let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
    for p in positions.iter().flatten() {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    let c = 0.5 * lo + 0.5 * hi;
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
        let source = Source::read(path)?;
        AoSpec::from_source(&source, Header::read(&source)?)
    }

    /// Validates an ambient-occlusion experiment read from `source` (shared keys `header`) and
    /// loads its meshes.
    pub fn from_source(source: &Source, header: Header) -> Result<AoSpec, ConfigError> {
        let path = source.path.as_path();
        let f: File = source.parse()?;
        let err = |p: &[crate::config::Seg], m: String| source.error(p, m);
        source.image_size(&key_path!["width"], &key_path!["height"], f.width, f.height)?;
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
        if f.issue.is_empty() {
            return Err(err(
                &key_path!["issue"],
                "list at least one of `single`, `bundled`".into(),
            ));
        }
        if let Some(i) = (1..f.issue.len()).find(|&i| f.issue[..i].contains(&f.issue[i])) {
            return Err(err(
                &key_path!["issue", i],
                format!("`{}` is listed twice", f.issue[i].name()),
            ));
        }
        if !f.issue.contains(&Issue::Single) {
            return Err(err(
                &key_path!["issue"],
                "list `single` too: the verdict on the claim compares single rays, and a structure without bundles of its own (the BVHs) is timed with them only".into(),
            ));
        }
        let t = &f.tuning;
        source.image_size(
            &key_path!["tuning", "width"],
            &key_path!["tuning", "height"],
            t.width,
            t.height,
        )?;
        let least = crate::experiment::kind::Kind::Ao.min_repeats();
        if !(least..=crate::experiment::header::MAX_REPEATS).contains(&t.repeats) {
            return Err(err(
                &key_path!["tuning", "repeats"],
                format!(
                    "must be in {least}..={} (the rounds behind each candidate's median and its interval)",
                    crate::experiment::header::MAX_REPEATS
                ),
            ));
        }
        let Comparison {
            names,
            tables: mut given,
            places,
        } = Comparison::read(source, &f.structures, &f.accel, &f.claim, true)?;
        let places = places
            .with_frame((f.width, f.height), source.error(&key_path!["width"], String::new()))
            .with_frame(
                (t.width, t.height),
                source.error(&key_path!["tuning", "width"], String::new()),
            );
        let structures: Vec<(&'static str, Vec<AccelSettings>)> = names
            .into_iter()
            .map(|name| {
                let r = crate::accel::registered(name).expect("a registered name");
                let all = match given.remove(name) {
                    Some(listed) => listed,
                    None => candidates(r, &(r.tuning)()).expect("a structure's own grid is valid"),
                };
                (name, all)
            })
            .collect();
        let dir = path.parent().unwrap_or(Path::new("."));
        let mut meshes = Vec::new();
        let mut held = 0usize;
        for (i, m) in f.meshes.iter().enumerate() {
            plain_name(&m.name).map_err(|e| err(&key_path!["meshes", i, "name"], e))?;
            if f.meshes[..i].iter().any(|o| o.name == m.name) {
                return Err(err(
                    &key_path!["meshes", i, "name"],
                    format!("`{}` is listed twice", m.name),
                ));
            }
            if let Some(p) = &m.paper {
                for (k, v) in [("crt_seconds", p.crt_seconds), ("vlf_seconds", p.vlf_seconds)] {
                    if !(v.is_finite() && v > 0.0) {
                        return Err(err(
                            &key_path!["meshes", i, "paper", k],
                            format!("the paper's seconds must be positive, got {v}"),
                        ));
                    }
                }
            }
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
            // Every mesh stays loaded for the whole run: their sum is bounded, not each alone.
            held += kept.len();
            if held > MAX_FILE_TRIANGLES {
                return Err(err(
                    &at,
                    format!("the meshes up to this one hold {held} triangles, more than the {MAX_FILE_TRIANGLES} one run keeps loaded"),
                ));
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
        let available = crate::accel::memory::available();
        for (name, candidates) in &structures {
            for m in &meshes {
                for c in candidates {
                    crate::accel::memory::check(c, m.triangles.positions.len(), available).map_err(|e| {
                        places
                            .error(name, format!("mesh `{}`: {e}", m.name))
                            .expect("a compared structure")
                    })?;
                }
            }
        }
        Ok(AoSpec {
            name: header.name.clone(),
            header,
            path: path.to_path_buf(),
            width: f.width,
            height: f.height,
            ao: AmbientOcclusion {
                directions: AoDirections::grid(level),
                rays: f.rays,
                weighting: f.weighting,
                max_distance: f.max_distance,
                issue: Default::default(),
            },
            structures,
            issues: f.issue,
            tuning: f.tuning,
            claim: f.claim,
            meshes,
            reused: None,
            places,
        })
    }
}
