//! Build-time provenance for every manifest: the commit the binary was built from, whether the
//! checkout was clean (nothing changed or untracked outside `results/`, which reruns rewrite),
//! and the compiler. Taken here rather than from the folder the binary later runs in, which
//! may be another checkout. Rerun when a checked-in folder or file changes or a commit moves a
//! ref (not on `.git/index`, which a mere `git status` rewrites).

use std::process::Command;

fn git(args: &[&str]) -> Option<String> {
    let out = Command::new("git").args(args).output().ok()?;
    out.status
        .success()
        .then(|| String::from_utf8_lossy(&out.stdout).trim().to_string())
}

fn main() {
    for path in [
        "src",
        "tests",
        "benches",
        "experiments",
        "assets",
        "scripts",
        "build.rs",
        "Cargo.toml",
        "Cargo.lock",
        "README.md",
        ".git/HEAD",
        ".git/refs",
        ".git/packed-refs",
    ] {
        if std::path::Path::new(path).exists() {
            println!("cargo:rerun-if-changed={path}");
        }
    }
    let commit = git(&["rev-parse", "HEAD"]).unwrap_or_else(|| "unknown".into());
    let clean = git(&["status", "--porcelain", "--", ".", ":(exclude)results"]).is_some_and(|s| s.is_empty());
    let rustc = std::env::var("RUSTC").unwrap_or_else(|_| "rustc".into());
    let version = Command::new(rustc)
        .arg("--version")
        .output()
        .ok()
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .unwrap_or_default();
    println!("cargo:rustc-env=PENUMBRA_COMMIT={commit}");
    println!("cargo:rustc-env=PENUMBRA_CLEAN={clean}");
    println!("cargo:rustc-env=PENUMBRA_RUSTC={version}");
    println!(
        "cargo:rustc-env=PENUMBRA_PROFILE={}",
        std::env::var("PROFILE").unwrap_or_default()
    );
}
