//! The sweep: the file ([`spec`]), its expansion into runs ([`run`]), the per-radius references
//! ([`reference`]), the runs ([`runner`]) with their resumable journal ([`journal`]), and the
//! outputs ([`report`]).

pub mod axes;
pub mod filter;
pub mod journal;
pub mod measure;
pub mod pictures;
pub mod reference;
pub mod report;
pub mod run;
pub mod runner;
pub mod spec;
pub mod timing;

pub use run::{Record, Run};
pub use runner::{run_sweep, Outcome};
pub use spec::Spec;
