//! The sweep: the file ([`spec`]) and its axes ([`axes`]), their expansion into runs ([`run`]),
//! the per-radius references ([`reference`]), a run measured ([`measure`]) into its record
//! ([`record`]), the kind's units on the experiment core ([`experiment`]) and what they yield
//! ([`runner`]), the timing design ([`timing`]), and the outputs ([`report`]).

pub mod axes;
pub mod experiment;
pub mod measure;
pub mod pictures;
pub mod record;
pub mod reference;
pub mod report;
pub mod run;
pub mod runner;
pub mod spec;
pub mod timing;

pub use axes::{Config, Run};
pub use experiment::{run_sweep, Sweep};
pub use record::Record;
pub use runner::Outcome;
pub use spec::Spec;
