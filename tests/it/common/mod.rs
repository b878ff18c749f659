//! Shared test fixtures: the GPU backend (opened once per test binary) and a kind's experiment
//! run on it beside the CPU ([`on_gpu`]), scene paths, results tables, and the seeded ray
//! generators of the visibility-field tests ([`rays`]).
#![allow(dead_code)]

use std::path::PathBuf;

pub mod browser;
pub mod on_gpu;
pub mod rays;
pub mod updates;

pub use on_gpu::{gpu, images_against_cpu, on_gpu_and_cpu};

/// A shipped OFF mesh's triangles as loaded (file units, assets/meshes), degenerate ones
/// dropped; every triangle of object 0.
pub fn off_mesh(name: &str) -> penumbra::mesh::Triangles {
    let file = penumbra::mesh::load(&repo(&format!("assets/meshes/{name}.off"))).unwrap();
    let (positions, _) = penumbra::mesh::clean(file.triangles, &glam::DMat4::IDENTITY);
    assert!(!positions.is_empty(), "{name}: no triangles");
    penumbra::mesh::Triangles {
        object_of: vec![0; positions.len()],
        positions,
    }
}

/// Earlier results of experiment `name` of `kind` in `out`: a runs.csv reading "earlier
/// results" and a manifest naming the experiment, so later runs recognise the folder as theirs.
pub fn earlier_results(out: &std::path::Path, kind: &str, name: &str) {
    std::fs::create_dir_all(out).unwrap();
    std::fs::write(out.join("runs.csv"), "earlier results\n").unwrap();
    std::fs::write(
        out.join("manifest.toml"),
        format!("schema = 2\nkind = \"{kind}\"\nname = \"{name}\"\n"),
    )
    .unwrap();
}

/// Checks every CSV file under `dir` (hidden journals included) against the tables' one unit
/// convention and tidy shape: times in seconds (`_s`, `_s_lo`, `_s_hi`), rates per second
/// (`_per_s`), one value per column (no `parameters` column packing several), each column named
/// once. Returns the files checked.
pub fn assert_tidy_tables(dir: &std::path::Path) -> Vec<PathBuf> {
    let mut files = vec![];
    let mut pending = vec![dir.to_path_buf()];
    while let Some(d) = pending.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                pending.push(p);
            } else if p.extension().is_some_and(|x| x == "csv") {
                files.push(p);
            }
        }
    }
    for f in &files {
        let header = csv::Reader::from_path(f).unwrap().headers().unwrap().clone();
        let names: Vec<&str> = header.iter().collect();
        for name in &names {
            let words: Vec<&str> = name.split('_').collect();
            assert!(
                !["ms", "seconds", "mrays", "fps", "mb", "parameters"]
                    .iter()
                    .any(|w| words.contains(w)),
                "{}: column {name} breaks the unit convention or packs several values: {names:?}",
                f.display()
            );
            assert_eq!(
                names.iter().filter(|n| *n == name).count(),
                1,
                "{}: {name} twice",
                f.display()
            );
        }
    }
    files
}

/// Path of a file in the repository.
pub fn repo(path: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(path)
}

/// A small ambient-occlusion experiment `name` on `backend` over one mesh (`mesh`: its name and
/// path): 8 x 8 frames of 33 rays, `bvh` against the claim's `subject`, tuned at `tuning` pixels
/// a side, with `accel` (the `[accel.NAME]` tables, which start on line 24) before the mesh.
pub fn small_ao(name: &str, backend: &str, subject: &str, tuning: u32, accel: &str, mesh: (&str, &str)) -> String {
    format!(
        r#"kind = "ao"
name = "{name}"
backend = "{backend}"
width = 8
height = 8
rays = 33
weighting = "plain"
max_distance = 4.0
structures = ["bvh", "{subject}"]

[timing]
warmup = 0
repeats = 6

[tuning]
width = {tuning}
height = {tuning}
repeats = 6

[claim]
subject = "{subject}"
baseline = "bvh"

{accel}
[[meshes]]
name = "{}"
path = "{}"
"#,
        mesh.0, mesh.1
    )
}

/// A tiny experiment over the sphere scene, written into `dir` with the scene beside it;
/// `edit` may change the experiment text first. Returns the experiment path.
pub fn tiny_experiment(dir: &std::path::Path, edit: impl Fn(String) -> String) -> PathBuf {
    std::fs::create_dir_all(dir.join("scenes")).unwrap();
    std::fs::copy(repo("experiments/scenes/sphere.toml"), dir.join("scenes/sphere.toml")).unwrap();
    let text = r#"name = "tiny"
scene = "scenes/sphere.toml"

[measure]
camera = "measure"
width = 24
height = 24

[sweep]
schemes = ["uniform", "paper"]
patterns = ["per-pixel", "shared"]
samples = [4, 16]
light_radii = [0.02]
seeds = [1, 2]

[ground_truth]
samples = 256

[timing]
warmup = 0
repeats = 0
"#;
    let path = dir.join("tiny.toml");
    std::fs::write(&path, edit(text.to_string())).unwrap();
    path
}

/// Runs experiment `text` (written to DIR/bad.toml) and checks it is refused as bad input at
/// `key`: exit status 2, the file and key named, nothing written. Returns what it said.
pub fn rejected_at(dir: &std::path::Path, text: &str, key: &str) -> String {
    let path = dir.join("bad.toml");
    std::fs::write(&path, text).unwrap();
    let out = dir.join("out");
    let (code, err) = sweep(&[path.as_os_str(), std::ffi::OsStr::new("--out"), out.as_os_str()]);
    assert_eq!(code, 2, "{key}: {err}");
    assert!(err.contains("bad.toml:") && err.contains(key), "{key}: {err}");
    assert!(!out.exists(), "{key}: wrote {}", out.display());
    err
}

/// Runs experiment file `exp` with its results in `out` and the further arguments `args`
/// (`--backend gpu`), and checks that it succeeds.
pub fn run_experiment(exp: &std::path::Path, out: &std::path::Path, args: &[&str]) {
    let mut all = vec![exp.as_os_str(), std::ffi::OsStr::new("--out"), out.as_os_str()];
    all.extend(args.iter().map(std::ffi::OsStr::new));
    let (code, err) = sweep(&all);
    assert_eq!(code, 0, "{} {args:?}: {err}", exp.display());
}

/// Runs the `sweep` binary; returns (exit code, stderr).
pub fn sweep(args: &[&std::ffi::OsStr]) -> (i32, String) {
    sweep_with(args, &[])
}

/// [`sweep`] with `env` set (a test hook, a memory share).
pub fn sweep_with(args: &[&std::ffi::OsStr], env: &[(&str, &str)]) -> (i32, String) {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_sweep"))
        .args(args)
        .envs(env.iter().copied())
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// The count `key` (`units`, `units_from_journal`) of the kind's table in the manifest of the
/// results folder `home`.
pub fn manifest_count(home: &std::path::Path, key: &str) -> i64 {
    let manifest: toml::Table = std::fs::read_to_string(home.join("manifest.toml"))
        .unwrap()
        .parse()
        .unwrap();
    manifest["details"][key].as_integer().unwrap()
}

/// Scene TOML for the receiver every test scene shares: the ground plane z = 0 and a one-sided
/// disk light of `radius` metres 2 m above the origin, facing down.
pub fn plane_and_light(radius: f64) -> String {
    format!(
        r#"
[[planes]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
albedo = 0.8

[[lights]]
type = "disk"
center = [0.0, 0.0, 2.0]
normal = [0.0, 0.0, -1.0]
radius = {radius}
power = 60.0
samples = 16
"#
    )
}

/// Scene TOML of one OBJ mesh (`obj`, relative to the scene file) under the shared receiver and
/// light, seen by an orthographic measuring camera 0.6 m wide looking straight down.
pub fn mesh_over_plane(obj: &str, light_radius: f64) -> String {
    format!(
        r#"
[cameras.measure]
projection = "orthographic"
position = [0.0, 0.0, 3.0]
look_at = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
width = 0.6

[[meshes]]
path = "{obj}"
albedo = 0.7
"#
    ) + &plane_and_light(light_radius)
}

/// A scene of `triangles` alone (one mesh, every triangle its own), indexed by structure
/// `name`: what the structure tests probe.
pub fn triangles_scene(triangles: &penumbra::mesh::Triangles, name: &'static str) -> penumbra::scene::Scene {
    let mesh = penumbra::scene::Mesh {
        source: "test".into(),
        file_fnv1a: 0,
        albedo: 0.5,
        mirror: 0.0,
        triangles: triangles.positions.len(),
        skipped: Default::default(),
    };
    penumbra::scene::Scene::analytic(vec![], vec![], vec![]).with_meshes(
        vec![mesh],
        penumbra::mesh::Triangles {
            positions: triangles.positions.clone(),
            object_of: vec![0; triangles.positions.len()],
        },
        penumbra::accel::AccelSettings::named(name).expect("a registered structure"),
    )
}

/// A CPU backend that refuses what `refuses` picks: the runner's failure paths. `timing_too`
/// refuses timing the same frames (a device that cannot render a configuration at all).
pub struct Refusing {
    /// The working device underneath.
    pub cpu: penumbra::render::cpu::CpuBackend,
    /// Which frames fail.
    pub refuses: fn(&penumbra::render::Sampling) -> bool,
    /// Whether timing them fails too.
    pub timing_too: bool,
}

impl Refusing {
    /// Fails every render with seed 2 (timing, by the first seed, works): a flaky device.
    pub fn seed_2() -> Refusing {
        Refusing {
            cpu: Default::default(),
            refuses: |s| s.seed == 2,
            timing_too: false,
        }
    }
}

impl penumbra::render::Backend for Refusing {
    fn adapter(&self) -> &penumbra::render::AdapterInfo {
        self.cpu.adapter()
    }
    fn dispatches(&self) -> u64 {
        self.cpu.dispatches()
    }
    fn render(
        &mut self,
        scene: &penumbra::scene::Scene,
        view: penumbra::render::View,
        s: penumbra::render::Sampling,
    ) -> anyhow::Result<penumbra::render::Frame> {
        anyhow::ensure!(!(self.refuses)(&s), "simulated device loss");
        self.cpu.render(scene, view, s)
    }
    fn time(
        &mut self,
        scene: &penumbra::scene::Scene,
        view: penumbra::render::View,
        s: penumbra::render::Sampling,
        warmup: u32,
        repeats: u32,
    ) -> anyhow::Result<penumbra::render::Timing> {
        anyhow::ensure!(!(self.timing_too && (self.refuses)(&s)), "simulated device loss");
        self.cpu.time(scene, view, s, warmup, repeats)
    }
}

/// The sampling site the GPU's `disk_points` hook uses for pixel index `pixel` (light 0, an image
/// 64 wide) in frame `frame`, for comparing it with the CPU's points.
pub fn hook_site(seed: u32, pixel: u32, frame: u32) -> penumbra::sampling::Site {
    penumbra::sampling::Site::pixel(seed, 0, [pixel % 64, pixel / 64], pixel, frame)
}

/// Columns whose values come from the clock (timing phases, builds, updates).
const CLOCK_COLUMNS: [&str; 9] = [
    "timed_frames",
    "primary_s",
    "rays_per_s",
    "primary_rays_per_s",
    "shadow_rays_per_s",
    "frames_per_s",
    "clock",
    "build_s",
    "update_s",
];

/// Whether column `name` holds a value that comes from the clock.
pub fn from_clock(name: &str) -> bool {
    CLOCK_COLUMNS.contains(&name) || name.starts_with("frame_s")
}

/// The rows of a CSV file with the clock's columns blanked: what must not differ between runs of
/// one experiment, however its work was split, interrupted or resumed.
pub fn without_clock(path: &std::path::Path) -> Vec<Vec<String>> {
    let mut r = csv::Reader::from_path(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let header = r.headers().unwrap().clone();
    let mut rows = vec![header.iter().map(String::from).collect::<Vec<_>>()];
    for rec in r.records() {
        let rec = rec.unwrap();
        let row = rec.iter().zip(header.iter());
        rows.push(
            row.map(|(v, h)| if from_clock(h) { String::new() } else { v.to_string() })
                .collect(),
        );
    }
    rows
}

/// Writes experiment `text` to `dir/exp.toml`; returns its path.
pub fn write_experiment(dir: &std::path::Path, text: &str) -> PathBuf {
    let exp = dir.join("exp.toml");
    std::fs::write(&exp, text).unwrap();
    exp
}

/// The index of column `name` in a table's `header` ([`table`]).
pub fn column(header: &csv::StringRecord, name: &str) -> usize {
    header
        .iter()
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("no column `{name}` in {header:?}"))
}

/// A results table: its header and rows.
pub fn table(path: &std::path::Path) -> (csv::StringRecord, Vec<csv::StringRecord>) {
    let mut reader = csv::Reader::from_path(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let header = reader.headers().unwrap().clone();
    (header, reader.records().map(Result::unwrap).collect())
}
