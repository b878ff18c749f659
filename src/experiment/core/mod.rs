//! The experiment core: what every kind gets without writing it. Its axes reach `--filter`
//! ([`filter`]) and the dry run; its units of work are dealt to shards by cost ([`shard`]),
//! journaled as they finish so a killed run resumes, and put back together by `--merge`
//! ([`merge`]), which refuses a missing, duplicated or foreign shard with the command that
//! reruns it. A kind is a [`declaration::Declaration`]: axes, units, a measure for one unit, and a
//! report; [`declared::Declared`] makes it an [`super::contract::Experiment`]. Nothing here knows a kind.

pub mod declaration;
pub mod declared;
pub mod filter;
pub mod journal;
pub mod merge;
pub mod shard;

pub use declaration::{Declaration, Unit};
pub use declared::{measure_whole, Declared};
pub use filter::{Axis, AxisKey, Filter};
pub use journal::Measured;
pub use merge::MergeRefused;
pub use shard::{Cost, Shard};
