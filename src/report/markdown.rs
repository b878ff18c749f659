//! report.md: what was run, the scene's acceleration structure, how far the ground truth is
//! from the exact answer, the verdict, what accuracy costs in time, and where the outputs are.

use super::summary::{find, Summary};
use super::verdict::Verdict;
use crate::experiment::runner::{figure_samples, Outcome};
use crate::experiment::Spec;
use crate::render::AdapterInfo;
use crate::sampling::{DiskScheme, Pattern};

/// The light radius the verdict is read at: the paper's 2 cm if swept, else the nearest.
pub fn verdict_radius(spec: &Spec) -> f64 {
    *spec
        .axes
        .light_radii
        .iter()
        .min_by(|a, b| (*a - 0.02).abs().total_cmp(&(*b - 0.02).abs()))
        .expect("non-empty")
}

fn opt(x: Option<f64>, f: impl Fn(f64) -> String) -> String {
    x.filter(|v| v.is_finite()).map_or("n/a".into(), f)
}

/// The report's markdown.
pub fn report(spec: &Spec, outcome: &Outcome, summaries: &[Summary], adapter: &AdapterInfo, seconds: f64) -> String {
    let n = figure_samples(spec);
    let radius = verdict_radius(spec);
    let mut s = format!("# {}: soft-shadow sampling sweep\n\n", spec.name);
    s += &format!(
        "Experiment `{}`, scene `{}`; {} runs ({} failed, {} groups resumed from the journal) on **{}** ({}, {}, {}) in {:.0} s.\n\n",
        spec.path.display(),
        spec.scene_path.display(),
        outcome.records.len(),
        outcome.failures,
        outcome.resumed,
        adapter.name,
        adapter.backend,
        adapter.api,
        adapter.driver,
        seconds
    );
    s += "Render plan of a run at the figure ray count with every light on (derived from the scene):\n\n```\n";
    s += &outcome.plan.to_string();
    s += "```\n\n";
    if let Some(b) = &spec.scene.bvh {
        let m: Vec<String> = spec
            .scene
            .meshes
            .iter()
            .map(|m| {
                format!(
                    "`{}`: {} triangles ({} degenerate and {} non-finite skipped)",
                    m.source, m.triangles, m.skipped.degenerate, m.skipped.non_finite
                )
            })
            .collect();
        s += &format!(
            "Meshes: {}. BVH2 (obvhs, preset `{}`): {} nodes, depth {}, built in {:.1} ms ({:.1} ms core); {:.1} GPU bytes per triangle (32-byte nodes, 48-byte full-f32 triangles).\n\n",
            m.join("; "),
            b.preset.name(),
            b.node_count(),
            b.depth,
            b.total_time.as_secs_f64() * 1e3,
            b.build_time.as_secs_f64() * 1e3,
            (b.node_count() * 32 + b.tree.primitive_indices.len() * 48) as f64 / b.world.len() as f64
        );
    }
    s += "## Ground truth against the exact answer\n\n";
    s += &format!(
        "Ground truth: jittered sampling, {} shadow rays per pixel per light, {}x{} pixels. Exact: adaptive quadrature of the visible part of each disk (tolerance 1e-10), available for disk lights over spheres and planes; mesh scenes are judged against the ground truth alone.\n\n",
        spec.ground_truth.samples, spec.measure.width, spec.measure.height
    );
    s += "| lights | light radius (m) | r_u closed form (m) | r_p closed form (m) | GT max abs error (receiver pixels) | GT RMSE (penumbra) | GT mean error (penumbra) | penumbra pixels |\n|---|---|---|---|---|---|---|---|\n";
    for r in &outcome.references {
        let o = r.on_axis.as_ref();
        s += &format!(
            "| {} | {} | {} | {} | {} | {} | {} | {} |\n",
            r.lights,
            r.light_radius,
            opt(o.map(|o| o.umbra_radius()), |x| format!("{x:.5}")),
            opt(o.map(|o| o.penumbra_radius()), |x| format!("{x:.5}")),
            opt(r.gt_max_abs_all, |x| format!("{x:.2e}")),
            opt(r.gt_vs_exact.map(|e| e.rmse), |x| format!("{x:.2e}")),
            opt(r.gt_vs_exact.map(|e| e.bias), |x| format!("{x:+.1e}")),
            r.mask.pixels.len()
        );
    }
    let verdicts: Vec<Verdict> = [Pattern::PerPixel, Pattern::Shared]
        .into_iter()
        .filter_map(|p| Verdict::new(summaries, n, radius, p))
        .collect();
    if outcome.references.iter().any(|r| r.on_axis.is_some()) {
        s += "\n## Verdict\n\nThe claim (Vassilev 2012, Fig. 2): with eq. (2)+(3) the penumbra at 16 rays is wider than with eq. (1), at the same quality.\n\n";
        if verdicts.is_empty() {
            s += "The sweep does not hold both `uniform` and `paper` at this sample count and radius, so no verdict.\n\n";
        }
        for v in &verdicts {
            s += &v.markdown();
            s += "\n";
        }
    }
    for &lights in &spec.axes.light_counts {
        s += &cost_section(summaries, n, radius, lights);
    }
    s += "\n## Outputs\n\n- `runs.csv`: one row per run; `summary.csv`: means and 95 % CIs over seeds, with the per-pixel bias/variance split.\n";
    s += "- `ground_truth.csv`: per light configuration, the reference's checks above.\n- `plots/`: width vs samples (exact drawn), RMSE vs samples, RMSE vs frame time, radial profiles, width vs light radius (on-axis scenes); RMSE vs samples and vs frame time (any scene).\n";
    s += "- `images/`: Fig. 2-style comparisons (measuring view and picture), EXR of the ground truth and exact images.\n- `manifest.toml`: commit, adapter, experiment, seeds.\n";
    s
}

/// What accuracy costs: error and frame time per scheme at the verdict's count, and for each
/// scheme the fewest rays (and time) that reach uniform sampling's RMSE at that count.
fn cost_section(summaries: &[Summary], n: u32, radius: f64, lights: u32) -> String {
    let mut s = format!(
        "\n## What accuracy costs ({lights} light(s))\n\nPer-pixel pattern, light radius {radius} m. RMSE against the ground truth over its penumbra; `lost`: share of the true penumbra shown fully lit or fully dark. `to match uniform@{n}`: the fewest swept rays at which the scheme's RMSE is at or below uniform's at {n} rays, and that configuration's median frame time.\n\n"
    );
    s += &format!("| scheme | RMSE @{n} | lost @{n} | frame ms @{n} | rays/s @{n} | to match uniform@{n} |\n|---|---|---|---|---|---|\n");
    let target = find(summaries, DiskScheme::Uniform, Pattern::PerPixel, n, radius, lights).map(|u| u.mean("rmse"));
    for scheme in DiskScheme::ALL {
        let Some(at) = find(summaries, scheme, Pattern::PerPixel, n, radius, lights) else {
            continue;
        };
        let mut rows: Vec<&Summary> = summaries
            .iter()
            .filter(|x| {
                x.run.scheme == scheme
                    && x.run.pattern == Pattern::PerPixel
                    && x.run.light_radius == radius
                    && x.run.lights == lights
            })
            .collect();
        rows.sort_by_key(|x| x.run.samples);
        let matched = target
            .and_then(|t| rows.iter().find(|x| x.mean("rmse") <= t))
            .map_or("not reached".to_string(), |x| {
                format!("{} rays, {:.2} ms", x.run.samples, x.mean("frame_ms"))
            });
        s += &format!(
            "| {} | {:.4} | {:.3} | {:.2} | {:.3e} | {} |\n",
            scheme,
            at.mean("rmse"),
            at.mean("penumbra_lost_share"),
            at.mean("frame_ms"),
            at.mean("rays_per_s"),
            matched
        );
    }
    s
}
