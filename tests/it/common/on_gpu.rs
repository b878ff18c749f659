//! Running a kind's experiment on the GPU beside the f64 CPU: the GPU backend (opened once per
//! test binary; a missing adapter skips the GPU checks unless `PENUMBRA_REQUIRE_GPU=1`), an
//! experiment run on both, and their images compared.

use penumbra::render::gpu::GpuBackend;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, OnceLock};

/// The GPU backend, or `None` with a note when no adapter exists. Where the environment sets
/// `PENUMBRA_REQUIRE_GPU=1` (CI installs lavapipe and does), a missing adapter fails the test.
pub fn gpu() -> Option<std::sync::MutexGuard<'static, GpuBackend>> {
    static GPU: OnceLock<Option<Mutex<GpuBackend>>> = OnceLock::new();
    let slot = GPU.get_or_init(|| match GpuBackend::new() {
        Ok(g) => Some(Mutex::new(g)),
        Err(e) => {
            if std::env::var("PENUMBRA_REQUIRE_GPU").as_deref() == Ok("1") {
                panic!("PENUMBRA_REQUIRE_GPU=1 but: {e}");
            }
            eprintln!("skipping GPU checks: {e}");
            None
        }
    });
    slot.as_ref().map(|m| m.lock().unwrap_or_else(|p| p.into_inner()))
}

/// Runs experiment file `exp` (an ao or frames kind, whose default backend is the f64 CPU)
/// twice: with `--backend gpu` into `dir/gpu`, then as written into `dir/cpu`; returns both
/// folders. `None`, having run nothing, where there is no GPU to run on ([`gpu`]): the test
/// then checks nothing.
pub fn on_gpu_and_cpu(dir: &Path, exp: &Path) -> Option<(PathBuf, PathBuf)> {
    // Only asked whether there is one: the runs are processes of their own.
    drop(gpu()?);
    let (gpu, cpu) = (dir.join("gpu"), dir.join("cpu"));
    super::run_experiment(exp, &gpu, &["--backend", "gpu"]);
    super::run_experiment(exp, &cpu, &[]);
    Some((gpu, cpu))
}

/// Every image the GPU's run wrote (`gpu/images/*.exr`) against the CPU's of the same name:
/// (file, pixels differing by more than `step`, pixels, largest difference). f32 against f64
/// decides a grazing ray the other way now and then, which moves a pixel by about one ray's
/// weight.
pub fn images_against_cpu(gpu: &Path, cpu: &Path, step: f32) -> Vec<(String, usize, usize, f32)> {
    let mut files: Vec<String> = std::fs::read_dir(gpu.join("images"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|f| f.ends_with(".exr"))
        .collect();
    files.sort();
    assert!(!files.is_empty(), "{}: no images", gpu.display());
    files
        .into_iter()
        .map(|file| {
            let (g, _) = super::browser::exr(&gpu.join("images").join(&file)).unwrap();
            let (c, _) = super::browser::exr(&cpu.join("images").join(&file)).unwrap();
            assert_eq!(g.len(), c.len(), "{file}");
            let diff: Vec<f32> = g.iter().zip(&c).map(|(a, b)| (a - b).abs()).collect();
            let worst = diff.iter().cloned().fold(0.0, f32::max);
            let off = diff.iter().filter(|&&d| d > step).count();
            eprintln!(
                "{file}: {off} of {} pixels differ from the CPU's by more than {step}, worst {worst}",
                diff.len()
            );
            (file, off, diff.len(), worst)
        })
        .collect()
}
