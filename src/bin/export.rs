//! `export SCENE --camera NAME --size WxH --to mitsuba|pbrt|penumbra --out DIR`: one view of a
//! penumbra scene for another renderer (a Mitsuba 3 or pbrt-v4 scene file, meshes as PLY) or rendered by
//! penumbra's f64 CPU backend (radiance EXRs), with the `view.toml` record `judge` scores
//! images of the view against. Exit status: 0 done, 2 bad input (a scene or view the format
//! cannot hold as penumbra renders it), 1 else.

use clap::{Parser, ValueEnum};
use penumbra::experiment::cli::{finish, print_out};
use penumbra::files::Refused;
use penumbra::peers::{export::view_of, mitsuba, pbrt, view, write_files, write_folder};
use penumbra::render::{cpu::CpuBackend, Backend, Sampling, View};
use penumbra::sampling::{DiskScheme, Pattern};
use penumbra::scene::{Light, Scene};
use std::path::PathBuf;

/// What the view is written for.
#[derive(Clone, Copy, ValueEnum)]
enum Target {
    /// A Mitsuba 3 scene file (scene.xml) rendering the view with a box pixel filter.
    Mitsuba,
    /// A pbrt-v4 scene file (scene.pbrt) rendering the view with a box pixel filter.
    Pbrt,
    /// Penumbra's own radiance images of the view (pixel centres), one per sample count and seed.
    Penumbra,
}

/// Export a scene's view for another renderer, or render it with penumbra for the judge.
#[derive(Parser)]
#[command(version, about)]
struct Args {
    /// The scene file, e.g. experiments/scenes/sphere.toml.
    scene: PathBuf,
    /// The camera's name in the scene.
    #[arg(long)]
    camera: String,
    /// Image size, WIDTHxHEIGHT.
    #[arg(long, value_parser = parse_size)]
    size: (u32, u32),
    /// The format.
    #[arg(long, value_enum)]
    to: Target,
    /// The folder written (replaced as a whole, only once everything is written).
    #[arg(long)]
    out: PathBuf,
    /// With `--to penumbra`: shadow rays per pixel and light, one image per count.
    #[arg(long, value_delimiter = ',', default_value = "16")]
    spp: Vec<u32>,
    /// With `--to penumbra`: seeds 1..=SEEDS of each count.
    #[arg(long, default_value_t = 4)]
    seeds: u32,
    /// With `--to penumbra`: the disk-sampling scheme (per-pixel pattern).
    #[arg(long, default_value = "uniform")]
    scheme: DiskScheme,
}

fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let bad = || {
        format!(
            "`{s}`: expected WIDTHxHEIGHT, each 1 to {}",
            penumbra::config::MAX_IMAGE_SIDE
        )
    };
    let (w, h) = s.split_once('x').ok_or_else(bad)?;
    let (w, h): (u32, u32) = (w.parse().map_err(|_| bad())?, h.parse().map_err(|_| bad())?);
    let side = 1..=penumbra::config::MAX_IMAGE_SIDE;
    if !side.contains(&w) || !side.contains(&h) || w as u64 * h as u64 > penumbra::config::MAX_IMAGE_PIXELS {
        return Err(bad());
    }
    Ok((w, h))
}

fn run(args: &Args) -> anyhow::Result<String> {
    let bytes = penumbra::files::read_regular(&args.scene)?;
    let scene = Scene::load(&args.scene)?;
    let camera = scene.cameras.get(&args.camera).ok_or_else(|| {
        Refused(format!(
            "{}: no camera `{}`; it has {}",
            args.scene.display(),
            args.camera,
            scene
                .cameras
                .keys()
                .map(|k| format!("`{k}`"))
                .collect::<Vec<_>>()
                .join(", ")
        ))
    })?;
    penumbra::peers::refuse_unmatched_effects(&scene, &args.scene)?;
    let scene_path = std::path::absolute(&args.scene)?;
    let (w, h) = args.size;
    let (pixel, lift) = match args.to {
        Target::Mitsuba => (view::PixelFilter::Box, "mitsuba3"),
        Target::Pbrt => (view::PixelFilter::Box, "none"),
        Target::Penumbra => (view::PixelFilter::Centre, "none"),
    };
    let record = view_of(&scene_path, &bytes, &args.camera, w, h, pixel, lift);
    let mut files = Vec::new();
    match args.to {
        Target::Mitsuba => files.extend(mitsuba::export(&scene, camera, &record)?.into_files()),
        Target::Pbrt => files.extend(pbrt::export(&scene, camera, &record)?.into_files()),
        Target::Penumbra => {
            let mut backend = CpuBackend::default();
            let mut times = csv::Writer::from_writer(Vec::new());
            times.write_record(["image", "spp", "seed", "scheme", "shadow_rays", "seconds", "threads"])?;
            for &spp in &args.spp {
                if spp == 0 || spp > penumbra::scene::MAX_SAMPLES {
                    return Err(Refused(format!("--spp {spp}: expected 1 to {}", penumbra::scene::MAX_SAMPLES)).into());
                }
                let mut s = scene.clone();
                for l in &mut s.lights {
                    if let Light::Disk(d) = l {
                        d.samples = spp;
                    }
                }
                for seed in 1..=args.seeds {
                    let sampling = Sampling {
                        scheme: args.scheme,
                        pattern: Pattern::PerPixel,
                        seed,
                        frame: 0,
                    };
                    let started = std::time::Instant::now();
                    let frame = backend.render(
                        &s,
                        View {
                            camera,
                            width: w,
                            height: h,
                        },
                        sampling,
                    )?;
                    let seconds = started.elapsed().as_secs_f64();
                    let name = format!("penumbra-{}-spp{spp}-seed{seed}.exr", args.scheme.name());
                    times.write_record([
                        name.clone(),
                        spp.to_string(),
                        seed.to_string(),
                        args.scheme.name().to_string(),
                        frame.rays.shadow_total().to_string(),
                        format!("{seconds:.6}"),
                        rayon::current_num_threads().to_string(),
                    ])?;
                    files.push((name, penumbra::output::images::exr_bytes(&frame.radiance, w, h)?));
                }
            }
            files.push(("penumbra-times.csv".to_string(), times.into_inner()?));
        }
    }
    files.push((view::FILE.to_string(), record.to_toml().into_bytes()));
    write_folder(&args.out, |dir| write_files(dir, &files))?;
    Ok(format!("wrote {} ({} files)\n", args.out.display(), files.len()))
}

fn main() -> std::process::ExitCode {
    let args = Args::parse();
    finish(run(&args).and_then(|text| print_out(&text).map_err(Into::into)))
}
