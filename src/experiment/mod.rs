//! Experiments, one module per kind: [`sweep`] (sampling schemes swept and measured against a
//! ground truth) and [`fps`] (the paper's frame rates). Each kind has its spec, runner and report.

pub mod fps;
pub mod sweep;
