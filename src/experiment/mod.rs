//! Experiments: the file ([`spec`]), its expansion into runs ([`run`]), the per-radius
//! references ([`reference`]), the sweep ([`runner`]) and its resumable journal ([`journal`]).

pub mod filter;
pub mod fps;
pub mod journal;
pub mod measure;
pub mod pictures;
pub mod reference;
pub mod run;
pub mod runner;
pub mod spec;
pub mod timing;

pub use run::{Record, Run};
pub use runner::{run_sweep, Outcome};
pub use spec::Spec;
