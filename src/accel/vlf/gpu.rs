//! The visibility field's GPU form, read by `vlf.wgsl`: the triangles in input order, a header
//! (the ball in the frame's local coordinates, the settings, the rotation rows and which id
//! chunk holds each direction), the direction table, the layers' tile offsets (one u32 per tile,
//! [`super::layer::Offsets::flat`]) and their words. The WGSL reads the entries' ids and skips
//! their footprint boxes: SIMD lanes gain little from skipping single tests.
//!
//! The base layer's words can exceed wgpu's portable 128 MiB storage binding on large scenes,
//! so they are bound as up to [`ID_CHUNKS`] chunks of
//! whole directions, each at most [`CHUNK_BYTES`]; a direction's tile offsets are rebased on its
//! chunk's first word in the WGSL. The overlay layer (objects moved since the build) has its
//! own binding.

use super::layer::Layer;
use super::{Split, VisibilityField};
use crate::accel::{GpuStructure, GpuTri};
use crate::geometry::LocalFrame;
use crate::render::limit::{DeviceLimit, Part};

/// Storage buffers `vlf.wgsl` declares at group 2.
pub const GPU_BUFFERS: u32 = 9;

/// Bindings for the base layer's id chunks.
pub const ID_CHUNKS: usize = 4;

/// Largest id chunk: wgpu's default (and WebGPU's guaranteed) storage-binding size.
pub const CHUNK_BYTES: usize = 128 << 20;

/// Header words before the rotation rows (`VLF_H_ROWS` in the WGSL).
const HEADER: usize = 19;

/// Widening of the GPU's bounds in ball radii beyond the structure's own: f32 rounding of
/// coordinates of the order of the ball is ~1e-7 of its radius; this leaves a thousandfold
/// margin. The WGSL adds the rounding of each ray's origin, which grows with its distance.
const GPU_EPS: f64 = 1e-4;

/// Loop iterations budgeted for one any-hit query (tiles, leaves and entries): a query along a
/// stored direction visits one tile; long walks across the grid stay in the hundreds.
const WALK_ITERATIONS: u32 = 2048;

/// Bytes of the buffers [`structure`] uploads (without building them).
pub(super) fn bytes(field: &VisibilityField) -> usize {
    let dirs = field.frame.directions.len();
    let overlay = if field.overlay_ids.is_empty() {
        (0, 1)
    } else {
        (field.overlay.offsets.tiles() + 1, field.overlay.words.len().max(1))
    };
    std::mem::size_of::<GpuTri>() * field.world.len().max(1)
        + 4 * (HEADER + 10 * dirs)
        + 4 * field.frame.directions.table.len()
        + 4 * (field.base.offsets.tiles() + 1 + overlay.0)
        + 4 * (field.base.words.len().max(1) + overlay.1)
}

/// A field the GPU cannot bind: bad input at the field's settings.
fn over_limit(message: String) -> anyhow::Error {
    DeviceLimit::new(Part::Structure("vlf"), message).into()
}

/// The buffers `vlf.wgsl` binds at group 2, in binding order, or an error naming the array that
/// does not fit.
pub(super) fn structure(field: &VisibilityField, frame: &LocalFrame) -> anyhow::Result<GpuStructure> {
    let f = &field.frame;
    let s = &field.settings;
    let dirs = f.directions.len();
    let n2 = (s.tiles * s.tiles) as usize;
    let centre = frame.point_f64(f.centre);
    let radius = f.radius / frame.scale;
    let eps = GPU_EPS + super::EPS + 16.0 * f32::EPSILON as f64 * centre.length() / radius;
    let (base, overlay): (&Layer, Option<&Layer>) =
        (&field.base, (!field.overlay_ids.is_empty()).then_some(&field.overlay));

    // Chunks of whole directions, in order.
    let tile_first = base.offsets.flat();
    let word = |k: usize| (tile_first[k * n2] & !super::layer::SPLIT) as usize;
    let mut chunk_of = Vec::with_capacity(dirs);
    let mut chunk_start = vec![0usize];
    for k in 0..dirs {
        let (a, b) = (word(k), word(k + 1));
        if (b - a) * 4 > CHUNK_BYTES {
            return Err(over_limit(format!(
                "visibility field: direction {k}'s tile entries take {} bytes, over the {CHUNK_BYTES}-byte id chunk by {} bytes; use fewer tiles",
                (b - a) * 4,
                (b - a) * 4 - CHUNK_BYTES
            )));
        }
        if (b - chunk_start.last().unwrap()) * 4 > CHUNK_BYTES {
            chunk_start.push(a);
        }
        chunk_of.push(chunk_start.len() as u32 - 1);
    }
    if chunk_start.len() > ID_CHUNKS {
        return Err(over_limit(format!(
            "visibility field: the id buffer takes {} bytes, over the {} bytes of {ID_CHUNKS} chunks the GPU binds by {} bytes; use fewer tiles or directions",
            base.words.len() * 4,
            ID_CHUNKS * CHUNK_BYTES,
            (base.words.len() * 4).saturating_sub(ID_CHUNKS * CHUNK_BYTES)
        )));
    }
    chunk_start.push(base.words.len());

    let mut head: Vec<u32> = Vec::with_capacity(HEADER + 10 * dirs);
    head.extend(centre.as_vec3().to_array().map(f32::to_bits));
    head.extend([(radius as f32).to_bits(), (f.half_tiles as f32).to_bits()]);
    head.extend([
        s.tiles,
        s.depth,
        u32::from(s.split == Split::Median),
        f.directions.table_side,
        1 + u32::from(overlay.is_some()),
        tile_first.len() as u32,
        ((eps * f.half_tiles) as f32).to_bits(),
        (eps as f32).to_bits(),
    ]);
    head.extend((0..ID_CHUNKS).map(|c| *chunk_start.get(c).unwrap_or(&0) as u32));
    head.push(dirs as u32);
    head.push(u32::from(base.wide) | u32::from(overlay.is_some_and(|l| l.wide)) << 1);
    debug_assert_eq!(head.len(), HEADER);
    head.extend(f.directions.rows.iter().map(|&r| (r as f32).to_bits()));
    head.extend(&chunk_of);

    let mut tile_first = tile_first;
    tile_first.extend(overlay.map_or(Vec::new(), |l| l.offsets.flat()));
    let triangles: Vec<GpuTri> = field
        .world
        .iter()
        .enumerate()
        .map(|(i, t)| GpuTri::new(t, i as u32, frame))
        .collect();
    // A binding may not be empty.
    let words = |v: &[u32]| -> Vec<u8> {
        if v.is_empty() {
            vec![0; 4]
        } else {
            bytemuck::cast_slice(v).to_vec()
        }
    };
    let labels = [
        "visibility field id chunk 0",
        "visibility field id chunk 1",
        "visibility field id chunk 2",
        "visibility field id chunk 3",
    ];
    let mut buffers = vec![
        (
            "visibility field triangle buffer",
            bytemuck::cast_slice(&triangles).to_vec(),
        ),
        ("visibility field header buffer", words(&head)),
        ("visibility field direction table", words(&f.directions.table)),
        ("visibility field tile buffer", words(&tile_first)),
    ];
    for (c, label) in labels.iter().enumerate() {
        let (a, b) = match (chunk_start.get(c), chunk_start.get(c + 1)) {
            (Some(&a), Some(&b)) if c + 1 < chunk_start.len() => (a, b),
            _ => (0, 0),
        };
        buffers.push((label, words(&base.words[a..b])));
    }
    buffers.push((
        "visibility field overlay id buffer",
        words(overlay.map_or(&[][..], |l| &l.words[..])),
    ));
    debug_assert_eq!(buffers.len(), GPU_BUFFERS as usize);
    Ok(GpuStructure {
        buffers,
        walk_iterations: WALK_ITERATIONS,
    })
}
