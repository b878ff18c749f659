//! Any renderer's image of an exported view, scored against penumbra's exact reference with the
//! metrics a sweep row carries.
//!
//! The reference is the exact radiance of each receiver pixel (the measured plane seen through
//! the pixel): L = albedo / pi x sum over disk lights of L_e x integral of the light's visible
//! part of cos_r cos_l / d^2 dA ([`crate::reference::irradiance_fraction_estimate`]), at the
//! pixel's centre or averaged over its square as the exporting renderer's pixel filter says
//! (a 4 x 4 Gauss-Legendre product rule). Each image is read as radiance and divided by the
//! exact unoccluded radiance of its pixel, which makes it a visible fraction in [0, 1] (up to
//! noise) on the scale every penumbra metric takes, and turns a convention that does not match
//! (a light's radiance, a factor of pi) into a lit level away from 1 instead of a silent offset.
//!
//! Per image: RMSE over every judged pixel, RMSE / relMSE / bias over the exact penumbra
//! ([`PenumbraMask`]), the mean over the exact lit region and umbra, the 10-90 % width and the
//! visible extent across the exact edge ([`EdgeProfile`], [`Annuli`]) in pixels, and FLIP (LDR,
//! 8-bit grey, [`PIXELS_PER_DEGREE`], averaged over the judged pixels). Images named `NAME-seedK.exr` are seeds of `NAME`: per
//! group, means with 95 % intervals and the squared bias / variance split ([`BiasVariance`]).

use super::view::{ExportedView, PixelFilter};
use crate::files::Refused;
use crate::metrics::edge::EdgeProfile;
use crate::metrics::error::{ErrorMetrics, PenumbraMask, EPS};
use crate::metrics::extent::Annuli;
use crate::metrics::flip::{flip_map, PIXELS_PER_DEGREE};
use crate::metrics::seeds::BiasVariance;
use crate::output::images::grey;
use crate::reference::{irradiance_fraction_estimate, occluders};
use crate::render::cpu::closest_hit;
use crate::render::NO_RECEIVER;
use crate::scene::{Light, Scene};
use rayon::prelude::*;
use std::f64::consts::PI;
use std::path::Path;

/// The exact reference of one view under one pixel filter.
#[derive(Clone, Debug)]
pub struct Reference {
    /// Width, pixels.
    pub width: u32,
    /// Height, pixels.
    pub height: u32,
    /// Per pixel, the exact radiance without occluders (W m^-2 sr^-1); NaN where not judged.
    pub free: Vec<f64>,
    /// Per pixel, the exact radiance as a fraction of `free`; [`NO_RECEIVER`] where not judged:
    /// pixels where any camera ray the filter traces (under a box filter, its square's corners
    /// and edge midpoints too) meets something other than the measured plane, or that no light
    /// reaches.
    pub fraction: Vec<f32>,
    /// Point evaluations whose quadrature reached its depth limit (reported, never hidden).
    pub depth_limited: u64,
}

/// Where a renderer starts its shadow rays relative to the receiver point: penumbra starts them
/// on the surface ([`crate::render::shading::Receiver::origin`]); most renderers lift them
/// along the normal to escape self-intersection, which moves the shadow they compute (a
/// receiver raised towards the occluder sees a smaller, lighter penumbra). Judged against the
/// reference of the renderer's own lift, a renderer's remaining disagreement is its error alone.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Lift {
    /// Shadow rays from the surface point.
    None,
    /// A fixed distance along the normal, metres.
    Metres(f64),
    /// Mitsuba 3's `offset_p`: (1 + max_i |p_i|) x RayEpsilon along the normal, RayEpsilon =
    /// 1500 x 2^-24 for its single-precision variants.
    Mitsuba3,
}

impl Lift {
    /// The distance shadow rays from `p` start above it.
    pub fn at(self, p: glam::DVec3) -> f64 {
        match self {
            Lift::None => 0.0,
            Lift::Metres(m) => m,
            Lift::Mitsuba3 => (1.0 + p.abs().max_element()) * 1500.0 * f64::from(f32::EPSILON) * 0.5,
        }
    }

    /// As written in reports.
    pub fn describe(self) -> String {
        match self {
            Lift::None => "none".into(),
            Lift::Metres(m) => format!("{m} m"),
            Lift::Mitsuba3 => "mitsuba3".into(),
        }
    }
}

impl std::str::FromStr for Lift {
    type Err = String;
    fn from_str(s: &str) -> Result<Lift, String> {
        match s {
            "none" => Ok(Lift::None),
            "mitsuba3" => Ok(Lift::Mitsuba3),
            _ => match s.parse::<f64>() {
                Ok(m) if m.is_finite() && m >= 0.0 => Ok(Lift::Metres(m)),
                _ => Err(format!("`{s}`: expected none, mitsuba3 or a distance in metres (>= 0)")),
            },
        }
    }
}

/// Points of a pixel's square (offsets from its top-left corner) and their weights.
fn pixel_points(filter: PixelFilter) -> Vec<(f64, f64, f64)> {
    match filter {
        PixelFilter::Centre => vec![(0.5, 0.5, 1.0)],
        PixelFilter::Box => {
            // 4-point Gauss-Legendre on [0, 1].
            const X: [f64; 4] = [
                0.069_431_844_202_973_7,
                0.330_009_478_207_571_9,
                0.669_990_521_792_428_1,
                0.930_568_155_797_026_3,
            ];
            const W: [f64; 4] = [
                0.173_927_422_568_726_9,
                0.326_072_577_431_273_1,
                0.326_072_577_431_273_1,
                0.173_927_422_568_726_9,
            ];
            let mut p = Vec::with_capacity(16);
            for (x, wx) in X.iter().zip(W) {
                for (y, wy) in X.iter().zip(W) {
                    p.push((*x, *y, wx * wy));
                }
            }
            p
        }
    }
}

impl Reference {
    /// The exact reference of `view` of `scene`, or why there is none (triangles, for which no
    /// exact answer exists; point lights; a missing camera or plane).
    pub fn exact(scene: &Scene, view: &ExportedView, filter: PixelFilter, lift: Lift) -> anyhow::Result<Reference> {
        let name = view.scene.display();
        let (spheres, planes) = occluders(scene).ok_or_else(|| {
            Refused(format!(
                "{name}: holds triangles, for which there is no exact reference; judge scenes of spheres and planes"
            ))
        })?;
        super::refuse_unmatched_effects(scene, &view.scene)?;
        // One disk light: with several, a pixel one light wholly lights and another wholly
        // misses has a partial fraction, and the lit level and widths lose their meaning.
        if scene.lights.len() != 1 || matches!(scene.lights[0], Light::Point { .. }) {
            return Err(Refused(format!(
                "{name}: holds {} light(s){}; the judge measures the soft shadow of one disk light",
                scene.lights.len(),
                if scene.lights.iter().any(|l| matches!(l, Light::Point { .. })) {
                    ", a point light among them"
                } else {
                    ""
                }
            ))
            .into());
        }
        let camera = scene
            .cameras
            .get(&view.camera)
            .ok_or_else(|| Refused(format!("{name}: no camera `{}` (the view's `camera`)", view.camera)))?;
        let (plane_id, plane) = scene.plane(view.plane).ok_or_else(|| {
            Refused(format!(
                "{name}: no plane {} (the view's `plane`, counting planes from 0)",
                view.plane
            ))
        })?;
        let points = pixel_points(filter);
        let (w, h) = (view.width, view.height);
        let pixels: Vec<(f64, f64, u64)> = (0..w * h)
            .into_par_iter()
            .map(|i| {
                let (x, y) = ((i % w) as f64, (i / w) as f64);
                let (mut free, mut lit, mut limited) = (0.0, 0.0, 0u64);
                // Under the box filter a renderer's samples reach the square's edges: a pixel is
                // judged only where its corners and edge midpoints see the plane too.
                if filter == PixelFilter::Box {
                    let edges = [0.0, 0.5, 1.0];
                    for dx in edges {
                        for dy in edges {
                            let ray = camera.ray_at(x + dx, y + dy, w, h);
                            if closest_hit(scene, ray.origin, ray.direction).is_none_or(|r| r.object != plane_id) {
                                return (f64::NAN, f64::NAN, limited);
                            }
                        }
                    }
                }
                for &(dx, dy, weight) in &points {
                    let ray = camera.ray_at(x + dx, y + dy, w, h);
                    let Some(hit) = closest_hit(scene, ray.origin, ray.direction).filter(|r| r.object == plane_id)
                    else {
                        return (f64::NAN, f64::NAN, limited);
                    };
                    for light in &scene.lights {
                        let Light::Disk(d) = light else { continue };
                        // The renderer weighs each light sample at the surface point and tests
                        // its visibility from the lifted origin: the unoccluded integral is the
                        // point's, the visible fraction the origin's.
                        let origin = hit.p + hit.n * lift.at(hit.p);
                        let (f, mut whole) = irradiance_fraction_estimate(origin, hit.n, d, &spheres, &planes);
                        if origin != hit.p {
                            whole = irradiance_fraction_estimate(hit.p, hit.n, d, &[], &[]).1;
                        }
                        let l_free = plane.albedo / PI * super::export::disk_radiance(d.power, d.radius) * whole;
                        free += weight * l_free;
                        lit += weight * l_free * f.value;
                        limited += (f.depth_limited > 0) as u64;
                    }
                }
                (free, lit, limited)
            })
            .collect();
        let judged = |free: f64| free.is_finite() && free > 0.0;
        if !pixels.iter().any(|p| judged(p.0)) {
            return Err(Refused(format!(
                "{name}: no pixel of camera `{}` sees plane {} lit by the light; nothing to judge",
                view.camera, view.plane
            ))
            .into());
        }
        Ok(Reference {
            width: w,
            height: h,
            free: pixels
                .iter()
                .map(|p| if judged(p.0) { p.0 } else { f64::NAN })
                .collect(),
            fraction: pixels
                .iter()
                .map(|p| if judged(p.0) { (p.1 / p.0) as f32 } else { NO_RECEIVER })
                .collect(),
            depth_limited: pixels.iter().map(|p| p.2).sum(),
        })
    }

    /// Pixels judged.
    pub fn judged(&self) -> Vec<usize> {
        (0..self.fraction.len())
            .filter(|&i| self.fraction[i] != NO_RECEIVER)
            .collect()
    }

    /// A radiance image as a fraction of the exact unoccluded radiance, [`NO_RECEIVER`] where
    /// not judged; a non-finite judged pixel is refused, naming it.
    pub fn fraction_of(&self, radiance: &[f32], image: &str) -> anyhow::Result<Vec<f32>> {
        let w = self.width as usize;
        radiance
            .iter()
            .zip(&self.free)
            .enumerate()
            .map(|(i, (&l, &free))| {
                if free.is_nan() {
                    Ok(NO_RECEIVER)
                } else if !l.is_finite() {
                    Err(Refused(format!(
                        "{image}: pixel ({}, {}) is {l}; a judged pixel must be finite",
                        i % w,
                        i / w
                    ))
                    .into())
                } else {
                    Ok((l as f64 / free) as f32)
                }
            })
            .collect()
    }
}

/// One image's scores.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Judgement {
    /// The image's file name.
    pub image: String,
    /// Its group (the name before `-seedK`).
    pub group: String,
    /// The pixel filter its reference was taken with.
    pub pixel_filter: &'static str,
    /// The shadow-ray origin lift its reference was taken with ([`Lift`]).
    pub shadow_origin_lift: String,
    /// Pixels judged.
    pub pixels: usize,
    /// Pixels of the exact penumbra.
    pub penumbra_pixels: usize,
    /// RMSE of the visible fraction over every judged pixel.
    pub rmse: f64,
    /// RMSE over the exact penumbra.
    pub penumbra_rmse: f64,
    /// relMSE over the exact penumbra.
    pub penumbra_relmse: f64,
    /// Mean signed error over the exact penumbra.
    pub penumbra_bias: f64,
    /// Mean over the exact fully lit pixels (1 for a renderer whose radiance matches).
    pub lit_mean: f64,
    /// Mean over the exact umbra (0 for one that matches).
    pub umbra_mean: f64,
    /// 10-90 % width across the exact edge, pixels.
    pub width_10_90_px: f64,
    /// The exact image's.
    pub exact_width_10_90_px: f64,
    /// Visible extent across the exact edge, pixels.
    pub extent_px: f64,
    /// The exact image's.
    pub exact_extent_px: f64,
    /// FLIP against the exact image: LDR, 8-bit grey of the visible fraction, at
    /// [`PIXELS_PER_DEGREE`] pixels per degree; the whole image's map averaged over the judged
    /// pixels.
    pub flip_ldr_67ppd: f64,
}

/// The group of an image file: its stem without a trailing `-seedK`.
pub fn group_of(stem: &str) -> String {
    match stem.rsplit_once("-seed") {
        Some((g, k)) if !g.is_empty() && !k.is_empty() && k.bytes().all(|b| b.is_ascii_digit()) => g.to_string(),
        _ => stem.to_string(),
    }
}

/// Scores one image (a visible fraction, [`Reference::fraction_of`]) against the reference.
pub fn judge(
    reference: &Reference,
    filter: PixelFilter,
    lift: Lift,
    image: &str,
    fraction: &[f32],
) -> anyhow::Result<Judgement> {
    let (w, h) = (reference.width, reference.height);
    let exact = &reference.fraction;
    let all = PenumbraMask {
        pixels: reference.judged(),
    };
    let penumbra = PenumbraMask {
        pixels: all
            .pixels
            .iter()
            .copied()
            .filter(|&i| (exact[i] as f64) > EPS && (exact[i] as f64) < 1.0 - EPS)
            .collect(),
    };
    let mean_where = |keep: &dyn Fn(f64) -> bool| {
        let v: Vec<f64> = all
            .pixels
            .iter()
            .filter(|&&i| keep(exact[i] as f64))
            .map(|&i| fraction[i] as f64)
            .collect();
        v.iter().sum::<f64>() / v.len() as f64
    };
    let reach = 0.5 * w.max(h) as f64;
    let edge = EdgeProfile::new(exact, w, h, reach);
    // Values within EPS of 0 or 1 count as umbra or lit: a renderer's radiance divided by the
    // exact unoccluded radiance is 1 only to its rounding. Distances are shifted to start past
    // one annulus width, so a crossing at the patch's first annulus reads as clipped (NaN).
    let extent = |values: &[f32]| {
        let snap = |v: f64| {
            if v <= EPS {
                0.0
            } else if v >= 1.0 - EPS {
                1.0
            } else {
                v
            }
        };
        let shifted = edge
            .pixels
            .iter()
            .map(|&(i, d)| (d + reach + 1.0, snap(values[i] as f64)))
            .collect();
        let (inner, outer) = Annuli::new(shifted, 1.0).extent();
        outer - inner
    };
    let e = ErrorMetrics::measure(fraction, exact, &penumbra);
    let stem = Path::new(image)
        .file_stem()
        .map_or(image.to_string(), |s| s.to_string_lossy().into_owned());
    Ok(Judgement {
        image: image.to_string(),
        group: group_of(&stem),
        pixel_filter: filter.name(),
        shadow_origin_lift: lift.describe(),
        pixels: all.pixels.len(),
        penumbra_pixels: penumbra.pixels.len(),
        rmse: ErrorMetrics::measure(fraction, exact, &all).rmse,
        penumbra_rmse: e.rmse,
        penumbra_relmse: e.relmse,
        penumbra_bias: e.bias,
        lit_mean: mean_where(&|v| v >= 1.0 - EPS),
        umbra_mean: mean_where(&|v| v <= EPS),
        width_10_90_px: edge.width_10_90(fraction),
        exact_width_10_90_px: edge.width_10_90(exact),
        extent_px: extent(fraction),
        exact_extent_px: extent(exact),
        flip_ldr_67ppd: {
            let map = flip_map(
                &grey(exact, w, h).data,
                &grey(fraction, w, h).data,
                w,
                h,
                PIXELS_PER_DEGREE,
            )?;
            all.pixels.iter().map(|&i| map[i] as f64).sum::<f64>() / all.pixels.len() as f64
        },
    })
}

/// The mean signed error of a group's images across the exact edge: per bin of signed distance
/// to the exact contour (one pixel wide, negative on the umbra side), (distance in pixels,
/// mean over the group's images of the bin's mean of image - exact). Where a renderer's
/// penumbra is shifted or widened, this is its shape.
pub fn error_profile(reference: &Reference, fractions: &[&[f32]]) -> Vec<(f64, f64)> {
    let (w, h) = (reference.width, reference.height);
    let edge = EdgeProfile::new(&reference.fraction, w, h, 0.5 * w.max(h) as f64);
    let exact = edge.profile(&reference.fraction);
    let mut sum = vec![0.0; exact.len()];
    for f in fractions {
        for (s, (got, want)) in sum.iter_mut().zip(edge.profile(f).iter().zip(&exact)) {
            *s += got.1 - want.1;
        }
    }
    exact
        .iter()
        .zip(sum)
        .map(|(e, s)| (e.0, s / fractions.len() as f64))
        .collect()
}

/// The seeds of one group, summarised.
#[derive(Clone, Debug, serde::Serialize)]
pub struct GroupSummary {
    /// The group's name.
    pub group: String,
    /// The pixel filter of its reference.
    pub pixel_filter: &'static str,
    /// The shadow-ray lift of its reference.
    pub shadow_origin_lift: String,
    /// Its images (seeds).
    pub seeds: usize,
    /// Mean penumbra RMSE and the half-width of its 95 % interval over seeds.
    pub penumbra_rmse: f64,
    /// Half-width of its 95 % interval.
    pub penumbra_rmse_ci95: f64,
    /// Mean signed error over the exact penumbra (a shifted or lifted shadow shows here first).
    pub penumbra_bias: f64,
    /// Half-width of its 95 % interval over seeds.
    pub penumbra_bias_ci95: f64,
    /// Mean 10-90 % width, pixels.
    pub width_10_90_px: f64,
    /// Half-width of its 95 % interval.
    pub width_10_90_px_ci95: f64,
    /// The exact width, pixels.
    pub exact_width_10_90_px: f64,
    /// Mean lit level.
    pub lit_mean: f64,
    /// Mean FLIP (LDR, 67.02 ppd).
    pub flip_ldr_67ppd: f64,
    /// Squared bias over the penumbra (unbiased estimate; NaN under 2 seeds).
    pub bias2: f64,
    /// Half-width of its 95 % interval (NaN under 3 seeds).
    pub bias2_ci95: f64,
    /// Per-pixel variance over seeds.
    pub variance: f64,
}

/// Summarises the judgements of each group (in the order groups first appear), splitting the
/// error of its seeds' `fractions` into squared bias and variance.
pub fn summarise(reference: &Reference, judged: &[(Judgement, Vec<f32>)]) -> Vec<GroupSummary> {
    let mut groups: Vec<&str> = Vec::new();
    for (j, _) in judged {
        if !groups.contains(&j.group.as_str()) {
            groups.push(&j.group);
        }
    }
    let exact = &reference.fraction;
    groups
        .into_iter()
        .map(|g| {
            let members: Vec<&(Judgement, Vec<f32>)> = judged.iter().filter(|(j, _)| j.group == g).collect();
            let first = &members[0].0;
            let mask = PenumbraMask {
                pixels: reference
                    .judged()
                    .into_iter()
                    .filter(|&i| (exact[i] as f64) > EPS && (exact[i] as f64) < 1.0 - EPS)
                    .collect(),
            };
            let images: Vec<Vec<f32>> = members.iter().map(|(_, f)| f.clone()).collect();
            let bv = BiasVariance::measure(&images, exact, &mask);
            let ci = |f: &dyn Fn(&Judgement) -> f64| {
                crate::metrics::stats::mean_ci(&members.iter().map(|(j, _)| f(j)).collect::<Vec<_>>())
            };
            let (rmse, width, bias) = (
                ci(&|j| j.penumbra_rmse),
                ci(&|j| j.width_10_90_px),
                ci(&|j| j.penumbra_bias),
            );
            GroupSummary {
                group: g.to_string(),
                pixel_filter: first.pixel_filter,
                shadow_origin_lift: first.shadow_origin_lift.clone(),
                seeds: members.len(),
                penumbra_rmse: rmse.mean,
                penumbra_rmse_ci95: rmse.ci95,
                penumbra_bias: bias.mean,
                penumbra_bias_ci95: bias.ci95,
                width_10_90_px: width.mean,
                width_10_90_px_ci95: width.ci95,
                exact_width_10_90_px: first.exact_width_10_90_px,
                lit_mean: ci(&|j| j.lit_mean).mean,
                flip_ldr_67ppd: ci(&|j| j.flip_ldr_67ppd).mean,
                bias2: bv.bias2,
                bias2_ci95: bv.bias2_ci,
                variance: bv.variance,
            }
        })
        .collect()
}

/// A radiance image: channel `Y`, or the Rec. 709 luminance of `R`, `G` and `B`, of an EXR
/// whose size must be the view's; refused with its path (not an EXR, another size, other
/// channels).
pub fn read_radiance(path: &Path, view: &ExportedView) -> anyhow::Result<Vec<f32>> {
    let img = crate::output::page::rebuild::read_exr_layer(path)?;
    let size = img.layer_data.size;
    if (size.width() as u32, size.height() as u32) != (view.width, view.height) {
        return Err(Refused(format!(
            "{}: a {} x {} image; the exported view is {} x {}",
            path.display(),
            size.width(),
            size.height(),
            view.width,
            view.height
        ))
        .into());
    }
    let channels = &img.layer_data.channel_data.list;
    let find = |name: &str| {
        channels
            .iter()
            .find(|c| c.name.to_string() == name)
            .map(|c| c.sample_data.values_as_f32().collect::<Vec<f32>>())
    };
    if let Some(y) = find("Y") {
        return Ok(y);
    }
    match (find("R"), find("G"), find("B")) {
        (Some(r), Some(g), Some(b)) => Ok(r
            .iter()
            .zip(&g)
            .zip(&b)
            .map(|((r, g), b)| 0.2126 * r + 0.7152 * g + 0.0722 * b)
            .collect()),
        _ => Err(Refused(format!(
            "{}: channels {}; the judge reads Y, or R, G and B",
            path.display(),
            channels
                .iter()
                .map(|c| c.name.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ))
        .into()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Shape;
    use glam::DVec3;

    fn sphere_scene() -> Scene {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("experiments/scenes/sphere.toml");
        Scene::load(&path).unwrap()
    }

    fn strip(pixel: PixelFilter) -> ExportedView {
        ExportedView {
            scene: "sphere.toml".into(),
            scene_fnv1a: String::new(),
            camera: "measure".into(),
            width: 32,
            height: 4,
            plane: 0,
            pixel,
            lift: "none".into(),
        }
    }

    #[test]
    fn seeds_group_by_the_name_before_their_number() {
        assert_eq!(group_of("mitsuba-spp64-seed3"), "mitsuba-spp64");
        assert_eq!(group_of("a-seed12"), "a");
        assert_eq!(group_of("a-seed"), "a-seed");
        assert_eq!(group_of("a-seedx"), "a-seedx");
        assert_eq!(group_of("-seed1"), "-seed1");
    }

    /// Lifting the shadow rays' origin by d is the same geometry as moving every occluder and
    /// light down by d under a fixed receiver: the lifted reference equals the moved scene's
    /// plain one (an independent path through the scene's own translation), pixel for pixel.
    #[test]
    fn a_lift_is_the_scene_moved_down_under_the_receiver() {
        let scene = sphere_scene();
        let lift = 2e-3;
        let mut moved = scene.clone();
        for s in &mut moved.shapes {
            if let Shape::Sphere(s) = s {
                s.center.z -= lift;
            }
        }
        for l in &mut moved.lights {
            if let Light::Disk(d) = l {
                d.center.z -= lift;
            }
        }
        let view = strip(PixelFilter::Centre);
        let lifted = Reference::exact(&scene, &view, PixelFilter::Centre, Lift::Metres(lift)).unwrap();
        let plain = Reference::exact(&moved, &view, PixelFilter::Centre, Lift::None).unwrap();
        let unlifted = Reference::exact(&scene, &view, PixelFilter::Centre, Lift::None).unwrap();
        let mut moved_by_lift = 0;
        for i in 0..lifted.fraction.len() {
            assert!((lifted.fraction[i] - plain.fraction[i]).abs() <= 1e-6, "pixel {i}");
            moved_by_lift += ((lifted.fraction[i] - unlifted.fraction[i]).abs() > 1e-3) as u32;
        }
        assert!(moved_by_lift >= 8, "the lift changed {moved_by_lift} pixels");
        // Mitsuba 3.9.1's own spawn_ray_to from (0.34, 0, 0) with normal +z starts at z =
        // 1.19805e-4 (printed in f32 by its Python binding).
        assert!((Lift::Mitsuba3.at(DVec3::new(0.34, 0.0, 0.0)) - 1.19805e-4).abs() < 1e-9);
    }

    /// The box filter's 4 x 4 Gauss-Legendre rule against a 16 x 16 midpoint mean over each
    /// pixel of a coarse strip (2.5 mm pixels, the penumbra about six wide: curvature at its
    /// largest against the pixel): agreement within 5e-4, measured 1.4e-4 (the kinks at the umbra's and the lit
    /// side's edges are what the rules resolve differently).
    #[test]
    fn the_box_rule_averages_the_pixel() {
        let scene = sphere_scene();
        let view = strip(PixelFilter::Box);
        let boxed = Reference::exact(&scene, &view, PixelFilter::Box, Lift::None).unwrap();
        let camera = &scene.cameras["measure"];
        let (spheres, planes) = occluders(&scene).unwrap();
        let Light::Disk(d) = &scene.lights[0] else { panic!() };
        let n = 16;
        let mut worst: f64 = 0.0;
        for y in 0..view.height {
            for x in 0..view.width {
                let (mut free, mut lit) = (0.0, 0.0);
                for i in 0..n {
                    for j in 0..n {
                        let (sx, sy) = ((i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64);
                        let ray = camera.ray_at(x as f64 + sx, y as f64 + sy, view.width, view.height);
                        let hit = closest_hit(&scene, ray.origin, ray.direction).unwrap();
                        let (f, whole) = irradiance_fraction_estimate(hit.p, hit.n, d, &spheres, &planes);
                        free += whole;
                        lit += whole * f.value;
                    }
                }
                let i = (y * view.width + x) as usize;
                worst = worst.max((boxed.fraction[i] as f64 - lit / free).abs());
            }
        }
        assert!(worst < 5e-4, "{worst}");
    }
}
