//! A frame or structure larger than the device binds. It is bad input (exit status 2), not a
//! failed run: the same experiment fails the same way on every rerun, and what fixes it is a
//! smaller frame or a structure with fewer tiles, both keys of the experiment. Each kind locates
//! it at the key that sized the part ([`crate::experiment::contract::Experiment::locate`]).

/// What the device could not bind.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Part {
    /// A per-frame buffer (hits, visibility, mirror chains) of a frame this wide and high:
    /// sized by the frame's width and height and the scene's lights. The size tells apart the
    /// keys that set one (a sweep's `[measure]` and `[figures]`, an ao's frame and `[tuning]`).
    Frame { width: u32, height: u32 },
    /// The scene's geometry on the GPU (its meshes' triangles): sized by the meshes.
    Scene,
    /// A buffer of the named registered structure: sized by its settings.
    Structure(&'static str),
}

/// A buffer over the device's binding limit, refused before anything is dispatched.
#[derive(Debug, thiserror::Error)]
#[error("{message}")]
pub struct DeviceLimit {
    /// What is too large.
    pub part: Part,
    /// The buffer, its size and the limit.
    pub message: String,
}

impl DeviceLimit {
    /// `part`, refused with `message`.
    pub fn new(part: Part, message: String) -> DeviceLimit {
        DeviceLimit { part, message }
    }

    /// The part `e` refuses, where `e` is a device limit.
    pub fn part_of(e: &anyhow::Error) -> Option<Part> {
        e.downcast_ref::<DeviceLimit>().map(|d| d.part)
    }
}

/// The adapter's binding limit as the checks read it: with the `test-hooks` feature,
/// `PENUMBRA_TEST_BINDING_BYTES` lowers it, so tests reach every refusal on any adapter.
pub fn binding_bytes(adapter: u64) -> u64 {
    #[cfg(feature = "test-hooks")]
    if let Some(b) = std::env::var("PENUMBRA_TEST_BINDING_BYTES")
        .ok()
        .and_then(|v| v.parse::<u64>().ok())
    {
        return adapter.min(b);
    }
    adapter
}
