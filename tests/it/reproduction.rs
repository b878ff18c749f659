//! The committed results are what the code in front of the reader computes. For every folder
//! under `results/`, a seeded draw picks one of its units (a sweep's run, an ao mesh and
//! structure, an fps configuration, a frames experiment's scene, shading and viewpoint), the
//! current `sweep` binary measures that unit again from the committed experiment file, and
//! every number in its rows that does not depend on the clock (errors, widths, image hashes,
//! rays, nodes, primitive tests, memory, ambient occlusion, differing pixels) must equal the
//! committed row's text. A change in behaviour fails with the folder, the unit and the command
//! that regenerates it.
//!
//! What is changed to keep it to seconds, none of which moves a compared number: nothing is
//! timed that can be skipped (a sweep's `repeats = 0`; the other kinds' fewest rounds, no
//! warmup), tuned structures are pinned to the parameters the committed rows record (tuning
//! chooses by time), and a frames experiment renders its first frame only (a path's frame 0 and
//! a random camera's first draw do not depend on how many frames follow). Where a folder times
//! the visibility field the draw is among the field's units; random-triangle scenes are drawn up
//! to 16K triangles (narrow entries: the wide layout is checked by tests/it/visibility_field_*).
//! The sweep, fps and realtime folders and ao-bundles-gpu render on the GPU, and f32 rounds
//! differently on another device: they are compared where the adapter and driver are the
//! committed ones (CI's lavapipe, as the manifests record them), and skipped with a note
//! elsewhere or without an adapter.

use crate::common;
use penumbra::sampling::rng::Seeded;
use std::collections::BTreeMap;
use std::path::Path;

/// Seed of the draw of units; any value works, a fixed one keeps the test deterministic.
const DRAW_SEED: u32 = 2012;

type Row = BTreeMap<String, String>;

/// How one kind's folder is sampled and compared.
struct Kind {
    /// The table units are drawn from.
    units: &'static str,
    /// Tables compared, each with the columns that identify a row.
    tables: &'static [(&'static str, &'static [&'static str])],
    /// Whether its numbers come from the GPU.
    gpu: bool,
}

const SWEEP_AXES: &[&str] = &[
    "scheme",
    "pattern",
    "samples",
    "light_radius",
    "lights",
    "accelerator",
    "seed",
];
const REALTIME_ID: &[&str] = &["variant", "scheme", "rays", "frames", "accumulation", "filter", "seed"];
const FRAME_ID: &[&str] = &["triangles", "structure", "update", "shading", "viewpoint", "frame"];

fn kind_of(name: &str) -> Kind {
    match name {
        "sphere" | "body" | "body-structures" => Kind {
            units: "runs.csv",
            tables: &[
                ("runs.csv", SWEEP_AXES),
                ("ground_truth.csv", &["lights", "light_radius"]),
            ],
            gpu: true,
        },
        "fps" => Kind {
            units: "fps.csv",
            tables: &[("fps.csv", &["scene", "lights", "width", "height"])],
            gpu: true,
        },
        "realtime" | "realtime-body" => Kind {
            units: "runs.csv",
            tables: &[("runs.csv", REALTIME_ID)],
            gpu: true,
        },
        "ao" | "ao-bundles" | "ao-bundles-gpu" => Kind {
            units: "ao.csv",
            tables: &[("ao.csv", &["mesh", "structure", "issue"])],
            gpu: name.ends_with("-gpu"),
        },
        "walkthrough" | "dynamic" | "scaling" => Kind {
            units: "frames.csv",
            tables: &[("frames.csv", FRAME_ID), ("builds.csv", &["triangles", "structure"])],
            gpu: false,
        },
        other => panic!("results/{other}: no reproduction rule; add one to tests/it/reproduction.rs"),
    }
}

/// Columns whose values depend on the clock ([`common::from_clock`]), the device or the unit's
/// neighbours (a filtered run's `same_image_as_first`, `differing_pixels` and `ao_difference`
/// compare with a different first structure, or with none).
fn clock_dependent(column: &str) -> bool {
    common::from_clock(column)
        || [
            "timed_renders",
            "adapter",
            "driver",
            "api",
            "backend",
            "run_key",
            "error",
            "same_image_as_first",
            "differing_pixels",
            "ao_difference",
        ]
        .contains(&column)
}

fn read_rows(path: &Path) -> Vec<Row> {
    let mut reader = csv::Reader::from_path(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let headers = reader.headers().unwrap().clone();
    reader
        .records()
        .map(|r| {
            let r = r.unwrap();
            headers
                .iter()
                .zip(r.iter())
                .map(|(h, v)| (h.to_string(), v.to_string()))
                .collect()
        })
        .collect()
}

/// The adapter and driver a results folder's manifest records.
fn device(folder: &Path) -> (String, String) {
    let path = folder.join("manifest.toml");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let manifest: toml::Table = toml::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let adapter = &manifest["adapter"];
    let field = |key: &str| adapter[key].as_str().unwrap_or_default().to_string();
    (field("name"), field("driver"))
}

/// The experiment file with relative `scene` and `path` values made absolute (the copy runs from
/// a temporary folder).
fn absolute_paths(value: &mut toml::Value, base: &Path) {
    match value {
        toml::Value::Table(t) => {
            for (key, v) in t.iter_mut() {
                match v {
                    toml::Value::String(s) if is_file_key(key, s) && Path::new(s).is_relative() => {
                        *s = base.join(&*s).to_string_lossy().into_owned();
                    }
                    _ => absolute_paths(v, base),
                }
            }
        }
        toml::Value::Array(a) => a.iter_mut().for_each(|v| absolute_paths(v, base)),
        _ => {}
    }
}

/// Whether `key = value` names a file: `path`, or a `scene` naming a scene file (an ao mesh's
/// `paper.scene` is a label).
fn is_file_key(key: &str, value: &str) -> bool {
    key == "path" || (key == "scene" && value.ends_with(".toml"))
}

/// A CSV cell as the TOML value the experiment file would give.
fn toml_value(text: &str) -> toml::Value {
    if let Ok(i) = text.parse::<i64>() {
        toml::Value::Integer(i)
    } else if let Ok(f) = text.parse::<f64>() {
        toml::Value::Float(f)
    } else {
        toml::Value::String(text.to_string())
    }
}

/// Pins `[accel.STRUCTURE]` to the parameters a committed row records (`STRUCTURE_KEY` columns).
fn pin_parameters(doc: &mut toml::Table, rows: &[Row]) {
    let accel = doc
        .entry("accel")
        .or_insert_with(|| toml::Value::Table(toml::Table::new()))
        .as_table_mut()
        .unwrap();
    for row in rows {
        let structure = &row["structure"];
        let prefix = format!("{structure}_");
        let table = accel
            .entry(structure.clone())
            .or_insert_with(|| toml::Value::Table(toml::Table::new()))
            .as_table_mut()
            .unwrap();
        for (column, value) in row {
            if let Some(key) = column.strip_prefix(&prefix) {
                if !value.is_empty() {
                    table.insert(key.to_string(), toml_value(value));
                }
            }
        }
    }
}

/// Reruns one seeded unit of `results/NAME` and returns the differences from the committed rows
/// (empty when it reproduces); `None` when the folder needs a GPU and none is present.
fn reproduce(name: &str) -> Option<Vec<String>> {
    let kind = kind_of(name);
    if kind.gpu && common::gpu().is_none() {
        eprintln!("results/{name}: not reproduced (its numbers are GPU numbers and no adapter exists)");
        return None;
    }
    let repo = common::repo("");
    let committed = repo.join("results").join(name);
    let text = std::fs::read_to_string(repo.join(format!("experiments/{name}.toml"))).unwrap();
    let mut doc: toml::Value = toml::from_str(&text).unwrap();
    absolute_paths(&mut doc, &repo.join("experiments"));
    let units = read_rows(&committed.join(kind.units));
    // Random-triangle scenes are drawn up to 16K triangles: a larger field takes its build's
    // tens of seconds and gigabytes for numbers the smaller ones already check. Where a folder
    // times the visibility field, the draw is among its units, so the field is always checked.
    let random_scene = doc
        .get("scene")
        .and_then(|s| s.get("generator"))
        .and_then(|g| g.as_str())
        == Some("random-triangles");
    let small = |r: &Row| !random_scene || r["triangles"].parse::<u64>().is_ok_and(|t| t <= 16_000);
    let field = |r: &Row| {
        ["structure", "accelerator"]
            .iter()
            .any(|c| r.get(*c).is_some_and(|v| v == "vlf"))
    };
    let has_field = units.iter().any(field);
    let cheap: Vec<&Row> = units.iter().filter(|r| small(r) && (!has_field || field(r))).collect();
    assert!(!cheap.is_empty(), "results/{name}: no unit to draw");
    let mut draw = Seeded(DRAW_SEED ^ penumbra::fingerprint::fnv1a(name.as_bytes()) as u32);
    let unit = cheap[draw.index(cheap.len())];

    let table = doc.as_table_mut().unwrap();
    let timing = table
        .entry("timing")
        .or_insert_with(|| toml::Value::Table(toml::Table::new()))
        .as_table_mut()
        .unwrap();
    timing.insert("warmup".into(), toml::Value::Integer(0));
    let mut filters: Vec<String> = Vec::new();
    match kind.units {
        "runs.csv" if kind.tables[0].1 == REALTIME_ID => {
            // One seed of one (variant, scheme, rays) unit: its frames are one sequence, whole.
            timing.insert("repeats".into(), toml::Value::Integer(6));
            for axis in ["variant", "scheme", "rays", "seed"] {
                filters.push(format!("{axis}={}", unit[axis]));
            }
        }
        "runs.csv" => {
            timing.insert("repeats".into(), toml::Value::Integer(0));
            filters.extend(SWEEP_AXES.iter().map(|a| format!("{a}={}", unit[*a])));
        }
        "fps.csv" => {
            timing.insert("repeats".into(), toml::Value::Integer(6));
            filters.push(format!("scene={}", unit["scene"]));
            filters.push(format!("lights={}", unit["lights"]));
            filters.push(format!("resolution={}x{}", unit["width"], unit["height"]));
        }
        "ao.csv" => {
            timing.insert("repeats".into(), toml::Value::Integer(6));
            for axis in ["mesh", "structure", "issue"] {
                filters.push(format!("{axis}={}", unit[axis]));
            }
            let same_mesh: Vec<Row> = units.iter().filter(|r| r["mesh"] == unit["mesh"]).cloned().collect();
            pin_parameters(table, &same_mesh);
        }
        _ => {
            timing.insert("repeats".into(), toml::Value::Integer(3));
            table
                .get_mut("path")
                .unwrap()
                .as_table_mut()
                .unwrap()
                .insert("frames".into(), toml::Value::Integer(1));
            table.remove("tuning");
            let builds = read_rows(&committed.join("builds.csv"));
            let scene: Vec<Row> = builds
                .into_iter()
                .filter(|r| r["triangles"] == unit["triangles"])
                .collect();
            pin_parameters(table, &scene);
            if table["scene"].get("generator").and_then(|g| g.as_str()) == Some("random-triangles") {
                filters.push(format!("scene={}", unit["triangles"]));
            }
            filters.push(format!("shading={}", unit["shading"]));
            filters.push(format!("viewpoint={}", unit["viewpoint"]));
        }
    }

    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join(format!("{name}.toml"));
    std::fs::write(&file, toml::to_string(&doc).unwrap()).unwrap();
    let out = dir.path().join("out");
    let mut command = std::process::Command::new(env!("CARGO_BIN_EXE_sweep"));
    command.arg(&file).arg("--out").arg(&out).arg("-q");
    for f in &filters {
        command.arg("--filter").arg(f);
    }
    let status = command.status().unwrap();
    if !status.success() {
        return Some(vec![format!(
            "results/{name}: the unit {filters:?} did not run again ({status}); scripts/regenerate.sh {name} makes the folder anew"
        )]);
    }

    // GPU numbers are f32 arithmetic on one device and driver: another adapter rounds
    // differently, so they are compared only where the device is the committed one (as each
    // run's manifest records it).
    if kind.gpu && device(&out) != device(&committed) {
        eprintln!(
            "results/{name}: not compared: committed on {:?}, rendered now on {:?}",
            device(&committed),
            device(&out)
        );
        return None;
    }
    let mut problems = Vec::new();
    for (table, id) in kind.tables {
        let fresh = read_rows(&out.join(table));
        let old = read_rows(&committed.join(table));
        assert!(!fresh.is_empty(), "results/{name}: {table} of {filters:?} has no rows");
        for row in &fresh {
            let key: Vec<&str> = id.iter().map(|c| row[*c].as_str()).collect();
            let Some(was) = old.iter().find(|r| id.iter().zip(&key).all(|(c, v)| r[*c] == *v)) else {
                problems.push(format!("{table} {key:?}: no committed row"));
                continue;
            };
            let columns: std::collections::BTreeSet<&String> = row.keys().chain(was.keys()).collect();
            for column in columns.into_iter().filter(|c| !clock_dependent(c)) {
                let (then, now) = (was.get(column), row.get(column));
                if then != now {
                    problems.push(format!("{table} {key:?} {column}: committed {then:?}, now {now:?}"));
                }
            }
        }
    }
    if !problems.is_empty() {
        problems.insert(
            0,
            format!(
                "results/{name} does not reproduce with the current code (unit {filters:?}); if the change is meant, regenerate it: scripts/regenerate.sh {name}"
            ),
        );
    }
    Some(problems)
}

/// Folders with a test below; every folder under `results/` must be one of them.
const FOLDERS: &[&str] = &[
    "ao",
    "ao-bundles",
    "ao-bundles-gpu",
    "body",
    "body-structures",
    "dynamic",
    "fps",
    // Judged peers' images: tests/it/peers.rs recomputes them from their CSVs.
    "peers",
    "realtime",
    "realtime-body",
    "scaling",
    "sphere",
    "walkthrough",
];

fn check(name: &str) {
    if let Some(problems) = reproduce(name) {
        assert!(problems.is_empty(), "{}", problems.join("\n"));
    }
}

#[test]
fn every_committed_folder_has_a_reproduction_test() {
    // Results folders; a plain file beside them (a stability table) is not one.
    for entry in std::fs::read_dir(common::repo("results")).unwrap() {
        let entry = entry.unwrap();
        if !entry.path().is_dir() {
            continue;
        }
        let name = entry.file_name().to_string_lossy().into_owned();
        assert!(
            FOLDERS.contains(&name.as_str()),
            "results/{name} has no reproduction test in tests/it/reproduction.rs"
        );
    }
}

macro_rules! reproduces {
    ($($test:ident: $name:literal,)*) => {
        $(
            #[test]
            fn $test() {
                check($name);
            }
        )*
    };
}

reproduces! {
    ao_reproduces: "ao",
    ao_bundles_reproduces: "ao-bundles",
    ao_bundles_gpu_reproduces: "ao-bundles-gpu",
    body_reproduces: "body",
    body_structures_reproduces: "body-structures",
    dynamic_reproduces: "dynamic",
    fps_reproduces: "fps",
    realtime_reproduces: "realtime",
    realtime_body_reproduces: "realtime-body",
    scaling_reproduces: "scaling",
    sphere_reproduces: "sphere",
    walkthrough_reproduces: "walkthrough",
}
