//! The sweep as a kind on the experiment core. Its units: one per configuration (every seed of
//! it rendered in one process, since the per-pixel bias/variance split needs every seed's
//! image), the Fig. 2 pictures, and the timing phase (every configuration interleaved in one
//! schedule, so times are only ever ranked against times from the same process). Filters,
//! the unit journal, `--shard`, `--merge`, resume and the dry run are the core's.
//!
//! Groups are dealt to shards by the rays their frames trace; each names its (lights, radius)
//! ground truth as a setup shared with the groups judged against it, so groups sharing a costly
//! ground truth stay together exactly where that finishes sooner. The ground truths are cached
//! under the results folder (`cache/`), shared by the shards and the merge: a shard that finds
//! none renders it (deterministically: same seed, same device, same bytes) and writes it
//! atomically, so two shards racing for one entry both end with a whole, identical file.

use super::axes::Axis;
use super::reference::Reference;
use super::run::{context_key, expand, Group};
use super::runner::UnitOutcome;
use super::runner::{assemble, measure_group, time_all, Outcome};
use super::spec::Spec;
use crate::experiment::contract::RunContext;
use crate::experiment::core::filter;
use crate::experiment::core::{measure_whole, Cost, Declaration, Unit};
use crate::experiment::header::Header;
use crate::experiment::progress::Progress;
use crate::fingerprint::fnv1a;
use crate::render::{AdapterInfo, Backend, RenderPlan, View};
use crate::sampling::DiskScheme;
use anyhow::Context;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

/// The label of the pictures unit.
const PICTURES: &str = "pictures";
/// The label of the timing unit.
const TIMING: &str = "timing";

/// References made on first use in one process, keyed by (lights, light radius bits).
type References = Arc<Mutex<HashMap<(u32, u64), Arc<Reference>>>>;

/// A sweep with the references its units share in one process.
#[derive(Clone)]
pub struct Sweep {
    /// The validated file.
    pub spec: Spec,
    /// Where ground truths are cached (`cache/` under the results folder), once known.
    cache: Option<PathBuf>,
    /// The cache folder, held from the first ground truth on: one swapped for another folder
    /// or a link between two ground truths is refused, not written through.
    held: Arc<Mutex<Option<Arc<crate::files::Folder>>>>,
    /// References made on first use.
    references: References,
}

impl Sweep {
    /// Wraps a validated file.
    pub fn new(spec: Spec) -> Sweep {
        Sweep {
            spec,
            cache: None,
            held: Default::default(),
            references: Default::default(),
        }
    }

    /// The reference of (`lights`, `radius`): made on first use in this process, its ground
    /// truth read from the cache where a unit (here or in another shard) left it.
    pub fn reference(&self, backend: &mut dyn Backend, lights: u32, radius: f64) -> anyhow::Result<Arc<Reference>> {
        let key = (lights, radius.to_bits());
        if let Some(r) = self.references.lock().expect("not poisoned").get(&key) {
            return Ok(r.clone());
        }
        let context = context_key(&self.spec, backend.adapter());
        let cache = self.cache_folder()?;
        let built = Reference::build(&self.spec, backend, lights, radius, &cache, &context);
        if built.is_err() {
            cache.remove_if_made_and_empty();
        }
        let reference = Arc::new(built?);
        for warning in reference.warnings() {
            tracing::warn!("{warning}");
        }
        self.references
            .lock()
            .expect("not poisoned")
            .insert(key, reference.clone());
        Ok(reference)
    }

    /// The ground-truth cache, created and held on first use, and checked to be the folder held
    /// on every later one.
    fn cache_folder(&self) -> anyhow::Result<Arc<crate::files::Folder>> {
        let mut held = self.held.lock().expect("not poisoned");
        if let Some(folder) = held.as_ref() {
            folder.check_held()?;
            return Ok(folder.clone());
        }
        let path = self
            .cache
            .clone()
            .unwrap_or_else(|| std::env::temp_dir().join("penumbra-cache"));
        let folder = Arc::new(crate::files::Folder::create(&path)?);
        *held = Some(folder.clone());
        Ok(folder)
    }

    /// Rays one frame of `lights` lights at `samples` rays each traces at most: the unit of
    /// expected cost.
    fn frame_rays(&self, lights: u32, samples: u32) -> f64 {
        let s = &self.spec;
        let scene = s.scene_with(lights, s.axes.light_radii[0], samples, &s.axes.accelerators[0]);
        let view = View {
            camera: &scene.cameras[&s.measure.camera],
            width: s.measure.width,
            height: s.measure.height,
        };
        RenderPlan::new(&scene, view).map_or(0.0, |p| p.max_rays() as f64)
    }

    /// The groups' costs: their frames' rays, each with its ground truth as a shared setup.
    fn group_costs(&self, groups: &[Group]) -> Vec<Cost> {
        let mut memo: HashMap<(u32, u32), f64> = HashMap::new();
        let mut rays = |lights: u32, samples: u32| {
            *memo
                .entry((lights, samples))
                .or_insert_with(|| self.frame_rays(lights, samples))
        };
        groups
            .iter()
            .map(|g| {
                let head = g.head();
                let pair = fnv1a(format!("{};{}", head.lights, head.light_radius.to_bits()).as_bytes());
                Cost {
                    work: g.runs.len() as f64 * rays(head.lights, head.samples),
                    setup: Some((pair, rays(head.lights, self.spec.ground_truth.samples))),
                    tie: head.key_text(),
                }
            })
            .collect()
    }
}

impl Declaration for Sweep {
    type Outcome = UnitOutcome;

    fn header(&self) -> &Header {
        &self.spec.header
    }

    fn locate(&self, e: anyhow::Error) -> anyhow::Error {
        self.spec.places.locate(e)
    }

    fn gpu(&self) -> bool {
        true
    }

    fn inputs(&self) -> Vec<PathBuf> {
        let s = &self.spec;
        let mut v = vec![s.path.clone(), s.scene_path.clone()];
        v.extend(s.scene.meshes().map(|m| PathBuf::from(&m.source)));
        v.extend(s.points_files());
        v
    }

    fn gpu_gap(&self) -> Option<String> {
        let s = &self.spec;
        if let Some(gap) = crate::experiment::contract::scene_gpu_gap(&s.scene_path, &s.scene) {
            return Some(gap);
        }
        s.axes.accelerators.iter().enumerate().find_map(|(i, name)| {
            let refusal = s.structures.get(name)?.as_ref()?.gpu_refusal()?;
            Some(if *name == s.scene.accel_settings.name {
                format!("{}: key `accelerator`: {refusal}", s.scene_path.display())
            } else {
                format!("{}: key `sweep.accelerators[{i}]`: {refusal}", s.path.display())
            })
        })
    }

    type Axis = Axis;

    fn axes(&self) -> Vec<filter::Axis<Axis>> {
        self.spec.axes.declared()
    }

    fn restrict(&mut self, axis: Axis, keep: &[usize]) {
        self.spec.axes.restrict(axis, keep);
    }

    fn units(&self) -> Vec<Unit> {
        let groups = expand(&self.spec);
        let mut units: Vec<Unit> = groups
            .iter()
            .zip(self.group_costs(&groups))
            .enumerate()
            .map(|(i, (g, cost))| Unit {
                at: vec![i],
                label: g.config().to_string(),
                cost,
            })
            .collect();
        let s = &self.spec;
        let lights = *s.axes.light_counts.iter().max().expect("validated non-empty");
        if let Some(f) = &s.figures {
            let pictures = groups.len() as f64 / s.axes.samples.len().max(1) as f64;
            let per_pixel = (f.width * f.height) as f64 / (s.measure.width * s.measure.height) as f64;
            units.push(Unit {
                at: vec![],
                label: PICTURES.into(),
                cost: Cost {
                    work: per_pixel
                        * (pictures * self.frame_rays(lights, f.samples)
                            + self.frame_rays(lights, f.ground_truth_samples)),
                    setup: None,
                    tie: PICTURES.into(),
                },
            });
        }
        if s.timing.repeats > 0 {
            let per_round: f64 = groups
                .iter()
                .map(|g| self.frame_rays(g.head().lights, g.head().samples))
                .sum();
            units.push(Unit {
                at: vec![],
                label: TIMING.into(),
                cost: Cost {
                    work: per_round * (1 + s.timing.warmup) as f64 * s.timing.repeats as f64,
                    setup: None,
                    tie: TIMING.into(),
                },
            });
        }
        units
    }

    fn plan(&self, units: &[Unit]) -> anyhow::Result<String> {
        let s = &self.spec;
        let seeds: Vec<String> = s.axes.seeds.iter().map(|r| r.to_string()).collect();
        let groups = units.iter().filter(|u| !u.at.is_empty()).count();
        Ok(format!(
            "{}: {} runs in {groups} configurations, each over seeds [{}]\nrender plan of a run:\n{}",
            s.name,
            groups * seeds.len(),
            seeds.join(", "),
            s.plan()?
        ))
    }

    /// A group is determined by its runs' keys (scene, meshes, view, ground truth, device,
    /// build, its configuration with a points file's hash, and the seeds) and whether it keeps
    /// a figure: adding a scheme or editing the timing reuses every journaled group. Pictures
    /// and timing take the default.
    fn unit_context(&self, unit: &Unit, adapter: &AdapterInfo) -> Option<String> {
        let [i] = unit.at[..] else {
            return None;
        };
        let group = &expand(&self.spec)[i];
        // Whether it keeps a figure follows the swept ray counts, not the group alone.
        let figure = group.head().samples == self.spec.figure_samples();
        Some(format!(
            "{};figure={figure}",
            group.key(&context_key(&self.spec, adapter))
        ))
    }

    fn keep_state_in(&mut self, home: &Path) {
        self.cache = Some(home.join("cache"));
        self.held = Default::default();
    }

    fn measure(&self, unit: &Unit, backend: &mut dyn Backend, progress: &Progress) -> anyhow::Result<UnitOutcome> {
        let s = &self.spec;
        if s.axes
            .schemes
            .iter()
            .any(|x| matches!(x, DiskScheme::SobolBluenoise | DiskScheme::SobolBluenoiseT))
        {
            // Every table the sweep reads, generated in parallel once (later calls find them).
            let mut counts = s.axes.samples.clone();
            counts.extend(s.figures.as_ref().map(|f| f.samples));
            crate::sampling::bluenoise::prepare(&counts);
        }
        match (unit.at.as_slice(), unit.label.as_str()) {
            ([i], _) => {
                let group = &expand(s)[*i];
                let reference = self.reference(backend, group.head().lights, group.head().light_radius)?;
                Ok(UnitOutcome::Group(measure_group(s, backend, group, &reference)?))
            }
            (_, PICTURES) => {
                let pictures = super::pictures::render_pictures(s, backend, s.verdict_radius())
                    .context("rendering the figures' pictures")?;
                Ok(UnitOutcome::Pictures(pictures))
            }
            _ => Ok(UnitOutcome::Timing(time_all(s, backend, progress)?)),
        }
    }

    fn failed(&self, outcome: &UnitOutcome) -> usize {
        match outcome {
            UnitOutcome::Group(g) => g.failed(),
            _ => 0,
        }
    }

    fn report(&self, outcomes: Vec<UnitOutcome>, run: &mut RunContext) -> anyhow::Result<toml::Table> {
        let adapter = run.backend.adapter().clone();
        let outcome = assemble(&self.spec, &adapter, |l, r| self.reference(run.backend, l, r), outcomes)?;
        tracing::info!("render plan of a run:\n{}", outcome.plan);
        let adapter = run.backend.adapter().clone();
        let results = super::report::Results {
            spec: &self.spec,
            outcome: &outcome,
            pictures: outcome.pictures.as_ref(),
            adapter: &adapter,
            seconds: run.started.elapsed().as_secs_f64(),
        };
        super::report::write_all(&results, run.out)?;
        tracing::info!("{} runs ({} failed)", outcome.records.len(), outcome.failures);
        Ok(super::report::details(&results))
    }
}

/// Runs the whole sweep in this process with the core's unit journal and the ground-truth cache
/// under `home` (`fresh` discards the journal first), and puts its outcomes together.
pub fn run_sweep(
    spec: &Spec,
    backend: &mut dyn Backend,
    home: &Path,
    fresh: bool,
    progress: &Progress,
) -> anyhow::Result<Outcome> {
    let mut sweep = Sweep::new(spec.clone());
    sweep.keep_state_in(home);
    let measured = measure_whole(&sweep, home, fresh, backend, progress)?;
    let adapter = backend.adapter().clone();
    assemble(spec, &adapter, |l, r| sweep.reference(backend, l, r), measured.outcomes)
}
