//! manifest.toml: where a results folder came from, one serde struct for every kind. The build
//! (commit, clean tree, compiler) is taken when the binary was built, not from the folder it runs
//! in; every input file is named with its hash, so a reader can
//! tell whether the numbers belong to the code and files in front of them; [`staleness`] does
//! that check for every committed results folder (the test command runs it).

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
    /// Path as the run resolved it, `.` and `..` folded; an absolute path inside the folder the
    /// run ran in is written relative to it, so that the same file reads the same however it was
    /// named and a results folder copied from another checkout still names its inputs.
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
        let tidied = tidy(path);
        let shown = std::env::current_dir()
            .ok()
            .and_then(|here| tidied.strip_prefix(tidy(&here)).ok().map(Path::to_path_buf))
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or(tidied);
        Ok(Input {
            path: shown.display().to_string(),
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

/// One reason a committed results folder may not belong to the code and files in front of the
/// reader, found by [`staleness`]; its text names the folder and the command that regenerates it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Problem {
    /// The folder's name under the results folder.
    pub folder: String,
    /// What is wrong with it.
    pub what: String,
}

impl std::fmt::Display for Problem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "results/{}: {}; regenerate with: scripts/regenerate.sh (this folder alone: `cargo run --release --bin sweep experiments/{}.toml`)",
            self.folder, self.what, self.folder
        )
    }
}

/// Every way the folders under `results` (each a results folder) fail to belong to one clean
/// build and to the files of the repository at `repo`: a folder without a readable manifest of
/// this [`SCHEMA`], a name or experiment file other than `experiments/FOLDER.toml`, a build from
/// a dirty tree, a commit other than the other folders', an input file missing or changed since
/// the run. Empty when every folder is fresh. Hidden entries (a run's staging folder) and plain
/// files are not results folders and are passed over.
pub fn staleness(results: &Path, repo: &Path) -> Vec<Problem> {
    let problem = |folder: &str, what: String| Problem {
        folder: folder.to_string(),
        what,
    };
    let entries = match std::fs::read_dir(results) {
        Ok(e) => e,
        Err(e) => return vec![problem(".", format!("cannot list {}: {e}", results.display()))],
    };
    let mut folders: Vec<String> = entries
        .flatten()
        .filter(|e| e.path().is_dir())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| !n.starts_with('.'))
        .collect();
    folders.sort();
    let mut problems = Vec::new();
    let mut commits: Vec<(String, String)> = Vec::new();
    for folder in &folders {
        let manifest = match read_manifest(&results.join(folder).join("manifest.toml")) {
            Ok(m) => m,
            Err(what) => {
                problems.push(problem(folder, what));
                continue;
            }
        };
        if manifest.name != *folder {
            problems.push(problem(
                folder,
                format!("its manifest names experiment `{}`, not `{folder}`", manifest.name),
            ));
        }
        if !manifest.build.clean {
            problems.push(problem(
                folder,
                format!(
                    "built from a dirty tree ({}): its numbers belong to no commit",
                    manifest.build.label()
                ),
            ));
        }
        commits.push((folder.clone(), manifest.build.commit.clone()));
        let expected = format!("experiments/{folder}.toml");
        match manifest.inputs.first() {
            Some(first) if tidy(Path::new(&first.path)) == Path::new(&expected) => {}
            Some(first) => problems.push(problem(
                folder,
                format!("made from experiment file `{}`, not `{expected}`", first.path),
            )),
            None => problems.push(problem(folder, "its manifest lists no input files".into())),
        }
        for input in &manifest.inputs {
            if let Some(what) = input_problem(input, repo) {
                problems.push(problem(folder, what));
            }
        }
    }
    problems.extend(mixed_commits(&commits).into_iter().map(|(f, w)| problem(&f, w)));
    problems
}

/// The manifest at `path`, or why it cannot be read as one of this [`SCHEMA`].
fn read_manifest(path: &Path) -> Result<Manifest, String> {
    let text = match std::fs::read_to_string(path) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Err("no manifest.toml: nothing says which build and files made it".into())
        }
        Err(e) => return Err(format!("manifest.toml cannot be read: {e}")),
    };
    let table: toml::Table = text
        .parse()
        .map_err(|e: toml::de::Error| format!("manifest.toml is not TOML: {}", one_line(&e.to_string())))?;
    if !table.contains_key("schema") {
        let commit = table.get("git_commit").and_then(|c| c.as_str());
        return Err(format!(
            "manifest.toml is in the format before schema {SCHEMA} ({}no `schema`): it does not state the build and input files that made the results",
            commit.map_or(String::new(), |c| format!("`git_commit = \"{c}\"`, "))
        ));
    }
    match table.get("schema").and_then(|s| s.as_integer()) {
        Some(s) if s == i64::from(SCHEMA) => {}
        Some(s) => return Err(format!("manifest.toml is schema {s}; this code writes schema {SCHEMA}")),
        None => return Err("manifest.toml's `schema` is not a number".into()),
    }
    toml::from_str::<Manifest>(&text).map_err(|e| {
        format!(
            "manifest.toml is not a schema {SCHEMA} manifest: {}",
            one_line(&e.to_string())
        )
    })
}

/// An error's text on one line (the TOML parser's spans several, with the offending line drawn).
fn one_line(s: &str) -> String {
    s.lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect::<Vec<_>>()
        .join(" ")
}

/// Why the input file a manifest lists no longer matches the repository's, if it does not. A
/// relative path is the run's, relative to the folder it ran in: the repository root, where
/// `results/` is.
fn input_problem(input: &Input, repo: &Path) -> Option<String> {
    let recorded = tidy(Path::new(&input.path));
    let relative = if recorded.is_absolute() {
        match recorded.strip_prefix(repo) {
            Ok(r) => r.to_path_buf(),
            Err(_) => {
                return Some(format!(
                    "input `{}` was read outside this repository (run from its root with relative paths)",
                    input.path
                ))
            }
        }
    } else {
        recorded
    };
    if relative.components().next() == Some(Component::ParentDir) {
        return Some(format!(
            "input `{}` lies outside the repository (run from its root with relative paths)",
            input.path
        ));
    }
    match Input::read(&repo.join(&relative)) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            Some(format!("input `{}` no longer exists", relative.display()))
        }
        Err(e) => Some(format!("input `{}` cannot be read: {e}", relative.display())),
        Ok(current) => {
            let now = current.fnv1a;
            (now != input.fnv1a).then(|| {
                format!(
                    "input `{}` changed since the run (FNV-1a {} then, {now} now)",
                    relative.display(),
                    input.fnv1a
                )
            })
        }
    }
}

/// The folders whose commit is not the one most folders name, each with what it is. When no
/// commit is named by more folders than every other, every folder is named.
fn mixed_commits(commits: &[(String, String)]) -> Vec<(String, String)> {
    let mut count: std::collections::BTreeMap<&str, usize> = std::collections::BTreeMap::new();
    for (_, c) in commits {
        *count.entry(c).or_default() += 1;
    }
    if count.len() < 2 {
        return vec![];
    }
    let most = count.values().copied().max().unwrap_or(0);
    let leaders: Vec<&str> = count.iter().filter(|(_, &n)| n == most).map(|(c, _)| *c).collect();
    let majority = (leaders.len() == 1).then(|| leaders[0]);
    let summary = count
        .iter()
        .map(|(c, n)| format!("{} ({n})", short(c)))
        .collect::<Vec<_>>()
        .join(", ");
    commits
        .iter()
        .filter(|(_, c)| Some(c.as_str()) != majority)
        .map(|(f, c)| {
            (
                f.clone(),
                format!(
                    "built from commit {}, but the results folders name {} commits: {summary}",
                    short(c),
                    count.len()
                ),
            )
        })
        .collect()
}

/// A commit's first 12 hex digits.
fn short(commit: &str) -> &str {
    commit.get(..12).unwrap_or(commit)
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
                threads: None,
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

    /// The commit the sample manifests name.
    const COMMIT: &str = "3ce542543f049b80f670b351f9c8c510b3f0a48f";

    /// A repository in a temporary folder: an experiment and a mesh per name, and a results
    /// folder per name whose manifest lists them as a run from the root at `commit` would.
    struct Repo {
        dir: tempfile::TempDir,
    }

    impl Repo {
        fn new(names: &[&str]) -> Repo {
            let repo = Repo {
                dir: tempfile::tempdir().unwrap(),
            };
            for name in names {
                repo.write(&format!("experiments/{name}.toml"), &format!("name = \"{name}\"\n"));
                repo.write(&format!("assets/{name}.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
                repo.run(name, COMMIT, true);
            }
            repo
        }

        fn root(&self) -> &Path {
            self.dir.path()
        }

        fn write(&self, relative: &str, text: &str) {
            let p = self.root().join(relative);
            std::fs::create_dir_all(p.parent().unwrap()).unwrap();
            std::fs::write(p, text).unwrap();
        }

        fn input(&self, relative: &str) -> Input {
            let mut i = Input::read(&self.root().join(relative)).unwrap();
            i.path = relative.to_string();
            i
        }

        /// Writes `results/NAME/manifest.toml` as a run of `experiments/NAME.toml` would.
        fn run(&self, name: &str, commit: &str, clean: bool) {
            self.manifest(name, |m| {
                m.build.commit = commit.into();
                m.build.clean = clean;
            });
        }

        fn manifest(&self, name: &str, edit: impl FnOnce(&mut Manifest)) {
            let mut m = sample(name);
            m.inputs = vec![
                self.input(&format!("experiments/{name}.toml")),
                self.input(&format!("assets/{name}.obj")),
            ];
            edit(&mut m);
            self.write(&format!("results/{name}/manifest.toml"), &toml::to_string(&m).unwrap());
        }

        fn problems(&self) -> Vec<Problem> {
            staleness(&self.root().join("results"), self.root())
        }
    }

    fn sample(name: &str) -> Manifest {
        Manifest {
            schema: SCHEMA,
            kind: Kind::Ao,
            name: name.into(),
            build: Build {
                commit: COMMIT.into(),
                clean: true,
                ..Build::current()
            },
            run: RunInfo {
                command_line: vec!["sweep".into(), format!("experiments/{name}.toml")],
                started_utc: utc(std::time::UNIX_EPOCH),
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
                threads: None,
            },
            timing: Schedule {
                seed: 1,
                warmup: 1,
                repeats: 6,
            },
            inputs: vec![],
            details: toml::Table::new(),
        }
    }

    /// The one problem found, for `folder`, whose text holds `needle`.
    fn only(problems: &[Problem], folder: &str, needle: &str) {
        assert_eq!(problems.len(), 1, "{problems:#?}");
        assert_eq!(problems[0].folder, folder, "{problems:#?}");
        assert!(problems[0].what.contains(needle), "{needle:?} not in {}", problems[0]);
        let text = problems[0].to_string();
        assert!(text.starts_with(&format!("results/{folder}: ")), "{text}");
        assert!(text.contains("scripts/regenerate.sh"), "{text}");
        assert!(
            text.contains(&format!("cargo run --release --bin sweep experiments/{folder}.toml")),
            "{text}"
        );
    }

    #[test]
    fn a_fresh_set_passes() {
        let repo = Repo::new(&["a", "b"]);
        assert_eq!(repo.problems(), vec![]);
        // A run's staging folder and a stray file are no results folders.
        repo.write("results/.a.staging.host.1/x.csv", "x");
        repo.write("results/notes.txt", "x");
        // An input named by an absolute path inside the repository is the same file.
        repo.manifest("b", |m| {
            m.inputs[1].path = repo.root().join("assets/./b.obj").display().to_string();
        });
        assert_eq!(repo.problems(), vec![]);
    }

    #[test]
    fn a_changed_input_is_caught() {
        let repo = Repo::new(&["a", "b"]);
        repo.write("experiments/b.toml", "name = \"b\"\n# edited\n");
        only(
            &repo.problems(),
            "b",
            "input `experiments/b.toml` changed since the run",
        );
        let repo = Repo::new(&["a", "b"]);
        repo.write("assets/a.obj", "v 0 0 0\n");
        only(&repo.problems(), "a", "input `assets/a.obj` changed");
    }

    #[test]
    fn a_missing_input_is_caught() {
        let repo = Repo::new(&["a", "b"]);
        std::fs::remove_file(repo.root().join("assets/a.obj")).unwrap();
        only(&repo.problems(), "a", "input `assets/a.obj` no longer exists");
    }

    #[test]
    fn an_input_outside_the_repository_is_caught() {
        let repo = Repo::new(&["a"]);
        repo.manifest("a", |m| m.inputs[1].path = "/elsewhere/assets/a.obj".into());
        only(&repo.problems(), "a", "outside this repository");
        repo.manifest("a", |m| m.inputs[1].path = "../assets/a.obj".into());
        only(&repo.problems(), "a", "outside the repository");
    }

    #[test]
    fn a_dirty_build_is_caught() {
        let repo = Repo::new(&["a", "b"]);
        repo.run("a", COMMIT, false);
        only(
            &repo.problems(),
            "a",
            "built from a dirty tree (3ce542543f049b80f670b351f9c8c510b3f0a48f-dirty)",
        );
    }

    #[test]
    fn mixed_commits_are_caught() {
        let repo = Repo::new(&["a", "b", "c"]);
        repo.run("b", "22ab66d2415fe440541a222c3f8442bd1285999f", true);
        only(
            &repo.problems(),
            "b",
            "built from commit 22ab66d2415f, but the results folders name 2 commits",
        );
        // No commit named by most folders: every folder is named.
        let repo = Repo::new(&["a", "b"]);
        repo.run("b", "22ab66d2415fe440541a222c3f8442bd1285999f", true);
        let folders: Vec<String> = repo.problems().into_iter().map(|p| p.folder).collect();
        assert_eq!(folders, ["a", "b"]);
    }

    #[test]
    fn an_old_or_unreadable_manifest_is_caught() {
        let repo = Repo::new(&["a", "b"]);
        repo.write(
            "results/a/manifest.toml",
            "# Provenance of the results in this folder.\ngit_commit = \"f43f97ede0393c73dcdd79c660b73a2ddeca24e1-dirty\"\nexperiment = \"experiments/a.toml\"\n",
        );
        only(&repo.problems(), "a", "format before schema");
        repo.write("results/a/manifest.toml", "schema = 2\nkind = \"ao\"\nname = \"a\"\n");
        only(&repo.problems(), "a", "schema 2; this code writes schema");
        repo.write("results/a/manifest.toml", &format!("schema = {SCHEMA}\nname = \"a\"\n"));
        only(&repo.problems(), "a", "not a schema");
        repo.write("results/a/manifest.toml", "[[[");
        only(&repo.problems(), "a", "not TOML");
        std::fs::remove_file(repo.root().join("results/a/manifest.toml")).unwrap();
        only(&repo.problems(), "a", "no manifest.toml");
    }

    #[test]
    fn a_folder_made_from_another_experiment_is_caught() {
        let repo = Repo::new(&["a", "b"]);
        repo.manifest("b", |m| m.inputs.swap(0, 1));
        only(
            &repo.problems(),
            "b",
            "made from experiment file `assets/b.obj`, not `experiments/b.toml`",
        );
        let repo = Repo::new(&["a", "b"]);
        repo.manifest("b", |m| m.name = "a".into());
        only(&repo.problems(), "b", "names experiment `a`, not `b`");
    }

    #[test]
    fn every_problem_is_listed() {
        let repo = Repo::new(&["a", "b", "c"]);
        repo.run("a", COMMIT, false);
        repo.write("experiments/b.toml", "changed");
        std::fs::remove_file(repo.root().join("results/c/manifest.toml")).unwrap();
        let folders: Vec<String> = repo.problems().into_iter().map(|p| p.folder).collect();
        assert_eq!(folders, ["a", "b", "c"]);
    }
}
