//! The sweep: the file ([`spec`]) and its axes ([`axes`]), their expansion into runs ([`run`]),
//! the per-radius references ([`reference`]), the runs ([`runner`]) and their records
//! ([`record`]) with a resumable journal ([`journal`]), and the outputs ([`report`]). A sweep too
//! big for one machine runs as shares ([`shard`]) merged back into one result ([`merge`]).

pub mod axes;
pub mod experiment;
pub mod filter;
pub mod journal;
pub mod measure;
pub mod merge;
pub mod pictures;
pub mod record;
pub mod reference;
pub mod report;
pub mod run;
pub mod runner;
pub mod shard;
pub mod spec;
pub mod timing;

pub use axes::{Config, Run};
pub use record::Record;
pub use runner::{run_sweep, Outcome};
pub use spec::Spec;
