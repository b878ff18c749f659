//! Outputs: CSV tables, plots, images and the markdown report, all written atomically.

pub mod fps;
pub mod images;
pub mod markdown;
pub mod numbers;
pub mod pictures;
pub mod plots;
pub mod summary;
pub mod thresholds;
pub mod verdict;
pub mod write;
