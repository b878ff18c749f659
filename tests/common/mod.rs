//! Shared test fixtures: the GPU backend (opened once per test binary) and scene paths.
#![allow(dead_code)]

use penumbra::render::gpu::GpuBackend;
use std::path::PathBuf;
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

/// Path of a file in the repository.
pub fn repo(path: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(path)
}
