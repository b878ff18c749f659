//! What every kind's report is made of: plots, images, how numbers read, CSV tables.

pub mod images;
pub mod numbers;
pub mod page;
pub mod plots;
pub mod table;
