//! Hostile input over all four kinds, table-driven: every case exits with status 2 and a message
//! naming the file and the key (or table), never panics, writes nothing anywhere (the whole
//! scratch tree, results folder included, is byte-for-byte what it was) and leaves earlier
//! results whole. Then what only a run can show: a killed run leaves the earlier set whole and
//! the next run clears its staging folder; a folder holding another experiment's results is
//! replaced only with `--fresh`, and then as a whole.

use crate::common;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Every file under `root` with its bytes.
pub(crate) fn snapshot(root: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for e in std::fs::read_dir(&dir).unwrap().flatten() {
            let (p, kind) = (e.path(), e.file_type().unwrap());
            if kind.is_dir() {
                out.insert(p.clone(), b"<dir>".to_vec());
                stack.push(p);
            } else if kind.is_file() {
                out.insert(p.clone(), std::fs::read(&p).unwrap_or_default());
            } else {
                out.insert(p.clone(), b"<not a file>".to_vec());
            }
        }
    }
    out
}

/// The first entry of `dir` by name (`what` it must hold, for the message where it is empty).
pub(crate) fn first_file(dir: &Path, what: &str) -> PathBuf {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .min()
        .unwrap_or_else(|| panic!("{}: no {what}", dir.display()))
}

/// A scratch tree: `root/a/b/work` is the working folder (so `../../x` stays inside `root`),
/// holding the experiment as `exp.toml` and earlier results of experiment `name` (of the kind
/// the text declares) in `results/NAME`.
pub(crate) struct Scratch {
    _dir: tempfile::TempDir,
    pub(crate) root: PathBuf,
    pub(crate) work: PathBuf,
}

impl Scratch {
    pub(crate) fn new(experiment: &str, name: &str) -> Scratch {
        let dir = tempfile::tempdir().unwrap();
        let root = dir.path().to_path_buf();
        let work = root.join("a/b/work");
        std::fs::create_dir_all(&work).unwrap();
        std::fs::write(work.join("exp.toml"), experiment).unwrap();
        let kind = ["fps", "ao", "frames"]
            .into_iter()
            .find(|k| experiment.contains(&format!("kind = \"{k}\"")))
            .unwrap_or("sweep");
        common::earlier_results(&work.join("results").join(name), kind, name);
        Scratch { _dir: dir, root, work }
    }

    /// Runs the binary in the working folder.
    pub(crate) fn run(&self, args: &[&str]) -> (i32, String) {
        self.run_with(args, &[])
    }

    /// Runs the binary in the working folder with `env` set.
    fn run_with(&self, args: &[&str], env: &[(&str, &str)]) -> (i32, String) {
        let out = Command::new(env!("CARGO_BIN_EXE_sweep"))
            .current_dir(&self.work)
            .args(args)
            .envs(env.iter().copied())
            .output()
            .unwrap();
        (
            out.status.code().unwrap_or(-1),
            String::from_utf8_lossy(&out.stderr).into_owned(),
        )
    }
}

/// The shipped experiment `file` with every relative path made absolute, so it runs from any
/// folder.
fn shipped(file: &str) -> String {
    let text = std::fs::read_to_string(common::repo(&format!("experiments/{file}"))).unwrap();
    text.replace("\"../assets/", &format!("\"{}/", common::repo("assets").display()))
        .replace(
            "\"scenes/",
            &format!("\"{}/", common::repo("experiments/scenes").display()),
        )
}

/// The tiny sweep (`common::tiny_experiment`) with its scene path made absolute.
pub(crate) fn tiny() -> String {
    let dir = tempfile::tempdir().unwrap();
    let exp = common::tiny_experiment(dir.path(), |t| t);
    std::fs::read_to_string(exp).unwrap().replace(
        "\"scenes/",
        &format!("\"{}/", common::repo("experiments/scenes").display()),
    )
}

/// A scene file in the scratch tree's working folder, the sphere scene edited.
fn scene_edit(edit: impl Fn(String) -> String) -> String {
    edit(std::fs::read_to_string(common::repo("experiments/scenes/sphere.toml")).unwrap())
}

/// One hostile case: the experiment's text, extra files in the working folder, extra command
/// line words, and what the message must name.
struct Case {
    what: &'static str,
    name: &'static str,
    text: String,
    files: Vec<(&'static str, Vec<u8>)>,
    args: Vec<&'static str>,
    env: Vec<(&'static str, &'static str)>,
    names: Vec<&'static str>,
    /// Words that must not appear in the message (the contents of a file the user did not mean).
    hidden: Vec<&'static str>,
}

fn case(what: &'static str, name: &'static str, text: String, names: &[&'static str]) -> Case {
    Case {
        what,
        name,
        text,
        files: vec![],
        args: vec![],
        env: vec![],
        names: names.to_vec(),
        hidden: vec![],
    }
}

/// `text` without the table headed `header` (up to the next blank line).
fn without_table(text: &str, header: &str) -> String {
    let start = text.find(&format!("\n{header}\n")).expect("the table is there") + 1;
    let end = text[start..].find("\n\n").map_or(text.len(), |e| start + e + 1);
    assert!(text[start..end].starts_with(header));
    format!("{}{}", &text[..start], &text[end..])
}

/// Contents that make a case's file a named pipe (reading one would block for ever).
const FIFO: &[u8] = b"<fifo>";

/// Contents that make a case's file a symbolic link to the path after the marker (relative to
/// the working folder).
const LINK: &str = "<link>";

/// A case file that is a symbolic link to `target`.
fn link(target: &str) -> Vec<u8> {
    format!("{LINK}{target}").into_bytes()
}

/// Makes a case's file under `work`: a pipe, a link, or the bytes (parents created).
fn plant(work: &Path, file: &str, bytes: &[u8]) {
    let path = work.join(file);
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    if bytes == FIFO {
        let made = Command::new("mkfifo").arg(&path).status().unwrap();
        assert!(made.success(), "mkfifo");
    } else if let Some(target) = bytes.strip_prefix(LINK.as_bytes()) {
        std::os::unix::fs::symlink(work.join(std::str::from_utf8(target).unwrap()), &path).unwrap();
    } else {
        std::fs::write(&path, bytes).unwrap();
    }
}

/// The name of a staging folder a killed run of `name` on this host would have left.
fn dead_staging(name: &str) -> &'static str {
    let host = std::fs::read_to_string("/proc/sys/kernel/hostname").unwrap();
    Box::leak(format!("results/.{name}.staging.{}.{}", host.trim(), u32::MAX - 1).into_boxed_str())
}

/// An OBJ file of three vertices and one face listing them `corners` times over.
fn obj_face_of(corners: usize) -> Vec<u8> {
    let mut text = String::from("v 0 0 0.5\nv 0.1 0 0.5\nv 0 0.1 0.5\nf");
    for k in 0..corners {
        text.push_str([" 1", " 2", " 3"][k % 3]);
    }
    text.push('\n');
    text.into_bytes()
}

/// An OFF file whose one face claims `corners` corners.
fn off_claiming(corners: &str) -> Vec<u8> {
    format!("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n{corners} 0 1 2\n").into_bytes()
}

fn cases() -> Vec<Case> {
    let (sweep, fps, ao, frames) = (
        tiny(),
        shipped("fps.toml"),
        shipped("ao-ci.toml"),
        shipped("frames-ci.toml"),
    );
    let named =
        |text: &str, from: &str, to: &str| text.replacen(&format!("name = \"{from}\""), &format!("name = \"{to}\""), 1);
    let mut v = Vec::new();
    // Names that would become paths outside the results folder, in every kind.
    for (text, name) in [(&sweep, "tiny"), (&fps, "fps"), (&ao, "ao-ci"), (&frames, "frames-ci")] {
        for bad in ["../../x", "/abs/x", "..", "", "a/b", ".hidden"] {
            v.push(case(
                "a name that is a path",
                name,
                named(text, name, bad),
                &["exp.toml", "key `name`"],
            ));
        }
        v.push(case(
            "a name that is no string",
            name,
            named(text, name, "x").replacen("name = \"x\"", "name = 7", 1),
            &["exp.toml", "key `name`"],
        ));
        v.push(case(
            "a repeat count that never ends",
            name,
            text.lines()
                .map(|l| {
                    if l.starts_with("repeats = ") {
                        "repeats = 4294967295"
                    } else {
                        l
                    }
                })
                .collect::<Vec<_>>()
                .join("\n"),
            &["exp.toml", "timing.repeats"],
        ));
        v.push(case(
            "an unknown kind",
            name,
            format!("kind = \"sweeps\"\n{}", text.replacen("kind = ", "# kind = ", 1)),
            &["exp.toml", "key `kind`"],
        ));
        v.push(case(
            "a repeated table",
            name,
            format!("{text}\n[timing]\nwarmup = 1\n"),
            &["exp.toml", "`timing`", "twice"],
        ));
    }
    v.push(case(
        "an ao mesh name that is a path",
        "ao-ci",
        ao.replacen("name = \"cow\"", "name = \"../../../x\"", 1),
        &["exp.toml", "meshes[0].name"],
    ));
    v.push(case(
        "two ao meshes of one name",
        "ao-ci",
        ao.replace("name = \"mech-holes-shark\"", "name = \"cow\""),
        &["exp.toml", "meshes[1].name", "twice"],
    ));
    v.push(case(
        "an fps scene name that is a path",
        "fps",
        fps.replacen("name = \"sphere\"", "name = \"../x\"", 1),
        &["exp.toml", "scenes[0].name"],
    ));
    // Counts and sizes that would panic, abort or run out of memory.
    for (corners, what) in [
        ("18446744073709551615", "a face of 2^64 - 1 corners"),
        ("100000000000", "a face of 1e11 corners"),
    ] {
        let mut c = case(
            what,
            "ao-ci",
            ao.replacen(
                &format!("\"{}/meshes/cow.off\"", common::repo("assets").display()),
                "\"bad.off\"",
                1,
            ),
            &["bad.off:6", "meshes[0].path", "at most 65536"],
        );
        c.files.push(("bad.off", off_claiming(corners)));
        v.push(c);
    }
    let mut c = case(
        "a vertex count of 2^64 - 1",
        "ao-ci",
        ao.replacen(
            &format!("\"{}/meshes/cow.off\"", common::repo("assets").display()),
            "\"bad.off\"",
            1,
        ),
        &["bad.off", "meshes[0].path"],
    );
    c.files
        .push(("bad.off", b"OFF\n18446744073709551615 1 0\n0 0 0\n".to_vec()));
    v.push(c);
    let mut c = case(
        "a mesh path that is a pipe",
        "ao-ci",
        ao.replacen(
            &format!("\"{}/meshes/cow.off\"", common::repo("assets").display()),
            "\"pipe.off\"",
            1,
        ),
        &["exp.toml", "meshes[0].path", "not a regular file"],
    );
    c.files.push(("pipe.off", FIFO.to_vec()));
    v.push(c);
    let with_scene = |edit: &dyn Fn(String) -> String| -> (String, Vec<(&'static str, Vec<u8>)>) {
        (
            sweep.replace(
                &format!("\"{}/sphere.toml\"", common::repo("experiments/scenes").display()),
                "\"s.toml\"",
            ),
            vec![("s.toml", scene_edit(edit).into_bytes())],
        )
    };
    for (what, edit, names) in [
        (
            "an orthographic camera 1e200 m wide",
            Box::new(|t: String| t.replacen("width = 0.08", "width = 1e200", 1)) as Box<dyn Fn(String) -> String>,
            vec!["s.toml", "cameras.measure.width"],
        ),
        (
            "a camera at z = 1e300",
            Box::new(|t: String| t.replacen("position = [0.3375, 0.0, 3.0]", "position = [0.3375, 0.0, 1e300]", 1)),
            vec!["s.toml", "cameras.measure.position"],
        ),
    ] {
        let (text, files) = with_scene(&*edit);
        let mut c = case(what, "tiny", text, &names);
        c.files = files;
        v.push(c);
    }
    // Inside the allowed ranges, but 17 GB while building: refused on a 4 GB share.
    let (text, mut files) = with_scene(&|t: String| {
        format!("accelerator = \"vlf\"\n{t}\n[accel.vlf]\nlevel = 64\ntiles = 512\n\n[[meshes]]\npath = \"tri.obj\"\n")
    });
    files.push(("tri.obj", b"v 0 0 0.5\nv 0.1 0 0.5\nv 0 0.1 0.5\nf 1 2 3\n".to_vec()));
    let mut c = case(
        "a visibility field too large for the machine",
        "tiny",
        text,
        &["s.toml", "key `accelerator`", "needs at least 17.2 GB"],
    );
    c.files = files;
    c.env = vec![("PENUMBRA_MEMORY_BYTES", "4000000000")];
    v.push(c);
    // Nested triangles sharing a corner, each 1/sqrt(2) the last: the builders peel them off one
    // by one, a tree deeper than the GPU's traversal stack, refused before any work on the GPU.
    let nested: String = (0..200)
        .map(|i| {
            let s = 0.3 * 0.5f64.powf(i as f64 / 2.0);
            format!(
                "v 0 0 0.5\nv {s:e} 0 0.5\nv 0 {s:e} 0.5\nf {} {} {}\n",
                3 * i + 1,
                3 * i + 2,
                3 * i + 3
            )
        })
        .collect();
    for (structure, depth) in [("bvh", "the BVH is"), ("cwbvh", "the CWBVH is")] {
        let (text, mut files) =
            with_scene(&|t: String| format!("accelerator = \"{structure}\"\n{t}\n[[meshes]]\npath = \"nested.obj\"\n"));
        files.push(("nested.obj", nested.clone().into_bytes()));
        let mut c = case(
            "a tree deeper than the GPU's traversal stack, on the GPU",
            "tiny",
            text,
            &[
                "s.toml",
                "key `accelerator`",
                depth,
                "levels deep",
                "backend = \"cpu\" or \"auto\"",
            ],
        );
        c.files = files;
        c.args = vec!["--backend", "gpu"];
        v.push(c);
    }
    v.push(case(
        "a light as large as the world",
        "tiny",
        sweep.replace("light_radii = [0.02]", "light_radii = [1e200]"),
        &["exp.toml", "sweep.light_radii[0]"],
    ));
    v.push(case(
        "four billion random triangles",
        "frames-ci",
        frames
            .replace(
                "generator = \"classroom\"",
                "generator = \"random-triangles\"\ntriangles = [4000000000]",
            )
            .replace("[path]\nframes = 3", "[path]\nframes = 3\nviewpoints = [\"outside\"]"),
        &["exp.toml", "scene.triangles[0]"],
    ));
    v.push(case(
        "a path of four billion frames",
        "frames-ci",
        frames.replace("frames = 3", "frames = 4294967295"),
        &["exp.toml", "path.frames"],
    ));
    v.push(case(
        "cameras placed in a way no generator knows",
        "frames-ci",
        frames.replace("[path]\nframes = 3", "[path]\nframes = 3\ncameras = \"orbit\""),
        &["exp.toml", "path.cameras", "path, random"],
    ));
    v.push(case(
        "a camera seed for a path that draws nothing",
        "frames-ci",
        frames.replace("[path]\nframes = 3", "[path]\nframes = 3\nseed = 4"),
        &["exp.toml", "path.seed", "random"],
    ));
    v.push(case(
        "a tuning table with nothing to tune",
        "frames-ci",
        format!("{frames}\n[tuning]\ncameras = 2\n"),
        &["exp.toml", "tuning", "no structure lists candidates"],
    ));
    v.push(case(
        "no tuning cameras",
        "frames-ci",
        format!("{frames}\n[tuning]\ncameras = 0\n").replace("tiles = 32\ndepth = 3", "tiles = 32\ndepth = [2, 3]"),
        &["exp.toml", "tuning.cameras"],
    ));
    v.push(case(
        "tuning candidates on a path cut into blocks",
        "frames-ci",
        frames
            .replace("[path]\nframes = 3", "[path]\nframes = 3\nblock = 1")
            .replace("tiles = 32\ndepth = 3", "tiles = 32\ndepth = [2, 3]"),
        &["exp.toml", "path.block", "`vlf` lists 2 candidates", "[accel.vlf]"],
    ));
    v.push(case(
        "a moving part on a path cut into blocks",
        "frames-ci",
        format!("{frames}\n[motion]\npart = \"chrome-ball\"\nstep = [0.01, 0.0, 0.0]\n")
            .replace("[path]\nframes = 3", "[path]\nframes = 3\nblock = 1"),
        &["exp.toml", "path.block", "one unit of work"],
    ));
    v.push(case(
        "a moving part seen from random cameras",
        "frames-ci",
        format!("{frames}\n[motion]\npart = \"chrome-ball\"\nstep = [0.01, 0.0, 0.0]\n")
            .replace("[path]\nframes = 3", "[path]\nframes = 3\ncameras = \"random\""),
        &["exp.toml", "path.cameras", "not independent draws"],
    ));
    let no_field = frames
        .split("[accel.vlf]")
        .next()
        .unwrap()
        .replace(
            "structures = [\"kdtree\", \"vlf\", \"bvh\", \"brute\"]",
            "structures = [\"kdtree\", \"bvh\"]",
        )
        .replace("subject = \"vlf\"", "subject = \"bvh\"");
    v.push(case(
        "a moving part sent beyond any coordinate, with no structure that bounds it",
        "frames-ci",
        format!("{no_field}\n[motion]\npart = \"chrome-ball\"\nstep = [1e50, 0.0, 0.0]\n"),
        &["exp.toml", "motion.step", "beyond"],
    ));
    let mut c = case(
        "random-triangle scenes whose copies and structures outgrow a 1.5 GB share",
        "frames-ci",
        no_field
            .replace(
                "generator = \"classroom\"",
                "generator = \"random-triangles\"\ntriangles = [4000000, 4000001]",
            )
            .replace("[path]\nframes = 3", "[path]\nframes = 3\nviewpoints = [\"outside\"]"),
        &["exp.toml", "scene.triangles[0]", "scene copies"],
    );
    c.env = vec![("PENUMBRA_MEMORY_BYTES", "1500000000")];
    v.push(c);
    let long = |n: usize| (1..=n).map(|k| k.to_string()).collect::<Vec<_>>().join(", ");
    v.push(case(
        "a sweep of 25 million runs",
        "tiny",
        sweep
            .replace("samples = [4, 16]", &format!("samples = [{}]", long(5000)))
            .replace("seeds = [1, 2]", &format!("seeds = [{}]", long(5000))),
        &["exp.toml", "key `sweep`", "runs"],
    ));
    let mut c = case(
        "an OFF face of 17 million corners",
        "ao-ci",
        ao.replacen(
            &format!("\"{}/meshes/cow.off\"", common::repo("assets").display()),
            "\"bad.off\"",
            1,
        ),
        &["bad.off:6", "meshes[0].path", "corners"],
    );
    c.files.push(("bad.off", off_claiming("17000000")));
    v.push(c);
    let mut c = case(
        "a mesh vertex at 1.7e308",
        "ao-ci",
        ao.replacen(
            &format!("\"{}/meshes/cow.off\"", common::repo("assets").display()),
            "\"bad.off\"",
            1,
        ),
        &["bad.off:3", "meshes[0].path", "beyond"],
    );
    c.files
        .push(("bad.off", b"OFF\n3 1 0\n1.7e308 0 0\n1 0 0\n0 1 0\n3 0 1 2\n".to_vec()));
    v.push(c);
    let mut c = case(
        "an OBJ of one triangle per group, 40000 groups (must stay linear)",
        "ao-ci",
        ao.replacen(
            &format!("\"{}/meshes/cow.off\"", common::repo("assets").display()),
            "\"groups.obj\"",
            1,
        )
        .replacen("[[meshes]]", "[[meshes]]\ngroups = [\"none\"]", 1),
        &["exp.toml", "meshes[0].groups", "none"],
    );
    let groups: String = (0..40_000)
        .map(|g| format!("g g{g}\nv 0 0 {g}\nv 1 0 {g}\nv 0 1 {g}\nf -3 -2 -1\n"))
        .collect();
    c.files.push(("groups.obj", groups.into_bytes()));
    v.push(c);
    v.push(case(
        "an fps light count listed twice",
        "fps",
        fps.replacen("lights = [1, 2]", "lights = [1, 1]", 1),
        &["exp.toml", "scenes[0].lights[1]", "twice"],
    ));
    v.push(case(
        "an fps light of radius 1e300",
        "fps",
        fps.replacen("light_radius = 0.02", "light_radius = 1e300", 1),
        &["exp.toml", "light_radius"],
    ));
    let mut c = case(
        "a results folder ending in `.`",
        "tiny",
        sweep.clone(),
        &["must end in a folder name"],
    );
    c.args = vec!["--out", "fresh/."];
    v.push(c);
    let mut c = case(
        "a results folder ending in `..`",
        "tiny",
        sweep.clone(),
        &["must end in a folder name"],
    );
    c.args = vec!["--out", "fresh/.."];
    v.push(c);
    let mut c = case("a merge of 99999999 shards", "tiny", sweep.clone(), &["--merge"]);
    c.args = vec!["--merge", "99999999"];
    v.push(c);
    // Missing parts, named with their tables.
    v.push(case(
        "no [measure]",
        "tiny",
        without_table(&sweep, "[measure]"),
        &["exp.toml", "key `measure`", "missing"],
    ));
    v.push(case(
        "no scene",
        "tiny",
        sweep.replacen("scene = ", "# scene = ", 1),
        &["exp.toml", "key `scene`", "missing"],
    ));
    v.push(case(
        "no [tuning]",
        "ao-ci",
        without_table(&ao, "[tuning]"),
        &["exp.toml", "key `tuning`", "missing"],
    ));
    v.push(case(
        "no meshes",
        "ao-ci",
        ao.split("[[meshes]]").next().unwrap().to_string(),
        &["exp.toml", "key `meshes`", "missing"],
    ));
    v.push(case(
        "no [path]",
        "frames-ci",
        without_table(&frames, "[path]"),
        &["exp.toml", "key `path`", "missing"],
    ));
    v.push(case(
        "no height in [measure]",
        "tiny",
        sweep.replace("height = 24\n", ""),
        &["exp.toml", "key `measure.height`", "missing"],
    ));
    v.push(case(
        "an fps scene file that does not exist",
        "fps",
        fps.replacen("sphere-two-lights.toml", "nowhere.toml", 1),
        &["exp.toml", "scenes[0].scene", "nowhere.toml"],
    ));
    v.push(case(
        "a scene path that is a folder",
        "tiny",
        sweep.replace(
            &format!("\"{}/sphere.toml\"", common::repo("experiments/scenes").display()),
            &format!("\"{}\"", common::repo("experiments/scenes").display()),
        ),
        &["exp.toml", "key `scene`", "not a regular file"],
    ));
    // Nonsense.
    let (text, mut files) = with_scene(&|t: String| format!("{t}\n[[meshes]]\npath = \"empty.obj\"\n"));
    files.push(("empty.obj", b"# nothing\n".to_vec()));
    let mut c = case(
        "an empty OBJ in a sweep scene",
        "tiny",
        text,
        &["s.toml", "meshes[0].path", "no triangle"],
    );
    c.files = files;
    v.push(c);
    v.push(case(
        "no resolutions",
        "fps",
        fps.replace("resolutions = [[800, 600], [1920, 1080]]", "resolutions = []"),
        &["exp.toml", "resolutions"],
    ));
    v.push(case(
        "no light counts",
        "fps",
        fps.replacen("lights = [1, 2]", "lights = []", 1),
        &["exp.toml", "scenes[0].lights"],
    ));
    v.push(case(
        "a NaN paper figure",
        "fps",
        fps.replacen("paper_fps = [15.95, 9.39]", "paper_fps = [nan, 9.39]", 1),
        &["exp.toml", "scenes[0].paper_fps[0]"],
    ));
    v.push(case(
        "a negative paper figure",
        "ao-ci",
        ao.replacen("crt_seconds = 38.01", "crt_seconds = -38.01", 1),
        &["exp.toml", "meshes[0].paper.crt_seconds"],
    ));
    let (text, files) = with_scene(&|t: String| {
        t.replacen(
            "[[lights]]",
            "[[lights]]\ntype = \"point\"\nposition = [0.0, 0.0, 2.0]\npower = 10.0\n\n[[lights]]",
            1,
        )
    });
    let mut c = case(
        "a swept light count of point lights only",
        "tiny",
        text.replace("seeds = [1, 2]", "seeds = [1, 2]\nlight_counts = [1]"),
        &["exp.toml", "sweep.light_counts[0]", "disk"],
    );
    c.files = files;
    v.push(c);
    // Links planted in a results folder: refused with their path, nothing followed or moved.
    for (what, planted, target, names) in [
        (
            "a link named like a killed run's staging folder",
            dead_staging("tiny"),
            "elsewhere",
            vec![".tiny.staging.", "symbolic link"],
        ),
        (
            "a results folder's cache that is a link",
            "results/tiny/cache",
            "elsewhere",
            vec!["results/tiny/cache", "symbolic link"],
        ),
        (
            "a results folder's journal that is a link",
            "results/tiny/.journal",
            "elsewhere/.journal",
            vec!["results/tiny/.journal", "symbolic link"],
        ),
        (
            "a journal file inside a shard that is a link",
            "results/tiny/shards/1-of-2/.journal/groups.csv",
            "elsewhere/.journal/groups.csv",
            vec!["shards/1-of-2/.journal/groups.csv", "symbolic link"],
        ),
    ] {
        let mut c = case(what, "tiny", sweep.clone(), &names);
        c.files = vec![
            ("elsewhere/.journal/groups.csv", b"theirs\n".to_vec()),
            ("elsewhere/cache/ground-truth-0000000000000000.bin", b"theirs".to_vec()),
            (planted, link(target)),
        ];
        v.push(c);
    }
    let mut c = case(
        "a results folder's journal that is a file",
        "tiny",
        sweep.clone(),
        &["results/tiny/.journal", "not a folder"],
    );
    c.files = vec![("results/tiny/.journal", b"not a journal\n".to_vec())];
    v.push(c);
    let mut c = case(
        "a pipe in a results folder's cache",
        "tiny",
        sweep.clone(),
        &["results/tiny/cache/ground-truth-0000000000000000.bin", "named pipe"],
    );
    c.files = vec![("results/tiny/cache/ground-truth-0000000000000000.bin", FIFO.to_vec())];
    v.push(c);
    // A face of a million corners: refused at its line, at once.
    let with_mesh = |file: &str| {
        ao.replacen(
            &format!("\"{}/meshes/cow.off\"", common::repo("assets").display()),
            &format!("\"{file}\""),
            1,
        )
    };
    let mut c = case(
        "an OBJ face of a million corners",
        "ao-ci",
        with_mesh("huge.obj"),
        &["huge.obj:4", "meshes[0].path", "more than 65536 corners"],
    );
    c.files.push(("huge.obj", obj_face_of(1_000_000)));
    v.push(c);
    let mut c = case(
        "an OFF face of a million corners",
        "ao-ci",
        with_mesh("huge.off"),
        &["huge.off:6", "meshes[0].path", "a face of 1000000 corners"],
    );
    let listed: String = (0..1_000_000).map(|k| [" 0", " 1", " 2"][k % 3]).collect();
    c.files.push((
        "huge.off",
        format!("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n1000000{listed}\n").into_bytes(),
    ));
    v.push(c);
    let mut c = case(
        "an OBJ face of 4096 corners listed out of order",
        "ao-ci",
        with_mesh("star.obj"),
        &["star.obj:4097", "meshes[0].path", "not a convex polygon"],
    );
    let mut star = String::new();
    for k in 0..4096 {
        let a = std::f64::consts::TAU * k as f64 / 4096.0;
        star.push_str(&format!("v {} {} 0\n", a.cos(), a.sin()));
    }
    star.push('f');
    for k in 0..4096 {
        star.push_str(&format!(" {}", k * 2047 % 4096 + 1));
    }
    star.push('\n');
    c.files.push(("star.obj", star.into_bytes()));
    v.push(c);
    // Limits of the scene checked with the scene, before a backend opens.
    let nine_lights = |t: String| {
        let light = &t[t.find("[[lights]]").unwrap()..];
        format!("{t}{}", format!("\n{light}").repeat(8))
    };
    let (text, files) = with_scene(&nine_lights);
    let mut c = case(
        "a sweep scene with nine lights",
        "tiny",
        text,
        &["s.toml", "lights[8]", "at most 8"],
    );
    c.files = files;
    v.push(c);
    let mut c = case(
        "an fps scene with nine lights",
        "fps",
        fps.replacen(
            &format!(
                "\"{}/sphere-two-lights.toml\"",
                common::repo("experiments/scenes").display()
            ),
            "\"s.toml\"",
            1,
        ),
        &["s.toml", "lights[8]", "at most 8"],
    );
    c.files = vec![("s.toml", scene_edit(nine_lights).into_bytes())];
    v.push(c);
    // A points path that reaches a file the user did not mean: named, its contents not shown.
    let mut c = case(
        "a points path reaching another file",
        "tiny",
        sweep.replace(
            "schemes = [\"uniform\", \"paper\"]",
            "schemes = [\"uniform\", \"points:p\"]",
        ) + "\n[points.p]\npath = \"../../secret\"\n",
        &["secret:1", "two numbers"],
    );
    c.files = vec![(
        "../../secret",
        b"someone:x:1000:1000:hidden-word:/home/someone\n".to_vec(),
    )];
    c.hidden = vec!["someone", "hidden-word"];
    v.push(c);
    v.push(case(
        "a viewpoint listed twice",
        "frames-ci",
        frames
            .replace(
                "generator = \"classroom\"",
                "generator = \"random-triangles\"\ntriangles = [1000]",
            )
            .replace(
                "[path]\nframes = 3",
                "[path]\nframes = 3\nviewpoints = [\"outside\", \"outside\"]",
            ),
        &["exp.toml", "path.viewpoints[1]", "twice"],
    ));
    v.push(case(
        "an experiment file that is a device",
        "tiny",
        String::new(),
        &["not a regular file"],
    ));
    #[cfg(feature = "test-hooks")]
    v.extend(device_limit_cases(&sweep));
    v
}

/// Buffers past the device's binding limit (lowered by `PENUMBRA_TEST_BINDING_BYTES`, so any
/// adapter reaches them): a visibility field's tile buffer is refused at its `[accel.vlf]`
/// table, a frame's hit buffer at the measuring frame's `width`, both with exit 2 and nothing
/// written.
#[cfg(feature = "test-hooks")]
fn device_limit_cases(sweep: &str) -> Vec<Case> {
    let cow = common::repo("assets/meshes/cow.off");
    let ao = common::small_ao(
        "ao-ci",
        "gpu",
        "vlf",
        8,
        "[accel.vlf]\ndepth = 2\n",
        ("cow", &cow.display().to_string()),
    );
    let mut field = case(
        "a visibility field past the device's binding limit",
        "ao-ci",
        ao,
        &["exp.toml:24:", "accel.vlf", "tile buffer", "binding limit"],
    );
    field.env = vec![("PENUMBRA_TEST_BINDING_BYTES", "8000000")];
    let mut frame = case(
        "a frame past the device's binding limit",
        "tiny",
        format!("backend = \"gpu\"\n{sweep}"),
        &["exp.toml:", "measure.width", "24x24 frame", "hit buffer"],
    );
    frame.env = vec![("PENUMBRA_TEST_BINDING_BYTES", "4096")];
    vec![field, frame]
}

#[test]
fn every_hostile_input_is_refused_with_its_place_and_nothing_written() {
    let all = cases();
    eprintln!("{} hostile inputs", all.len());
    let mut failures = Vec::new();
    for c in &all {
        let s = Scratch::new(&c.text, c.name);
        for (file, bytes) in &c.files {
            plant(&s.work, file, bytes);
        }
        let before = snapshot(&s.root);
        let mut args = vec![if c.what == "an experiment file that is a device" {
            "/dev/zero"
        } else {
            "exp.toml"
        }];
        args.extend(&c.args);
        let (code, stderr) = s.run_with(&args, &c.env);
        let mut wrong = Vec::new();
        if code != 2 {
            wrong.push(format!("exit {code}"));
        }
        if stderr.contains("panicked") {
            wrong.push("panicked".into());
        }
        // A message broken over source lines without its continuation keeps the indentation.
        if stderr.lines().any(|l| l.trim().contains("     ")) {
            wrong.push("a run of spaces in the message".into());
        }
        for n in &c.names {
            if !stderr.contains(n) {
                wrong.push(format!("does not name `{n}`"));
            }
        }
        for h in &c.hidden {
            if stderr.contains(h) {
                wrong.push(format!("shows `{h}`, from a file's contents"));
            }
        }
        if snapshot(&s.root) != before {
            wrong.push("wrote something".into());
        }
        if !wrong.is_empty() {
            failures.push(format!("{}: {}\n{stderr}", c.what, wrong.join(", ")));
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {} cases broke a promise:\n{}",
        failures.len(),
        all.len(),
        failures.join("\n")
    );
}

/// A run killed half-way leaves the earlier results whole; the next run clears what the killed
/// one left behind and replaces the set.
#[test]
fn a_killed_run_leaves_the_earlier_results_whole() {
    let s = Scratch::new(
        &shipped("frames-ci.toml").replace("frames = 3", "frames = 12"),
        "frames-ci",
    );
    let home = s.work.join("results/frames-ci");
    let before = snapshot(&home);
    let mut child = Command::new(env!("CARGO_BIN_EXE_sweep"))
        .current_dir(&s.work)
        .arg("exp.toml")
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    // Killed once the staging folder exists (the run is under way), long before it ends.
    let staging = |dir: &Path| {
        std::fs::read_dir(dir)
            .unwrap()
            .flatten()
            .any(|e| e.file_name().to_string_lossy().starts_with(".frames-ci.staging."))
    };
    let start = std::time::Instant::now();
    while !staging(&s.work.join("results")) && start.elapsed().as_secs() < 60 {
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    std::thread::sleep(std::time::Duration::from_millis(500));
    child.kill().unwrap();
    child.wait().unwrap();
    // The journal (`.journal/`, the run's state kept for a resume) may have been started beside
    // the earlier set; the set itself is untouched.
    let mut after = snapshot(&home);
    after.retain(|path, _| !path.starts_with(home.join(".journal")));
    assert_eq!(after, before, "the earlier set changed");
    assert!(
        staging(&s.work.join("results")),
        "the killed run's staging folder is left"
    );
    let (code, stderr) = s.run(&["exp.toml"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(!staging(&s.work.join("results")), "the next run clears it");
    assert!(
        home.join("frames.csv").exists() && !home.join("runs.csv").exists(),
        "one set, the new one"
    );
}

/// Another experiment's results are refused without `--fresh` and replaced whole with it.
#[test]
fn another_experiments_results_are_replaced_only_with_fresh() {
    let text = shipped("frames-ci.toml").replace("name = \"frames-ci\"", "name = \"tiny\"");
    let s = Scratch::new(&text, "tiny");
    let home = s.work.join("results/tiny");
    common::earlier_results(&home, "sweep", "tiny");
    let before = snapshot(&s.root);
    let (code, stderr) = s.run(&["exp.toml"]);
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("another experiment") && stderr.contains("--fresh"),
        "{stderr}"
    );
    assert_eq!(snapshot(&s.root), before);
    let (code, stderr) = s.run(&["exp.toml", "--fresh"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        !home.join("runs.csv").exists(),
        "nothing of the sweep's results is left"
    );
    assert!(home.join("frames.csv").exists() && home.join("manifest.toml").exists());
}

/// `--out` through a symbolic link writes into the link's target and leaves the link a link; a
/// results folder another run holds is refused before anything is done.
#[test]
fn a_linked_results_folder_is_followed_and_a_held_one_refused() {
    let s = Scratch::new(&tiny(), "tiny");
    let target = s.work.join("target");
    std::fs::create_dir(&target).unwrap();
    std::os::unix::fs::symlink(&target, s.work.join("link")).unwrap();
    let (code, stderr) = s.run(&["exp.toml", "--out", "link"]);
    assert_eq!(code, 0, "{stderr}");
    let link = std::fs::symlink_metadata(s.work.join("link")).unwrap();
    assert!(link.file_type().is_symlink(), "the link is still a link");
    assert!(target.join("manifest.toml").exists() && target.join("runs.csv").exists());
    // Another process holds the folder: refused with status 2, nothing touched.
    use std::os::fd::AsRawFd;
    let home = s.work.join("results/tiny");
    let held = std::fs::File::open(&home).unwrap();
    // SAFETY: a valid open descriptor, unlocked when `held` is dropped.
    assert_eq!(
        unsafe { libc::flock(held.as_raw_fd(), libc::LOCK_EX | libc::LOCK_NB) },
        0
    );
    let before = snapshot(&s.root);
    let (code, stderr) = s.run(&["exp.toml"]);
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("another run is writing"), "{stderr}");
    assert_eq!(snapshot(&s.root), before);
    drop(held);
    let (code, stderr) = s.run(&["exp.toml"]);
    assert_eq!(code, 0, "{stderr}");
}

/// Runs `command`, failing the test if it runs past a minute (a read of a pipe blocks for ever).
fn output_within_a_minute(mut command: Command) -> (i32, String) {
    let mut child = command
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let start = std::time::Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            let mut stderr = String::new();
            std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut stderr).unwrap();
            return (status.code().unwrap_or(-1), stderr);
        }
        if start.elapsed().as_secs() > 60 {
            child.kill().unwrap();
            panic!("still running after a minute: {command:?}");
        }
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
}

/// A small, well-formed EXR whose header declares a `side` x `side` image: its data and display
/// windows rewritten (box2i: x min, y min, x max, y max), which a reader that trusts the header
/// allocates for before it finds the pixels missing.
fn exr_claiming(side: i32) -> Vec<u8> {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("small.exr");
    penumbra::output::images::write_exr(&path, &[0.5; 16], 4, 4).unwrap();
    let mut bytes = std::fs::read(&path).unwrap();
    for name in [&b"dataWindow\0box2i\0"[..], &b"displayWindow\0box2i\0"[..]] {
        let at = bytes
            .windows(name.len())
            .position(|w| w == name)
            .expect("a window attribute")
            + name.len()
            + 4;
        bytes[at + 8..at + 12].copy_from_slice(&(side - 1).to_le_bytes());
        bytes[at + 12..at + 16].copy_from_slice(&(side - 1).to_le_bytes());
    }
    bytes
}

/// The `page` binary on a results folder with a link or a pipe where its files or folders
/// belong, an image whose header declares more than a results image can be, or a text that is
/// not UTF-8: exit 2 naming the path, at once, and nothing written anywhere (the folder
/// included).
#[test]
fn page_refuses_links_and_pipes_where_a_folders_files_belong() {
    use penumbra::output::images::write_exr;
    let cases: Vec<(&str, &str, Vec<u8>)> = vec![
        ("images/ a link", "images", link("../elsewhere")),
        ("plots/ a link", "plots", link("../elsewhere")),
        ("report.md a link", "report.md", link("../elsewhere/report.md")),
        ("report.md a pipe", "report.md", FIFO.to_vec()),
        ("a table a pipe", "runs.csv", FIFO.to_vec()),
        ("a table a link", "more.csv", link("../elsewhere/t.csv")),
        ("an image a pipe", "images/b.exr", FIFO.to_vec()),
        ("an image a link", "images/b.exr", link("../elsewhere/x.exr")),
        ("a 60000 x 60000 image", "images/b.exr", exr_claiming(60_000)),
        ("a table not UTF-8", "runs.csv", b"a,b\n1,\xff\n".to_vec()),
        ("report.md not UTF-8", "report.md", b"# a report \xc3\x28\n".to_vec()),
    ];
    let mut failures = Vec::new();
    for (what, planted, bytes) in &cases {
        let dir = tempfile::tempdir().unwrap();
        let (folder, elsewhere) = (dir.path().join("r"), dir.path().join("elsewhere"));
        for d in [&folder, &elsewhere] {
            std::fs::create_dir_all(d.join("images")).unwrap();
            std::fs::create_dir_all(d.join("plots")).unwrap();
            std::fs::write(d.join("report.md"), "# a report\n").unwrap();
            std::fs::write(d.join("t.csv"), "a,b\n1,2\n").unwrap();
        }
        std::fs::write(folder.join("runs.csv"), "a,b\n1,2\n").unwrap();
        write_exr(&folder.join("images/a.exr"), &[0.5; 16], 4, 4).unwrap();
        // An image with no PNG beside it: a rebuild through a link would draw one there.
        write_exr(&elsewhere.join("x.exr"), &[0.25; 16], 4, 4).unwrap();
        let path = folder.join(planted);
        if std::fs::symlink_metadata(&path).is_ok_and(|m| m.is_dir()) {
            std::fs::remove_dir_all(&path).unwrap();
        } else {
            let _ = std::fs::remove_file(&path);
        }
        plant(&folder, planted, bytes);
        let before = snapshot(dir.path());
        let mut page = Command::new(env!("CARGO_BIN_EXE_page"));
        page.arg(&folder);
        let (code, stderr) = output_within_a_minute(page);
        let mut wrong = Vec::new();
        if code != 2 {
            wrong.push(format!("exit {code}"));
        }
        if !stderr.contains(&format!("r/{planted}")) {
            wrong.push(format!("does not name r/{planted}"));
        }
        // The huge image is refused from its header, not by a reader that tried to allocate it.
        if what.contains("60000") && !stderr.contains("60000 x 60000 image; refused before reading") {
            wrong.push("not refused from its header".into());
        }
        if what.contains("UTF-8") && !stderr.contains("starts an invalid sequence") {
            wrong.push("does not say where the text stops being UTF-8".into());
        }
        if snapshot(dir.path()) != before {
            wrong.push("wrote something".into());
        }
        if !wrong.is_empty() {
            failures.push(format!("{what}: {}\n{stderr}", wrong.join(", ")));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// A scene asking for OpenGL-like shading renders on whatever backend `auto` opens (every pass
/// has a GPU kernel), and a face of the most corners a face may have, on a circle, loads, builds
/// and renders.
#[test]
fn a_face_of_the_most_corners_renders_under_opengl_shading() {
    let corners = penumbra::mesh::file::MAX_FACE_CORNERS;
    let mut circle = String::new();
    for k in 0..corners {
        let a = std::f64::consts::TAU * k as f64 / corners as f64;
        circle.push_str(&format!("v {} {} 0.6\n", 0.1 * a.cos(), 0.1 * a.sin()));
    }
    circle.push('f');
    for k in 1..=corners {
        circle.push_str(&format!(" {k}"));
    }
    circle.push('\n');
    let scene = scene_edit(|t| format!("{t}\n[shading]\nshadows = false\n\n[[meshes]]\npath = \"circle.obj\"\n"));
    let text = tiny().replace(
        &format!("\"{}/sphere.toml\"", common::repo("experiments/scenes").display()),
        "\"s.toml\"",
    );
    let s = Scratch::new(&text, "tiny");
    std::fs::write(s.work.join("s.toml"), scene).unwrap();
    std::fs::write(s.work.join("circle.obj"), circle).unwrap();
    let (code, stderr) = s.run(&["exp.toml"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(!stderr.contains("backend auto: the f64 CPU backend"), "{stderr}");
    let manifest = std::fs::read_to_string(s.work.join("results/tiny/manifest.toml")).unwrap();
    let adapter = manifest.split("[adapter]").nth(1).expect("an [adapter] table");
    let expected = if common::gpu().is_some() { "gpu" } else { "cpu" };
    assert!(adapter.contains(&format!("backend = \"{expected}\"")), "{manifest}");
    assert!(manifest.contains("circle.obj"), "the mesh is an input: {manifest}");
}

/// Under an address-space limit (`ulimit -v`) a structure that would pass the free-memory check
/// but not the limit is refused before it is built, naming the limit; nothing is written.
#[test]
fn an_address_space_limit_refuses_a_build_past_it() {
    let scene = scene_edit(|t| {
        format!("accelerator = \"vlf\"\n{t}\n[accel.vlf]\nlevel = 64\ntiles = 512\n\n[[meshes]]\npath = \"tri.obj\"\n")
    });
    let text = tiny().replace(
        &format!("\"{}/sphere.toml\"", common::repo("experiments/scenes").display()),
        "\"s.toml\"",
    );
    let s = Scratch::new(&text, "tiny");
    std::fs::write(s.work.join("s.toml"), scene).unwrap();
    std::fs::write(s.work.join("tri.obj"), "v 0 0 0.5\nv 0.1 0 0.5\nv 0 0.1 0.5\nf 1 2 3\n").unwrap();
    let before = snapshot(&s.root);
    // 3 GB of address space, in KiB (below what any machine that runs the suite has free); the
    // field needs 17.2 GB.
    let out = Command::new("sh")
        .current_dir(&s.work)
        .env_remove("PENUMBRA_MEMORY_BYTES")
        .args(["-c", "ulimit -v 3000000 && exec \"$0\" exp.toml"])
        .arg(env!("CARGO_BIN_EXE_sweep"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("s.toml") && stderr.contains("needs at least 17.2 GB") && stderr.contains("RLIMIT_AS"),
        "{stderr}"
    );
    assert_eq!(snapshot(&s.root), before, "wrote something");
}

/// A sweep's journal edited after it was written (a value changed, or rows cut off) is refused
/// on resume with exit 2, naming the table and `--fresh`, and nothing of the earlier results is
/// replaced; `--fresh` measures again.
#[test]
fn an_edited_sweep_journal_is_refused_not_resumed() {
    let s = Scratch::new(&tiny(), "tiny");
    let (code, stderr) = s.run(&["exp.toml"]);
    assert_eq!(code, 0, "{stderr}");
    let home = s.work.join("results/tiny");
    let runs = first_file(&home.join(".journal"), "a journaled unit");
    let good = std::fs::read_to_string(&runs).unwrap();
    let digit = good.rfind(|c: char| c.is_ascii_digit() && c != '7').unwrap();
    let mut edited = good.clone();
    edited.replace_range(digit..digit + 1, "7");
    for bad in [edited, good[..good.len() / 2].to_string()] {
        std::fs::write(&runs, &bad).unwrap();
        let before = snapshot(&s.root);
        let (code, stderr) = s.run(&["exp.toml"]);
        assert_eq!(code, 2, "{stderr}");
        assert!(stderr.contains(".journal") && stderr.contains("--fresh"), "{stderr}");
        assert_eq!(snapshot(&s.root), before, "a refused resume changed something");
    }
    let (code, stderr) = s.run(&["exp.toml", "--fresh"]);
    assert_eq!(code, 0, "{stderr}");
}

/// A kd-tree whose leaves outgrow the memory budget is known only while it builds (slivers
/// crossing one another straddle every plane): the ao kind refuses it there as bad input, exit
/// 2, at the structure's `[accel.kdtree]` table with the mesh named, and leaves the earlier
/// results as they were (no journal folder made for nothing).
#[test]
fn a_kd_tree_outgrowing_its_budget_mid_run_is_refused_at_its_settings() {
    // Near-diameters of a circle of 1024 points, one from each point, and a small triangle
    // off to the side that moves the median planes off the centre.
    let n = 1024;
    let at = |k: usize| {
        let a = std::f64::consts::TAU * (k % n) as f64 / n as f64;
        (a.cos(), a.sin())
    };
    let mut obj = String::new();
    for k in 0..n {
        for (x, y) in [at(k), at(k + n / 2 - 1), at(k + n / 2)] {
            obj += &format!("v {x} {y} 0\n");
        }
        obj += &format!("f {} {} {}\n", 3 * k + 1, 3 * k + 2, 3 * k + 3);
    }
    obj += "v 1.6 1.3 0\nv 1.61 1.3 0\nv 1.6 1.31 0\n";
    obj += &format!("f {} {} {}\n", 3 * n + 1, 3 * n + 2, 3 * n + 3);
    let text = common::small_ao(
        "ao-ci",
        "cpu",
        "kdtree",
        8,
        "[accel.kdtree]\nmax_depth = 20\n",
        ("slivers", "slivers.obj"),
    );
    let s = Scratch::new(&text, "ao-ci");
    std::fs::write(s.work.join("slivers.obj"), obj).unwrap();
    let before = snapshot(&s.root);
    // 16 MB: the plan's estimate of each structure fits; a quarter of it, a million leaf
    // entries, does not hold this tree.
    let (code, stderr) = s.run_with(&["exp.toml"], &[("PENUMBRA_MEMORY_BYTES", "16000000")]);
    assert_eq!(code, 2, "{stderr}");
    for part in [
        "exp.toml:24:",
        "accel.kdtree",
        "mesh `slivers`",
        "triangle entries",
        "max_depth",
    ] {
        assert!(stderr.contains(part), "no `{part}` in: {stderr}");
    }
    assert_eq!(snapshot(&s.root), before, "the refused run left something behind");
}

/// An EXR whose header declares 4 x 4 pixels, made 8 GiB long (sparse: nothing on disk): the
/// page refuses it from its header and length, exit 2 naming it, without reading 8 GiB.
#[test]
fn page_refuses_an_image_longer_than_its_header_declares() {
    let dir = tempfile::tempdir().unwrap();
    let folder = dir.path().join("r");
    std::fs::create_dir_all(folder.join("images")).unwrap();
    std::fs::write(folder.join("report.md"), "# a report\n").unwrap();
    let image = folder.join("images/a.exr");
    penumbra::output::images::write_exr(&image, &[0.5; 16], 4, 4).unwrap();
    lengthen_sparsely(&image);
    // Names only: the image's 8 GiB are not read here either.
    let names = |d: &Path| -> Vec<PathBuf> {
        let mut v: Vec<PathBuf> = walk(d);
        v.sort();
        v
    };
    let before = names(&folder);
    let mut page = Command::new(env!("CARGO_BIN_EXE_page"));
    page.arg(&folder);
    let (code, stderr) = output_within_a_minute(page);
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("images/a.exr") && stderr.contains("8589934592 bytes, more than an EXR"),
        "{stderr}"
    );
    assert_eq!(names(&folder), before, "wrote something");
    assert_eq!(
        std::fs::read_to_string(folder.join("report.md")).unwrap(),
        "# a report\n"
    );
}

/// Every path under `root`.
/// Makes `path` 8 GiB long without writing the bytes (a sparse file: nothing on disk).
fn lengthen_sparsely(path: &Path) {
    std::fs::OpenOptions::new()
        .write(true)
        .open(path)
        .unwrap()
        .set_len(8 << 30)
        .unwrap();
}

fn walk(root: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(root).unwrap().flatten() {
        let p = e.path();
        if e.file_type().unwrap().is_dir() {
            out.extend(walk(&p));
        }
        out.push(p);
    }
    out
}

/// Texts the page embeds past its limit (a sparse 8 GiB CSV, report.md and a plot) are refused
/// from their length, exit 2 naming the file, before any is read; a file the page would show
/// whose name is not UTF-8 is refused naming it, not skipped.
#[test]
fn page_refuses_a_text_past_its_limit_and_a_name_it_cannot_write() {
    use std::os::unix::ffi::OsStrExt;
    for (file, long) in [
        ("runs.csv", true),
        ("report.md", true),
        ("plots/a.svg", true),
        ("a CSV named bad-\\xff.csv", false),
    ] {
        let dir = tempfile::tempdir().unwrap();
        let folder = dir.path().join("r");
        std::fs::create_dir_all(folder.join("plots")).unwrap();
        std::fs::write(folder.join("report.md"), "# a report\n").unwrap();
        let path = if long {
            let path = folder.join(file);
            std::fs::write(&path, "a,b\n").unwrap();
            lengthen_sparsely(&path);
            path
        } else {
            let name = std::ffi::OsStr::from_bytes(b"bad-\xff.csv");
            let path = folder.join(name);
            std::fs::write(&path, "a,b\n1,2\n").unwrap();
            path
        };
        let sorted = |d: &Path| {
            let mut v = walk(d);
            v.sort();
            v
        };
        let before = sorted(&folder);
        let mut page = Command::new(env!("CARGO_BIN_EXE_page"));
        page.arg(&folder);
        let (code, stderr) = output_within_a_minute(page);
        assert_eq!(code, 2, "{file}: {stderr}");
        let named = path.file_name().unwrap().to_string_lossy().into_owned();
        let why = if long {
            "8589934592 bytes, over the"
        } else {
            "not UTF-8"
        };
        assert!(stderr.contains(&named) && stderr.contains(why), "{file}: {stderr}");
        assert_eq!(sorted(&folder), before, "{file}: wrote something");
    }
}
