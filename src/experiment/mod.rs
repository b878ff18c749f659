//! Experiments: one contract ([`contract`]: [`Experiment`]) that every kind implements, one
//! registry ([`kinds`]: [`load`]) that reads a file into its kind, and one [`driver`] that runs
//! any of them. The kinds: [`sweep`] (sampling schemes swept and measured against a ground
//! truth), [`fps`] (the paper's frame rates), [`ao`] (the visibility-field paper's
//! ambient-occlusion table), [`frames`] (its frame-time figures: scaling, walkthrough, dynamic
//! scenes) and [`realtime`] (few-ray pipelines accumulated and filtered). No kind imports
//! another: what two kinds share sits below them ([`shadow`], [`core`], [`tuning`]).
//!
//! The driver owns what every kind shares: the header (`kind`, `name`, `backend`, `[timing]`,
//! [`header`]) validated once, the command line's refusals, the output folder and its atomic
//! replacement ([`outputs`]), the manifest ([`manifest`]), logging and progress ([`progress`]),
//! and the timing method ([`crate::timing`]). A kind is its spec, its runner and its report. This
//! module only declares the parts and hands on the contract's names and [`load`].

pub mod ao;
pub mod args;
pub mod cli;
pub mod comparison;
pub mod contract;
pub mod core;
pub mod driver;
pub mod fps;
pub mod frames;
pub mod header;
pub mod kind;
pub mod kinds;
pub mod manifest;
pub mod outputs;
pub mod progress;
pub mod realtime;
pub mod shadow;
pub mod sweep;
pub mod tuning;

pub use contract::{Accepts, Experiment, Finished, RunContext};
pub use kinds::load;
