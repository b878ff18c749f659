//! What every kind's report is made of: plots, images, how numbers read, and the provenance
//! every manifest records.

pub mod images;
pub mod numbers;
pub mod plots;
pub mod table;

/// The checkout's commit, suffixed `-dirty` when tracked files outside `results/` differ from
/// it (a rerun rewriting committed results is not a change to what produced them).
pub fn git_commit() -> String {
    let run = |args: &[&str]| {
        std::process::Command::new("git")
            .args(args)
            .output()
            .ok()
            .filter(|o| o.status.success())
            .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
    };
    match run(&["rev-parse", "HEAD"]) {
        Some(c) => {
            let dirty = run(&[
                "status",
                "--porcelain",
                "--untracked-files=no",
                "--",
                ".",
                ":(exclude)results",
            ])
            .is_some_and(|s| !s.is_empty());
            if dirty {
                format!("{c}-dirty")
            } else {
                c
            }
        }
        None => "unknown".into(),
    }
}

/// manifest.toml of an experiment timed on the CPU backend: the commit, the experiment file, the
/// run's seconds and the thread count.
pub fn write_cpu_manifest(
    out: &std::path::Path,
    experiment: &std::path::Path,
    seconds: f64,
    threads: usize,
) -> anyhow::Result<()> {
    let manifest = format!(
        "# Provenance of the results in this folder.\ngit_commit = {:?}\nexperiment = {:?}\nseconds = {seconds:.1}\nbackend = \"cpu\"\nthreads = {threads}\n",
        git_commit(),
        experiment.display().to_string(),
    );
    crate::files::write_atomic(&out.join("manifest.toml"), manifest.as_bytes())
}
