//! manifest.toml: where a results folder came from, one serde struct for every kind. The build
//! (commit, clean tree, compiler) is taken when the binary was built, not from the folder it runs
//! in; every input file is named with its hash, so a reader can
//! tell whether the numbers belong to the code and files in front of them; [`staleness`] does
//! that check for every committed results folder (the test command runs it).
//!
//! Files: [`build`] (the binary), [`run`] (the run and its clock), [`machine`], [`input`] (an
//! input file, its hash and whether it still matches), [`staleness`] (the check over every
//! committed results folder).

pub mod build;
pub mod input;
pub mod machine;
pub mod provenance;
pub mod run;
pub mod staleness;

pub use build::Build;
pub use input::{tidy, Input};
pub use machine::Machine;
pub use provenance::{Provenance, PROVENANCE};
pub use run::{peak_rss, utc, RunInfo};
pub use staleness::{staleness, Problem};

use super::kind::Kind;
use crate::render::AdapterInfo;
use crate::timing::Schedule;
use serde::{Deserialize, Serialize};

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

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use std::path::Path;

    /// The commit the sample manifests name.
    pub const COMMIT: &str = "3ce542543f049b80f670b351f9c8c510b3f0a48f";

    /// A manifest of experiment `name` built clean at [`COMMIT`], on a CPU, reading nothing.
    pub fn sample(name: &str) -> Manifest {
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

    #[test]
    fn a_manifest_reads_back_as_written() {
        let m = Manifest {
            build: Build::current(),
            run: RunInfo {
                started_utc: utc(std::time::SystemTime::now()),
                ..sample("ao").run
            },
            inputs: vec![Input::read(Path::new("Cargo.toml")).unwrap()],
            details: toml::Table::from_iter([("seeds".to_string(), toml::Value::from(vec![1, 2]))]),
            ..sample("ao")
        };
        let text = toml::to_string(&m).unwrap();
        assert_eq!(toml::from_str::<Manifest>(&text).unwrap(), m, "{text}");
        assert!(m.build.commit.len() >= 7, "{:?}", m.build);
    }
}
