//! The `accelerator` sweep axis reaches every frame of a run: pictures, the logged plan; and a
//! scene without triangles has no structures to sweep.

use crate::common;

use penumbra::experiment::sweep::pictures::render_pictures;

use penumbra::experiment::sweep::spec::Spec;
use penumbra::render::cpu::CpuBackend;
use penumbra::render::{AdapterInfo, Backend, Frame, Sampling, Timing, View};
use penumbra::scene::Scene;

/// A backend that notes which structure each frame's scene carries.
struct Spy {
    inner: CpuBackend,
    seen: Vec<Option<&'static str>>,
}

impl Backend for Spy {
    fn adapter(&self) -> &AdapterInfo {
        self.inner.adapter()
    }
    fn dispatches(&self) -> u64 {
        self.inner.dispatches()
    }
    fn render(&mut self, scene: &Scene, view: View, sampling: Sampling) -> anyhow::Result<Frame> {
        self.seen.push(scene.accel.as_ref().map(|a| a.name()));
        self.inner.render(scene, view, sampling)
    }
    fn time(&mut self, s: &Scene, v: View, sm: Sampling, w: u32, r: u32) -> anyhow::Result<Timing> {
        self.inner.time(s, v, sm, w, r)
    }
}

fn meshed(dir: &std::path::Path, accelerators: &str, figures: bool) -> Spec {
    let exp = common::tiny_experiment(dir, |t| {
        let mut t = t
            .replace(
                "seeds = [1, 2]",
                &format!("seeds = [1]\naccelerators = [{accelerators}]"),
            )
            .replace("samples = [4, 16]", "samples = [4]")
            .replace("schemes = [\"uniform\", \"paper\"]", "schemes = [\"uniform\"]")
            .replace("patterns = [\"per-pixel\", \"shared\"]", "patterns = [\"per-pixel\"]");
        if figures {
            t += "\n[figures]\ncamera = \"picture\"\nwidth = 8\nheight = 6\nsamples = 4\nground_truth_samples = 4\n";
        }
        t
    });
    let tent = "v -0.1 -0.1 0.5\nv 0.1 -0.1 0.5\nv 0.0 0.1 0.5\nv 0.0 0.0 0.7\nf 1 2 4\nf 2 3 4\nf 3 1 4\n";
    std::fs::write(dir.join("scenes/tent.obj"), tent).unwrap();
    let mut text = std::fs::read_to_string(dir.join("scenes/sphere.toml")).unwrap();
    text += "\n[[meshes]]\npath = \"tent.obj\"\nalbedo = 0.5\n";
    std::fs::write(dir.join("scenes/sphere.toml"), text).unwrap();
    Spec::load(&exp).unwrap()
}

/// Each picture belongs to a run (and its FLIP goes into that run's configuration), so it must
/// be rendered through that run's structure.
#[test]
fn pictures_use_the_runs_structure() {
    let dir = tempfile::tempdir().unwrap();
    let spec = meshed(dir.path(), "\"bvh\", \"brute\"", true);
    let mut spy = Spy {
        inner: CpuBackend::default(),
        seen: vec![],
    };
    let p = render_pictures(&spec, &mut spy, 0.02).unwrap().unwrap();
    let labels: Vec<String> = p.runs.iter().map(|(r, _)| r.accelerator.clone()).collect();
    // seen[0] is the ground-truth picture.
    let used: Vec<Option<&str>> = spy.seen[1..].to_vec();
    assert_eq!(
        used,
        labels.iter().map(|l| Some(l.as_str())).collect::<Vec<_>>(),
        "pictures labelled {labels:?} were rendered with {used:?}"
    );
}

/// The plan logged with the results and printed by --dry-run describes a run of the sweep.
#[test]
fn dry_run_plan_names_a_swept_structure() {
    let dir = tempfile::tempdir().unwrap();
    let spec = meshed(dir.path(), "\"brute\"", false);
    let plan = spec.plan().unwrap().to_string();
    assert!(
        plan.contains("mesh (BRUTE)"),
        "only brute is swept, yet the plan says:\n{plan}"
    );
}

/// Listing structures for a scene without triangles sweeps nothing: every run would be
/// the same frame under another name.
#[test]
fn structures_without_triangles_are_rejected() {
    let dir = tempfile::tempdir().unwrap();
    let exp = common::tiny_experiment(dir.path(), |t| {
        t.replace("seeds = [1, 2]", "seeds = [1, 2]\naccelerators = [\"bvh\", \"brute\"]")
    });
    match Spec::load(&exp) {
        Ok(spec) => panic!(
            "accepted: {} configurations over {:?}, structures {:?}",
            spec.axes.configs().len(),
            spec.axes.accelerators,
            spec.structures.values().map(|s| s.is_some()).collect::<Vec<_>>()
        ),
        Err(e) => assert!(e.to_string().contains("sweep.accelerators"), "{e}"),
    }
}
