//! One run measured: render it, compare it with its reference, and assemble its record (the
//! timing columns stay blank until the timing phase fills them).

use super::reference::{shadow_image, Reference};
use super::run::{num, Record, Run, ADAPTER_COLUMNS, IDENTITY_COLUMNS, RUN_COLUMNS};
use super::spec::Spec;
use crate::metrics::{penumbra_coverage, ErrorMetrics, RadialProfile};
use crate::render::{Backend, Sampling, View};
use anyhow::Context;

/// Columns of a record between the run's identity and the adapter's.
const METRIC_COLUMNS: usize = RUN_COLUMNS.len() - IDENTITY_COLUMNS - ADAPTER_COLUMNS;

fn assemble(spec: &Spec, backend: &dyn Backend, run: &Run, context: &str, status: &str, error: &str) -> Record {
    let a = backend.adapter();
    let mut row = vec![
        run.key(context),
        status.to_string(),
        run.scheme.to_string(),
        run.pattern.to_string(),
        run.samples.to_string(),
        num(run.light_radius),
        run.lights.to_string(),
        run.seed.to_string(),
        spec.measure.width.to_string(),
        spec.measure.height.to_string(),
    ];
    row.extend(std::iter::repeat_n(String::new(), METRIC_COLUMNS));
    row.extend([
        a.backend.clone(),
        a.name.clone(),
        a.driver.clone(),
        a.api.clone(),
        error.to_string(),
    ]);
    Record(row)
}

/// The record of a run that failed, with its error.
pub fn failed_record(spec: &Spec, backend: &dyn Backend, run: &Run, context: &str, error: &str) -> Record {
    assemble(spec, backend, run, context, "failed", error)
}

/// Renders `run` and measures it against `reference`: its record and its shadow image.
pub fn measure_run(
    spec: &Spec,
    backend: &mut dyn Backend,
    run: &Run,
    reference: &Reference,
    context: &str,
) -> anyhow::Result<(Record, Vec<f32>)> {
    let scene = spec.scene_with(run.lights, run.light_radius, run.samples);
    let m = &spec.measure;
    let view = View {
        camera: &scene.cameras[&m.camera],
        width: m.width,
        height: m.height,
    };
    let sampling = Sampling {
        scheme: run.scheme,
        pattern: run.pattern,
        seed: run.seed,
    };
    let frame = backend.render(&scene, view, sampling).context("render")?;
    let image = shadow_image(&frame.visibility);
    let rays = frame.rays;
    let mut r = assemble(spec, backend, run, context, "ok", "");
    for (column, value) in radial_metrics(&image, reference) {
        r.set(column, num(value));
    }
    let vs_gt = ErrorMetrics::measure(&image, &reference.ground_truth, &reference.mask);
    let rmse_exact = reference
        .exact
        .as_ref()
        .map_or(f64::NAN, |e| ErrorMetrics::measure(&image, e, &reference.mask).rmse);
    let (area_ratio, lost) = penumbra_coverage(&image, &reference.mask, &reference.receivers);
    for (column, value) in [
        ("rmse", vs_gt.rmse),
        ("relmse", vs_gt.relmse),
        ("bias", vs_gt.bias),
        ("rmse_exact", rmse_exact),
        ("penumbra_area_ratio", area_ratio),
        ("penumbra_lost_share", lost),
    ] {
        r.set(column, num(value));
    }
    r.set("primary_rays", rays.primary.to_string());
    r.set("shadow_rays", rays.shadow_total().to_string());
    if let Some(b) = &scene.bvh {
        r.set("bvh_preset", b.preset.name().to_string());
        r.set("bvh_build_ms", num(b.total_time.as_secs_f64() * 1e3));
        r.set(
            "gpu_bytes_per_triangle",
            num((b.node_count() * 32 + b.tree.primitive_indices.len() * 48) as f64 / b.world.len() as f64),
        );
    }
    Ok((r, image))
}

/// The on-axis columns (closed-form radii, exact and measured extents and 10-90 widths, profile
/// bias); none when the scene has no rotationally symmetric exact shadow.
fn radial_metrics(image: &[f32], reference: &Reference) -> Vec<(&'static str, f64)> {
    let (Some(o), Some(exact)) = (&reference.on_axis, &reference.exact_profile) else {
        return vec![];
    };
    let profile = RadialProfile::new(&reference.receivers, image);
    let (inner, outer) = profile.extent();
    let (ex_in, ex_out) = exact.extent();
    let (bias, abs_bias) = profile.bias_against(exact);
    vec![
        ("exact_umbra_radius", o.umbra_radius()),
        ("exact_penumbra_radius", o.penumbra_radius()),
        ("exact_extent_width", ex_out - ex_in),
        ("exact_width_10_90", exact.width_10_90()),
        ("extent_inner", inner),
        ("extent_outer", outer),
        ("extent_width", outer - inner),
        ("width_10_90", profile.width_10_90()),
        ("profile_bias", bias),
        ("profile_abs_bias", abs_bias),
    ]
}
