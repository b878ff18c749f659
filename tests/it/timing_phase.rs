//! The timing phase, against a backend whose clock drifts: every configuration is timed once
//! (not once per seed) in interleaved rounds with warm-up frames, the configurations compared
//! visited back to back, the A/A control every round, drift does not rank configurations that
//! do the same work, rounds stop once every comparison is decided, and a resumed sweep reuses
//! the journaled timings.

use crate::common;

use penumbra::experiment::progress::Progress;
use penumbra::experiment::sweep::report::markdown::report;
use penumbra::experiment::sweep::report::summary::summarise;
use penumbra::experiment::sweep::timing::{compare, NOISE_VISITS};
use penumbra::experiment::sweep::{run_sweep, Spec};
use penumbra::render::cpu::CpuBackend;
use penumbra::render::{AdapterInfo, Backend, Clock, Frame, Sampling, Timing, View};
use penumbra::sampling::DiskScheme;
use penumbra::scene::Scene;
use penumbra::timing::Comparison;

/// Renders on the CPU; `time` returns 10 ms (times `paper_cost` for the paper's pattern) plus a
/// drift of 0.1 ms per call, and logs its calls.
struct Drifting {
    cpu: CpuBackend,
    calls: Vec<(Sampling, u32, u32, u32)>,
    paper_cost: f64,
}

impl Drifting {
    fn new(paper_cost: f64) -> Drifting {
        Drifting {
            cpu: CpuBackend::default(),
            calls: vec![],
            paper_cost,
        }
    }
}

impl Backend for Drifting {
    fn adapter(&self) -> &AdapterInfo {
        self.cpu.adapter()
    }
    fn dispatches(&self) -> u64 {
        self.cpu.dispatches()
    }
    fn render(&mut self, scene: &Scene, view: View, s: Sampling) -> anyhow::Result<Frame> {
        self.cpu.render(scene, view, s)
    }
    fn time(&mut self, scene: &Scene, _: View, s: Sampling, warmup: u32, repeats: u32) -> anyhow::Result<Timing> {
        let samples = match &scene.lights[0] {
            penumbra::scene::Light::Disk(d) => d.samples,
            _ => 1,
        };
        self.calls.push((s, samples, warmup, repeats));
        let cost = if s.scheme == DiskScheme::Paper {
            self.paper_cost
        } else {
            1.0
        };
        let t = 10e-3 * cost + 1e-4 * self.calls.len() as f64;
        Ok(Timing {
            seconds: vec![t; repeats as usize],
            primary_seconds: vec![],
            clock: Clock::WallClock,
        })
    }
}

#[test]
fn configurations_are_timed_once_in_interleaved_rounds() {
    let dir = tempfile::tempdir().unwrap();
    let exp = common::tiny_experiment(dir.path(), |t| {
        t.replace("warmup = 0\nrepeats = 0", "warmup = 2\nrepeats = 6")
    });
    let spec = Spec::load(&exp).unwrap();
    let mut backend = Drifting::new(1.0);
    let out = run_sweep(&spec, &mut backend, dir.path(), true, &Progress::default()).unwrap();
    // 2 schemes x 2 patterns x 2 ray counts = 8 configurations (each with 2 seeds), 6 rounds,
    // plus the A/A control's visits.
    let configs = 8;
    let per_round = configs + NOISE_VISITS as usize;
    assert_eq!(backend.calls.len(), 6 * per_round);
    assert!(
        backend.calls.iter().all(|c| c.2 == 2 && c.3 == 1),
        "warm-up frames, one timed frame"
    );
    assert!(
        backend.calls.iter().all(|c| c.0.seed == 1),
        "timed with the first seed only"
    );
    let rounds: Vec<Vec<(DiskScheme, u32)>> = backend
        .calls
        .chunks(per_round)
        .map(|r| r.iter().map(|c| (c.0.scheme, c.1)).collect())
        .collect();
    assert!(rounds.windows(2).all(|w| w[0] != w[1]), "every round has its own order");
    // The configurations compared (same pattern and ray count) are visited back to back.
    for round in backend.calls.chunks(per_round) {
        let blocks: Vec<(String, u32)> = round.iter().map(|c| (format!("{:?}", c.0.pattern), c.1)).collect();
        let mut seen: Vec<&(String, u32)> = Vec::new();
        for (i, b) in blocks.iter().enumerate() {
            if i > 0 && blocks[i - 1] != *b {
                assert!(!seen.contains(&b), "block {b:?} split within a round: {blocks:?}");
            }
            seen.push(b);
        }
    }
    assert_eq!(out.timings.configs.len(), configs);
    let (probe, noise) = out.timings.noise.as_ref().expect("an A/A control");
    assert_eq!(noise.frame_seconds.len(), 6 * NOISE_VISITS as usize);
    assert_eq!((probe.scheme, probe.samples), (DiskScheme::Uniform, 16));
    for r in &out.records {
        assert_eq!(r.time.timed_frames, Some(6));
        let (lo, med, hi) = (r.time.frame_s_lo, r.time.frame_s, r.time.frame_s_hi);
        assert!(lo <= med && med <= hi && lo > 10e-3, "{lo} {med} {hi}");
    }
    // Every configuration does the same (fake) work; the drift must rank no two of them, and
    // the A/A control is given no direction.
    let all: Vec<_> = out.timings.configs.values().chain([noise]).collect();
    for a in &all {
        for b in &all {
            let penumbra::timing::Decided { ratio, word, .. } = compare(a, b, out.timings.looks);
            assert!(
                !matches!(word, Comparison::Faster | Comparison::Slower),
                "{ratio:?}: {word:?}"
            );
        }
    }
    // A resumed sweep takes the timings from the journal and times nothing.
    backend.calls.clear();
    let again = run_sweep(&spec, &mut backend, dir.path(), false, &Progress::default()).unwrap();
    assert!(backend.calls.is_empty(), "{} frames re-timed", backend.calls.len());
    assert_eq!(again.timings.configs, out.timings.configs);
    assert_eq!(again.timings.noise.as_ref().map(|n| &n.1), Some(noise));
    let frame_s =
        |o: &penumbra::experiment::sweep::Outcome| -> Vec<f64> { o.records.iter().map(|r| r.time.frame_s).collect() };
    assert_eq!(frame_s(&again), frame_s(&out));
    // One configuration more: every configuration is timed again in one interleaved phase, so
    // the new one is never ranked against frames timed in another process.
    let text = std::fs::read_to_string(&exp).unwrap();
    std::fs::write(
        &exp,
        text.replace(r#"["uniform", "paper"]"#, r#"["uniform", "paper", "jittered"]"#),
    )
    .unwrap();
    let wider = Spec::load(&exp).unwrap();
    backend.calls.clear();
    let third = run_sweep(&wider, &mut backend, dir.path(), false, &Progress::default()).unwrap();
    assert_eq!(third.timings.configs.len(), configs + 4);
    assert_eq!(backend.calls.len(), 6 * (configs + 4 + NOISE_VISITS as usize));
}

/// With `repeats = 12` as the cap, a sweep whose every comparison is decided at the first look
/// (the paper's pattern 2x uniform's time: slower; the A/A control: equivalent) times six
/// rounds, and the report says so.
#[test]
fn rounds_stop_when_every_comparison_is_decided() {
    let dir = tempfile::tempdir().unwrap();
    let exp = common::tiny_experiment(dir.path(), |t| {
        t.replace("warmup = 0\nrepeats = 0", "warmup = 0\nrepeats = 12")
    });
    let spec = Spec::load(&exp).unwrap();
    let mut backend = Drifting::new(2.0);
    let out = run_sweep(&spec, &mut backend, dir.path(), true, &Progress::default()).unwrap();
    assert_eq!(backend.calls.len(), 6 * (8 + NOISE_VISITS as usize));
    let looks = out.timings.looks;
    assert_eq!(looks.cap, 12);
    let (probe, noise) = out.timings.noise.as_ref().unwrap();
    let twin_of = out.groups.iter().find(|g| g.config == *probe).unwrap();
    let d = compare(noise, &out.timings.configs[&twin_of.key], looks);
    assert_eq!((d.word, d.rounds), (Comparison::Equivalent, 6));
    for g in out.groups.iter().filter(|g| g.config.scheme == DiskScheme::Paper) {
        let mut c = g.config.clone();
        c.scheme = DiskScheme::Uniform;
        let uniform = out.groups.iter().find(|u| u.config == c).unwrap();
        let d = compare(&out.timings.configs[&g.key], &out.timings.configs[&uniform.key], looks);
        assert_eq!((d.word, d.rounds), (Comparison::Slower, 6), "{d:?}");
    }
    let summaries = summarise(&out, &Default::default());
    let text = report(&spec, &out, &summaries, backend.adapter(), 0.0);
    assert!(text.contains("slower (6 rounds)"), "{text}");
}

#[test]
fn timing_asks_for_at_least_six_repeats() {
    let dir = tempfile::tempdir().unwrap();
    let exp = common::tiny_experiment(dir.path(), |t| t.replace("repeats = 0", "repeats = 5"));
    let e = Spec::load(&exp).unwrap_err().to_string();
    assert!(
        e.contains("tiny.toml:") && e.contains("timing.repeats") && e.contains("at least 6"),
        "{e}"
    );
}

/// The frame-rate experiment times every configuration once per interleaved round, like every
/// kind, each median with its interval.
#[test]
fn frame_rates_are_timed_in_interleaved_rounds() {
    use penumbra::experiment::fps::{run_fps, FpsSpec};
    let dir = tempfile::tempdir().unwrap();
    let scenes = common::repo("experiments/scenes");
    // Six rounds whatever the committed file asks for.
    let text: String = std::fs::read_to_string(common::repo("experiments/fps.toml"))
        .unwrap()
        .lines()
        .map(|l| {
            if l.starts_with("repeats =") {
                "repeats = 6\n".to_string()
            } else {
                format!("{l}\n")
            }
        })
        .collect();
    let text = text
        .replace("resolutions = [[800, 600], [1920, 1080]]", "resolutions = [[16, 12]]")
        .replace("scene = \"scenes/", &format!("scene = \"{}/", scenes.display()));
    let path = dir.path().join("fps.toml");
    std::fs::write(&path, text).unwrap();
    let spec = FpsSpec::load(&path).unwrap();
    let mut backend = Drifting::new(1.0);
    let rows = run_fps(&spec, &mut backend, &Progress::default()).unwrap();
    assert_eq!(rows.len(), 4, "two scenes, one and two lights, one resolution");
    assert_eq!(
        backend.calls.len(),
        4 * 6,
        "one timed frame per configuration per round"
    );
    assert!(
        backend.calls.iter().all(|c| (c.2, c.3) == (1, 1)),
        "one warm-up, one timed frame"
    );
    for r in &rows {
        assert_eq!(r.frame_seconds.len(), 6);
        assert!(
            r.frame.lo <= r.frame.median && r.frame.median <= r.frame.hi,
            "{:?}",
            r.frame
        );
        assert!(r.work.is_some_and(|w| w.queries > 0), "the CPU counts the work");
    }
    // Its outputs: fps.csv under the one unit convention, the plot beside its SVG.
    let out = dir.path().join("out");
    let adapter = backend.adapter().clone();
    penumbra::experiment::fps::report::write_fps(&spec, &rows, &adapter, 1.0, &out).unwrap();
    assert_eq!(common::assert_tidy_tables(&out).len(), 2, "fps.csv and rounds.csv");
    let header = std::fs::read_to_string(out.join("fps.csv")).unwrap();
    assert!(header.starts_with("scene,lights,width,height,samples,timed_frames,frame_s,frame_s_lo,frame_s_hi,frames_per_s,paper_frames_per_s,"), "{header}");
    assert!(out.join("plots/fps.svg").is_file());
}

/// `[timed] samples = [16]` times the 16-ray configurations only: the 4-ray ones get no frames
/// and read "untimed", and the A/A control sits among the timed ones.
#[test]
fn only_the_timing_grid_is_timed() {
    let dir = tempfile::tempdir().unwrap();
    let exp = common::tiny_experiment(dir.path(), |t| {
        format!(
            "{}\n[timed]\nsamples = [16]\n",
            t.replace("warmup = 0\nrepeats = 0", "warmup = 0\nrepeats = 6")
        )
    });
    let spec = Spec::load(&exp).unwrap();
    let mut backend = Drifting::new(1.0);
    let out = run_sweep(&spec, &mut backend, dir.path(), true, &Progress::default()).unwrap();
    assert!(backend.calls.iter().all(|c| c.1 == 16), "only 16 rays timed");
    assert_eq!(backend.calls.len(), 6 * (4 + NOISE_VISITS as usize));
    assert_eq!(out.timings.configs.len(), 4);
    for r in &out.records {
        assert_eq!(r.time.frame_s.is_nan(), r.run.samples == 4, "{:?}", r.run);
    }
    assert_eq!(out.timings.noise.as_ref().unwrap().0.samples, 16);
}
