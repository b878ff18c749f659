//! One run measured: render it, compare it with its reference, and assemble its record (its frame
//! time stays unmeasured until the timing phase fills it in).

use super::record::{
    Device, FrameTime, Metrics, Radial, Record, SpectrumColumns, Status, StructureColumns, WorkCounts,
};
use super::reference::{shadow_image, Reference};
use super::run::Run;
use super::spec::Spec;
use crate::accel::settings::ParameterColumns;
use crate::metrics::spectrum::{blurred_rmse, error_spectrum};
use crate::metrics::{penumbra_coverage, ErrorMetrics, RadialProfile};
use crate::render::{Backend, Sampling, View};
use anyhow::Context;

/// The record of `run` with nothing measured yet.
fn unmeasured(spec: &Spec, backend: &dyn Backend, run: &Run, context: &str, status: Status, error: &str) -> Record {
    Record {
        run_key: run.key(context),
        status,
        run: run.clone(),
        radial: Radial::unmeasured(spec.measure.width, spec.measure.height),
        metrics: Metrics::NONE,
        spectrum: SpectrumColumns::NONE,
        rays: WorkCounts::default(),
        time: FrameTime::UNTIMED,
        structure: StructureColumns::NONE,
        parameters: ParameterColumns::none(),
        device: Device::of(backend.adapter()),
        image_fnv1a: String::new(),
        error: error.to_string(),
    }
}

/// The record of a run that failed, with its error.
pub fn failed_record(spec: &Spec, backend: &dyn Backend, run: &Run, context: &str, error: &str) -> Record {
    unmeasured(spec, backend, run, context, Status::Failed, error)
}

/// Renders `run` and measures it against `reference`: its record and its shadow image.
pub fn measure_run(
    spec: &Spec,
    backend: &mut dyn Backend,
    run: &Run,
    reference: &Reference,
    context: &str,
) -> anyhow::Result<(Record, Vec<f32>)> {
    let scene = spec.scene_with(run.lights, run.light_radius, run.samples, &run.accelerator);
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
        frame: 0,
    };
    let frame = backend.render(&scene, view, sampling).context("render")?;
    let image = shadow_image(&frame.visibility);
    let rays = frame.rays;
    let mut r = unmeasured(spec, backend, run, context, Status::Ok, "");
    let bits: Vec<u8> = image.iter().flat_map(|v| v.to_bits().to_le_bytes()).collect();
    r.image_fnv1a = format!("{:016x}", crate::fingerprint::fnv1a(&bits));
    measure_radial(&image, reference, &mut r);
    measure_spectrum(&image, reference, &mut r);
    let vs_gt = ErrorMetrics::measure(&image, &reference.ground_truth, &reference.mask);
    let rmse_exact = reference
        .exact
        .as_ref()
        .map_or(f64::NAN, |e| ErrorMetrics::measure(&image, e, &reference.mask).rmse);
    let (area_ratio, lost) = penumbra_coverage(&image, &reference.mask, &reference.receivers);
    let m = &mut r.metrics;
    (m.rmse, m.relmse, m.bias, m.rmse_exact) = (vs_gt.rmse, vs_gt.relmse, vs_gt.bias, rmse_exact);
    (m.penumbra_area_ratio, m.penumbra_lost_share) = (area_ratio, lost);
    let work = frame.work();
    r.rays = WorkCounts {
        primary_rays: Some(rays.primary),
        shadow_rays: Some(rays.shadow_total()),
        queries: work.map(|w| w.queries),
        nodes_visited: work.map(|w| w.nodes),
        primitive_tests: work.map(|w| w.primitives),
    };
    if let Some(a) = &scene.accel {
        let stats = a.stats();
        r.parameters = ParameterColumns::of(&scene.accel_settings);
        r.structure = StructureColumns {
            build_s: stats.build_time.as_secs_f64(),
            gpu_bytes_per_triangle: stats.gpu_bytes as f64 / stats.triangles as f64,
        };
    }
    Ok((r, image))
}

/// The on-axis columns (closed-form radii, exact and measured extents and 10-90 widths, profile
/// bias); left unmeasured when the scene has no rotationally symmetric exact shadow.
fn measure_radial(image: &[f32], reference: &Reference, r: &mut Record) {
    let (Some(o), Some(exact)) = (&reference.on_axis, &reference.exact_profile) else {
        return;
    };
    let profile = RadialProfile::new(&reference.receivers, image);
    let (inner, outer) = profile.extent();
    let (ex_in, ex_out) = exact.extent();
    let (bias, abs_bias) = profile.bias_against(exact);
    r.radial = Radial {
        exact_umbra_radius: o.umbra_radius(),
        exact_penumbra_radius: o.penumbra_radius(),
        exact_extent_width: ex_out - ex_in,
        exact_width_10_90: exact.width_10_90(),
        extent_inner: inner,
        extent_outer: outer,
        ..r.radial
    };
    let m = &mut r.metrics;
    (m.extent_width, m.width_10_90) = (outer - inner, profile.width_10_90());
    (m.profile_bias, m.profile_abs_bias) = (bias, abs_bias);
}

/// Where the error goes: the radial spectrum of the signed error against the ground truth over
/// the receiver pixels, its low-frequency share, and the error a small blur leaves over the
/// penumbra ([`crate::metrics::spectrum`]).
fn measure_spectrum(image: &[f32], reference: &Reference, r: &mut Record) {
    let (w, h) = (r.radial.width as usize, r.radial.height as usize);
    let mut receiver = vec![false; w * h];
    let mut error = vec![0.0; w * h];
    for &(i, _) in &reference.receivers.pixels {
        receiver[i] = true;
        error[i] = image[i] as f64 - reference.ground_truth[i] as f64;
    }
    let spectrum = error_spectrum(&error, &receiver, w, h);
    r.spectrum = SpectrumColumns::of(&spectrum.radial);
    r.metrics.lowfreq_share = spectrum.low_share;
    r.metrics.rmse_blurred = blurred_rmse(&error, &receiver, &reference.mask.pixels, w, h);
}
