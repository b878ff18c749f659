//! Real-time soft shadows (`kind = "realtime"`): the soft-shadow paper's question asked as a
//! real-time renderer asks it today. A pipeline casts 1-16 shadow rays per pixel per frame,
//! draws frame f's samples from the scheme's sequence at f, accumulates frames (running mean or
//! exponential moving average), reconstructs with a filter ([`crate::render::denoise`]), and is
//! judged against the exact image of the current frame on error, perceived error, the
//! penumbra's width and extent, frame-to-frame stability and, with a moving occluder, lag.
//!
//! Declared on the experiment core: axes variant x scheme x rays x frames x accumulation x
//! filter x seed; a unit is one (variant, scheme, rays), every seed rendered through every frame
//! (the frame counts are checkpoints of one sequence), plus one timing unit that times every
//! render and filter in the same interleaved rounds, so frame-time budgets compare like with
//! like.

pub mod pipeline;
pub mod reference;
pub mod report;
pub mod runner;
pub mod spec;
pub mod temporal;

pub use pipeline::Pipeline;
pub use spec::{RealtimeSpec, Variant};

use crate::experiment::contract::RunContext;
use crate::experiment::core::filter::{keep_at, Axis};
use crate::experiment::core::{Cost, Declaration, Unit};
use crate::experiment::header::Header;
use crate::experiment::progress::Progress;
use crate::render::Backend;
use runner::Outcome;
use std::path::PathBuf;

/// A real-time experiment with the references its units share in one process.
#[derive(Clone, Debug)]
pub struct Realtime {
    /// The validated file.
    pub spec: RealtimeSpec,
    refs: reference::References,
}

impl Realtime {
    /// Wraps a validated file.
    pub fn new(spec: RealtimeSpec) -> Realtime {
        Realtime {
            spec,
            refs: Default::default(),
        }
    }
}

crate::axis_keys! {
    /// The real-time pipelines' axes.
    pub enum RealtimeAxis {
        /// Still or moving scene.
        Variant => "variant",
        /// Disk sampling scheme.
        Scheme => "scheme",
        /// Shadow rays per pixel per frame.
        Rays => "rays",
        /// Frames accumulated.
        Frames => "frames",
        /// Running mean or moving average.
        Accumulation => "accumulation",
        /// Reconstruction filter.
        Filter => "filter",
        /// Seed of the sequence.
        Seed => "seed",
    }
}

impl Declaration for Realtime {
    type Outcome = Outcome;

    fn header(&self) -> &Header {
        &self.spec.header
    }

    fn locate(&self, e: anyhow::Error) -> anyhow::Error {
        self.spec.places.locate(e)
    }

    fn gpu(&self) -> bool {
        true
    }

    fn gpu_gap(&self) -> Option<String> {
        crate::experiment::contract::scene_gpu_gap(&self.spec.scene_path, &self.spec.scene)
    }

    fn inputs(&self) -> Vec<PathBuf> {
        let mut v = vec![self.spec.path.clone(), self.spec.scene_path.clone()];
        v.extend(self.spec.scene.meshes().map(|m| PathBuf::from(&m.source)));
        v.dedup();
        v
    }

    type Axis = RealtimeAxis;

    fn axes(&self) -> Vec<Axis<RealtimeAxis>> {
        let s = &self.spec;
        vec![
            Axis::of(RealtimeAxis::Variant, s.variants.iter().map(|v| v.name().to_string())),
            Axis::of(RealtimeAxis::Scheme, s.schemes.iter().map(|v| v.name().to_string())),
            Axis::of(RealtimeAxis::Rays, s.rays.iter().map(u32::to_string)),
            Axis::of(RealtimeAxis::Frames, s.frames.iter().map(u32::to_string)),
            Axis::of(
                RealtimeAxis::Accumulation,
                s.accumulations.iter().map(|a| a.name().to_string()),
            ),
            Axis::of(RealtimeAxis::Filter, s.filters.iter().map(|f| f.name().to_string())),
            Axis::of(RealtimeAxis::Seed, s.seeds.iter().map(u32::to_string)),
        ]
    }

    fn restrict(&mut self, axis: RealtimeAxis, keep: &[usize]) {
        let s = &mut self.spec;
        match axis {
            RealtimeAxis::Variant => keep_at(&mut s.variants, keep),
            RealtimeAxis::Scheme => keep_at(&mut s.schemes, keep),
            RealtimeAxis::Rays => keep_at(&mut s.rays, keep),
            RealtimeAxis::Frames => keep_at(&mut s.frames, keep),
            RealtimeAxis::Accumulation => keep_at(&mut s.accumulations, keep),
            RealtimeAxis::Filter => keep_at(&mut s.filters, keep),
            RealtimeAxis::Seed => keep_at(&mut s.seeds, keep),
        }
    }

    fn units(&self) -> Vec<Unit> {
        let s = &self.spec;
        let pixels = (s.width * s.height) as f64;
        let frames = s.max_frames() as f64 * s.seeds.len() as f64;
        let mut units = Vec::new();
        for (v, variant) in s.variants.iter().enumerate() {
            for (k, scheme) in s.schemes.iter().enumerate() {
                for (r, rays) in s.rays.iter().enumerate() {
                    let label = format!("variant={} scheme={scheme} rays={rays}", variant.name());
                    // Rays, and the filters' work at the judged frames (about 100 taps a pixel).
                    let filtering = 100.0 * (s.filters.len() * s.accumulations.len() * 2 * s.frames.len()) as f64;
                    units.push(Unit {
                        at: vec![v, k, r],
                        cost: Cost {
                            work: pixels * (frames * (1 + rays) as f64 + filtering * s.seeds.len() as f64),
                            setup: None,
                            tie: label.clone(),
                        },
                        label,
                    });
                }
            }
        }
        let timed = (s.schemes.len() * s.rays.len() + s.filters.len()) as f64;
        units.push(Unit {
            at: vec![],
            label: "timing".into(),
            cost: Cost {
                work: pixels * timed * 16.0 * s.header.schedule.repeats as f64,
                setup: None,
                tie: "timing".into(),
            },
        });
        units
    }

    fn plan(&self, units: &[Unit]) -> anyhow::Result<String> {
        let s = &self.spec;
        let mut out = format!(
            "{} x {} px; frames judged at {:?} of one sequence per seed; {} filter(s), {} accumulation(s)\n",
            s.width,
            s.height,
            s.frames,
            s.filters.len(),
            s.accumulations.len()
        );
        for u in units {
            out += &format!("  {}\n", u.label);
        }
        Ok(out)
    }

    fn measure(&self, unit: &Unit, backend: &mut dyn Backend, progress: &Progress) -> anyhow::Result<Outcome> {
        let s = &self.spec;
        match unit.at[..] {
            [v, k, r] => runner::measure(s, &self.refs, s.variants[v], s.schemes[k], s.rays[r], backend, progress),
            _ => runner::time(s, &self.refs, backend, progress),
        }
    }

    fn report(&self, outcomes: Vec<Outcome>, run: &mut RunContext) -> anyhow::Result<toml::Table> {
        report::write(&self.spec, outcomes, run)
    }
}
