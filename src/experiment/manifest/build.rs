//! The binary that made a results folder, as it was built.

use crate::fingerprint::fnv1a;
use serde::{Deserialize, Serialize};

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
            cargo_lock_fnv1a: format!("{:016x}", fnv1a(include_bytes!("../../../Cargo.lock"))),
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
