//! Each scheme's temporal error in the renderer: the running mean of its frames, unfiltered,
//! on the still scene, after each judged frame count. The sampling simulation beside it
//! (`tests/it/blue_noise.rs`, `temporal_error_after_k_frames`: one disk edge per pixel, the
//! scheme's points alone) predicts the order; this table is the same question asked of whole
//! frames, where the penumbra's pixels see many edges and the error is measured against the
//! exact image.

use super::report::{show, Summary};
use super::spec::{RealtimeSpec, Variant};
use std::fmt::Write as _;

/// The table: a row per (scheme, rays), a column per judged frame count, each cell the mean
/// RMSE over seeds with its 95 % half-width and its ratio to uniform's at the same rays and
/// frames (where uniform ran).
pub fn section(spec: &RealtimeSpec, summary: &[Summary]) -> String {
    let cell = |scheme: &str, rays: u32, frames: u32| {
        summary.iter().find(|s| {
            let p = &s.pipeline;
            p.on(Variant::Static)
                && p.scheme == scheme
                && p.rays == rays
                && p.frames == frames
                && p.accumulation == "mean"
                && p.filter == "none"
        })
    };
    let schemes: Vec<&str> = spec.schemes.iter().map(|s| s.name()).collect();
    if !spec.variants.contains(&Variant::Static) || cell(schemes[0], spec.rays[0], spec.frames[0]).is_none() {
        return String::new();
    }
    let mut out = String::from(
        "\n## Temporal error per scheme\n\nThe running mean of each scheme's frames, unfiltered, on the still scene: RMSE over the penumbra after each frame count (mean +- 95 % over seeds), and in brackets its ratio to uniform's at the same rays and frames. Frames drawn independently (uniform; sobol-bluenoise-t, rescrambled every frame) lose their noise as 1 / sqrt(frames); the others' frames depend on each other (sobol-bluenoise continues one sequence, bluenoise-cp walks its offsets along the R2 sequence, stbn-cp along its masks' time axis), which is what this table weighs. The paper's pattern is biased: its error cannot fall below its bias.\n\n",
    );
    let _ = writeln!(
        out,
        "| scheme x rays | {} |",
        spec.frames
            .iter()
            .map(|f| format!("{f} frame(s)"))
            .collect::<Vec<_>>()
            .join(" | ")
    );
    let _ = writeln!(out, "|{}", " --- |".repeat(spec.frames.len() + 1));
    for &rays in &spec.rays {
        for &scheme in &schemes {
            let cells: Vec<String> = spec
                .frames
                .iter()
                .map(|&f| match cell(scheme, rays, f) {
                    None => "n/a".into(),
                    Some(s) => {
                        let ratio = cell("uniform", rays, f)
                            .map(|u| format!(" ({:.2})", s.stats.rmse / u.stats.rmse))
                            .unwrap_or_default();
                        format!("{}{ratio}", show(s.stats.rmse, s.stats.rmse_ci95, 4))
                    }
                })
                .collect();
            let _ = writeln!(out, "| {scheme} x {rays} | {} |", cells.join(" | "));
        }
    }
    out
}
