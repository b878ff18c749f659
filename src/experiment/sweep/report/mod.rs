//! The sweep's outputs: CSV tables, plots, images, the markdown report with its verdict, and the
//! regression thresholds checked against them.

pub mod markdown;
pub mod pictures;
pub mod summary;
pub mod thresholds;
pub mod verdict;
pub mod write;
