//! Whether the committed results folders belong to clean builds of the repository's history and
//! to the files in front of the reader ([`staleness`]; the test command runs it). Folders may
//! name different commits: a change regenerates the folders it affects
//! (`scripts/regenerate.sh NAMES`), and that the others still hold what the code in front of the
//! reader computes is what the reproduction tests (tests/it/reproduction.rs) re-measure.

use super::input::{input_problem, tidy};
use super::{Manifest, SCHEMA};
use std::path::Path;

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

/// Every way the folders under `results` (each a results folder) fail to belong to a clean
/// build of the history of the repository at `repo` and to its files: a folder without a
/// readable manifest of this [`SCHEMA`], a name or experiment file other than
/// `experiments/FOLDER.toml`, a build from a dirty tree, a commit that is not HEAD or one of its
/// ancestors (checked where `repo` is a git work tree), an input file missing or changed since
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
        // A folder of judged peers' images names its build and scene file as a manifest does,
        // but no experiment file made it.
        let provenance = results.join(folder).join(super::PROVENANCE);
        if !results.join(folder).join("manifest.toml").exists() && provenance.exists() {
            match read_provenance(&provenance) {
                Ok(p) => {
                    if !p.build.clean {
                        problems.push(problem(
                            folder,
                            format!(
                                "judged by a build from a dirty tree ({}): its numbers belong to no commit",
                                p.build.label()
                            ),
                        ));
                    }
                    commits.push((folder.clone(), p.build.commit.clone()));
                    problems.extend(
                        p.inputs
                            .iter()
                            .filter_map(|i| input_problem(i, repo))
                            .map(|w| problem(folder, w)),
                    );
                }
                Err(what) => problems.push(problem(folder, what)),
            }
            continue;
        }
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
    problems.extend(foreign_commits(&commits, repo).into_iter().map(|(f, w)| problem(&f, w)));
    problems
}

/// A judged folder's provenance, or why it cannot be read.
fn read_provenance(path: &Path) -> Result<super::Provenance, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{} cannot be read: {e}", super::PROVENANCE))?;
    toml::from_str(&text).map_err(|e: toml::de::Error| {
        format!(
            "{} is not a judge's provenance: {}",
            super::PROVENANCE,
            one_line(&e.to_string())
        )
    })
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

/// The folders whose commit is not in the history of the repository at `repo` (HEAD or an
/// ancestor of it), each with what it is: results of code that was never committed here, or of
/// a branch that did not land. Nothing where `repo` is no git work tree or a shallow clone (an
/// exported copy has no history to check against, a shallow one only part of it).
fn foreign_commits(commits: &[(String, String)], repo: &Path) -> Vec<(String, String)> {
    let shallow = std::process::Command::new("git")
        .arg("-C")
        .arg(repo)
        .args(["rev-parse", "--is-shallow-repository"])
        .output();
    match shallow {
        Ok(out) if out.status.success() && out.stdout.starts_with(b"false") => {}
        _ => return vec![],
    }
    if !repo.join(".git").exists() {
        return vec![];
    }
    commits
        .iter()
        .filter_map(|(folder, commit)| {
            let status = std::process::Command::new("git")
                .arg("-C")
                .arg(repo)
                .args(["merge-base", "--is-ancestor", commit, "HEAD"])
                .stderr(std::process::Stdio::null())
                .status();
            let what = match status {
                Ok(s) if s.success() => return None,
                Ok(_) => format!(
                    "built from commit {}, which is not HEAD or one of its ancestors",
                    short(commit)
                ),
                Err(e) => format!("cannot ask git whether commit {} is in the history: {e}", short(commit)),
            };
            Some((folder.clone(), what))
        })
        .collect()
}

/// A commit's first 12 hex digits.
fn short(commit: &str) -> &str {
    commit.get(..12).unwrap_or(commit)
}

#[cfg(test)]
mod tests {
    use super::super::tests::{sample, COMMIT};
    use super::super::Input;
    use super::*;

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
    fn folders_may_name_different_commits_of_the_history_but_no_other() {
        let repo = Repo::new(&["a", "b", "c"]);
        let git = |args: &[&str]| {
            let out = std::process::Command::new("git")
                .arg("-C")
                .arg(repo.root())
                .args([
                    "-c",
                    "user.name=t",
                    "-c",
                    "user.email=t@t",
                    "-c",
                    "commit.gpgsign=false",
                ])
                .args(args)
                .output()
                .unwrap();
            assert!(
                out.status.success(),
                "git {args:?}: {}",
                String::from_utf8_lossy(&out.stderr)
            );
            String::from_utf8(out.stdout).unwrap().trim().to_string()
        };
        git(&["init", "-q"]);
        git(&["add", "experiments", "assets"]);
        git(&["commit", "-q", "-m", "first"]);
        let first = git(&["rev-parse", "HEAD"]);
        repo.write("notes.txt", "x");
        git(&["add", "notes.txt"]);
        git(&["commit", "-q", "-m", "second"]);
        let second = git(&["rev-parse", "HEAD"]);
        repo.run("a", &first, true);
        repo.run("b", &second, true);
        repo.run("c", &second, true);
        assert_eq!(repo.problems(), vec![]);
        // A commit this history does not hold (COMMIT, from another repository).
        repo.run("c", COMMIT, true);
        only(
            &repo.problems(),
            "c",
            "built from commit 3ce542543f04, which is not HEAD or one of its ancestors",
        );
        // A commit after HEAD, on a branch that did not land.
        git(&["checkout", "-q", "-b", "side"]);
        repo.write("side.txt", "x");
        git(&["add", "side.txt"]);
        git(&["commit", "-q", "-m", "side"]);
        let side = git(&["rev-parse", "HEAD"]);
        git(&["checkout", "-q", "-"]);
        repo.run("c", &side, true);
        only(&repo.problems(), "c", "which is not HEAD or one of its ancestors");
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
