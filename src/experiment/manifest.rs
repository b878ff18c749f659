//! manifest.toml: where a results folder came from, one serde struct for every kind. The build
//! (commit, clean tree, compiler) is taken when the binary was built, not from the folder it runs
//! in; every input file is named with its hash, so a reader can
//! tell whether the numbers belong to the code and files in front of them.

use super::kind::Kind;
use super::timing::Schedule;
use crate::fingerprint::fnv1a;
use crate::render::AdapterInfo;
use serde::{Deserialize, Serialize};
use std::path::{Component, Path, PathBuf};

/// Version of the manifest and of the tables beside it; raised when a column or key changes
/// name or meaning. 3: structure parameters one column each (`vlf_depth`, ...) instead of a
/// `parameters` text; fps.csv's rates `frames_per_s` and `paper_frames_per_s`; frames'
/// summary.csv names its work `nodes_visited` and `primitive_tests`.
pub const SCHEMA: u32 = 3;

/// A results folder's provenance.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// [`SCHEMA`] when written.
    pub schema: u32,
    /// The experiment's kind.
    pub kind: Kind,
    /// The experiment's name.
    pub name: String,
    /// The binary.
    pub build: Build,
    /// The run.
    pub run: RunInfo,
    /// The machine.
    pub machine: Machine,
    /// The device rendered on.
    pub adapter: AdapterInfo,
    /// How timed units were visited.
    pub timing: Schedule,
    /// Every file read, the experiment file first.
    pub inputs: Vec<Input>,
    /// What only this kind records (seeds, ground-truth samples, render plan...).
    pub details: toml::Table,
}

/// The binary that made the results.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Build {
    /// Commit it was built from.
    pub commit: String,
    /// Whether the checkout was clean then (nothing changed or untracked outside `results/`).
    pub clean: bool,
    /// FNV-1a of the executable.
    pub executable_fnv1a: String,
    /// FNV-1a of Cargo.lock as built (the dependencies' versions).
    pub cargo_lock_fnv1a: String,
    /// `rustc --version`.
    pub rustc: String,
    /// Cargo profile.
    pub profile: String,
}

impl Build {
    /// This binary's build.
    pub fn current() -> Build {
        Build {
            commit: env!("PENUMBRA_COMMIT").to_string(),
            clean: env!("PENUMBRA_CLEAN") == "true",
            executable_fnv1a: format!("{:016x}", crate::fingerprint::build_id()),
            cargo_lock_fnv1a: format!("{:016x}", fnv1a(include_bytes!("../../Cargo.lock"))),
            rustc: env!("PENUMBRA_RUSTC").to_string(),
            profile: env!("PENUMBRA_PROFILE").to_string(),
        }
    }

    /// `commit` or `commit-dirty`.
    pub fn label(&self) -> String {
        if self.clean {
            self.commit.clone()
        } else {
            format!("{}-dirty", self.commit)
        }
    }
}

/// One run of the binary.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunInfo {
    /// The command line, word by word.
    pub command_line: Vec<String>,
    /// When it started, UTC (RFC 3339).
    pub started_utc: String,
    /// Wall-clock seconds.
    pub seconds: f64,
    /// Peak resident memory, bytes, where the system says.
    pub peak_rss_bytes: Option<u64>,
}

/// The machine.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Machine {
    /// CPU model.
    pub cpu: String,
    /// Logical cores available to the process.
    pub cores: usize,
    /// Threads the CPU backend uses.
    pub threads: usize,
    /// Operating system and architecture.
    pub os: String,
}

impl Machine {
    /// This machine.
    pub fn current() -> Machine {
        let cpu = std::fs::read_to_string("/proc/cpuinfo")
            .ok()
            .and_then(|t| {
                t.lines()
                    .find(|l| l.starts_with("model name"))
                    .and_then(|l| l.split_once(':'))
                    .map(|(_, v)| v.trim().to_string())
            })
            .unwrap_or_else(|| "unknown".into());
        Machine {
            cpu,
            cores: std::thread::available_parallelism().map_or(1, |n| n.get()),
            threads: rayon::current_num_threads(),
            os: format!("{} {}", std::env::consts::OS, std::env::consts::ARCH),
        }
    }
}

/// An input file and its hash.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Input {
    /// Path as the run resolved it, relative paths with `.` and `..` folded.
    pub path: String,
    /// FNV-1a of its bytes.
    pub fnv1a: String,
    /// Its size.
    pub bytes: u64,
}

impl Input {
    /// `path` read and hashed now.
    pub fn read(path: &Path) -> std::io::Result<Input> {
        let bytes = std::fs::read(path)?;
        Ok(Input {
            path: tidy(path).display().to_string(),
            fnv1a: format!("{:016x}", fnv1a(&bytes)),
            bytes: bytes.len() as u64,
        })
    }
}

/// `path` with `.` dropped and `a/..` folded, without touching the file system.
pub fn tidy(path: &Path) -> PathBuf {
    let mut out: Vec<Component> = Vec::new();
    for c in path.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir if matches!(out.last(), Some(Component::Normal(_))) => {
                out.pop();
            }
            c => out.push(c),
        }
    }
    out.iter().collect()
}

/// Peak resident memory of this process, bytes (Linux).
pub fn peak_rss() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    line.split_whitespace().nth(1)?.parse::<u64>().ok().map(|kb| kb * 1024)
}

/// `t` seconds after the Unix epoch as an RFC 3339 UTC time (days to civil date after Howard
/// Hinnant's algorithm).
pub fn utc(t: std::time::SystemTime) -> String {
    let secs = t.duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_secs()) as i64;
    let (days, rem) = (secs.div_euclid(86_400), secs.rem_euclid(86_400));
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + (m <= 2) as i64;
    format!(
        "{y:04}-{m:02}-{d:02}T{:02}:{:02}:{:02}Z",
        rem / 3600,
        rem % 3600 / 60,
        rem % 60
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn utc_dates_of_known_instants() {
        let at = |s: u64| utc(std::time::UNIX_EPOCH + std::time::Duration::from_secs(s));
        assert_eq!(at(0), "1970-01-01T00:00:00Z");
        // `date -u -d @951782400`: the leap day of 2000.
        assert_eq!(at(951_782_400), "2000-02-29T00:00:00Z");
        assert_eq!(at(1_798_761_599), "2026-12-31T23:59:59Z");
    }

    #[test]
    fn paths_are_folded() {
        assert_eq!(
            tidy(Path::new("experiments/scenes/../../assets/x.obj")),
            PathBuf::from("assets/x.obj")
        );
        assert_eq!(tidy(Path::new("./a/./b")), PathBuf::from("a/b"));
        assert_eq!(tidy(Path::new("../a")), PathBuf::from("../a"));
    }

    #[test]
    fn a_manifest_reads_back_as_written() {
        let m = Manifest {
            schema: SCHEMA,
            kind: Kind::Ao,
            name: "ao".into(),
            build: Build::current(),
            run: RunInfo {
                command_line: vec!["sweep".into(), "experiments/ao.toml".into()],
                started_utc: utc(std::time::SystemTime::now()),
                seconds: 1.5,
                peak_rss_bytes: Some(7),
            },
            machine: Machine::current(),
            adapter: AdapterInfo {
                backend: "cpu".into(),
                name: "x".into(),
                driver: "y".into(),
                api: "cpu".into(),
                loop_cap: None,
            },
            timing: Schedule {
                seed: 1,
                warmup: 1,
                repeats: 5,
            },
            inputs: vec![Input::read(Path::new("Cargo.toml")).unwrap()],
            details: toml::Table::from_iter([("seeds".to_string(), toml::Value::from(vec![1, 2]))]),
        };
        let text = toml::to_string(&m).unwrap();
        assert_eq!(toml::from_str::<Manifest>(&text).unwrap(), m, "{text}");
        assert!(m.build.commit.len() >= 7, "{:?}", m.build);
    }
}
