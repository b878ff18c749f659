//! One set of parallel subfields over a subset of the triangles, in flat arrays (paper Sections
//! 3.2 and 4): per direction, `n x n` tiles in CSR form, each tile either a plain list of
//! triangle ids or a tile BSP. Built direction by direction in parallel.
//!
//! Layout (every array a flat `Vec` of plain numbers, indexed with u32; the GPU reads the same):
//! - `tile_first[k * n^2 + ty * n + tx]` (`D n^2 + 1` entries): start of the tile's block in
//!   `ids`; the block ends where the next tile's starts (mask [`SPLIT`] off both). An empty tile
//!   costs this one offset.
//! - Bit 31 ([`SPLIT`]) set: the tile is split, and its block starts with a header of
//!   [`bsp::header_len`] words, so that one tile's lookup touches one region of memory: the
//!   split values as f32 bits (`z0, scale` for uniform slabs, the `L - 1` planes for median
//!   splits; [`Split::stride`]), then for each of the `L = 2^depth` leaves its end `E_l`,
//!   counted from the first word after the header `h`: leaf `l` is `ids[h + E_{l-1} .. h + E_l]`
//!   (`E_{-1} = 0`).
//! - Otherwise `ids[start .. end]` are the tile's triangles, in increasing index order.
//! - `boxes[i]` (u16) is the footprint of `ids[i]`'s triangle within its tile on a 16 x 16
//!   sub-grid ([`super::raster::sub_box`]); 0 for header words. Not in the paper: the tiles'
//!   lateral resolution is what bounds the candidates (the beam through a surface seen at a
//!   grazing angle holds many triangles), and this refines it per entry for two bytes
//!   (measured on the body: 68 exact tests per AO ray without it, 9.5 with it).

use super::bsp;
use super::raster::{clipped_z_range, for_each_tile, sub_box};
use super::{Frame, VlfSettings, EPS};
use glam::DVec3;
use rayon::prelude::*;

/// Flag in `tile_first` marking a split tile.
pub const SPLIT: u32 = 1 << 31;

/// The flat arrays of one layer (see the module doc).
#[derive(Clone, Debug, Default)]
pub struct Layer {
    /// Per tile, start in `ids` (bit 31: split); one more entry closes the last tile.
    pub tile_first: Vec<u32>,
    /// Triangle ids, and the header at the head of each split tile's block.
    pub ids: Vec<u32>,
    /// Per entry of `ids`, the footprint box of the triangle in its tile
    /// ([`super::raster::sub_box`]; 0 for header words).
    pub boxes: Vec<u16>,
    /// Triangles indexed (distinct).
    pub triangles: usize,
}

/// One direction's part before merging (offsets relative to its own arrays).
struct Part {
    tile_first: Vec<u32>,
    ids: Vec<u32>,
    boxes: Vec<u16>,
}

/// Asks the kernel to back `v`'s (not yet touched) capacity with transparent huge pages: a
/// query touches two random places of arrays of hundreds of MB, and with 4 KiB pages each costs
/// a TLB miss on top of the cache miss (measured: the tile lookup was a third of a query). A
/// no-op off Linux, or where the kernel declines.
fn huge_pages<T>(v: &Vec<T>) {
    #[cfg(target_os = "linux")]
    {
        const PAGE: usize = 4096;
        let bytes = v.capacity() * std::mem::size_of::<T>();
        if bytes < (4 << 20) {
            return;
        }
        let start = (v.as_ptr() as usize).div_ceil(PAGE) * PAGE;
        let end = (v.as_ptr() as usize + bytes) / PAGE * PAGE;
        if end > start {
            // SAFETY: the range lies inside `v`'s own allocation; MADV_HUGEPAGE only changes
            // how the kernel backs those pages, never their contents.
            unsafe {
                libc::madvise(start as *mut libc::c_void, end - start, libc::MADV_HUGEPAGE);
            }
        }
    }
    #[cfg(not(target_os = "linux"))]
    let _ = v;
}

impl Layer {
    /// Bytes the arrays occupy.
    pub fn bytes(&self) -> usize {
        4 * (self.tile_first.len() + self.ids.len()) + 2 * self.boxes.len()
    }

    /// Split tiles.
    pub fn split_tiles(&self) -> usize {
        self.tile_first.iter().filter(|f| *f & SPLIT != 0).count()
    }

    /// Builds the layer over triangles `subset` of `world`.
    pub fn build(world: &[[DVec3; 3]], subset: &[u32], frame: &Frame, settings: &VlfSettings) -> anyhow::Result<Layer> {
        let dirs = frame.directions.len();
        let parts: Vec<Part> = (0..dirs as u32)
            .into_par_iter()
            .map(|k| direction_part(k, world, subset, frame, settings))
            .collect();
        let total_ids: usize = parts.iter().map(|p| p.ids.len()).sum();
        anyhow::ensure!(
            total_ids < SPLIT as usize,
            "visibility field: {total_ids} tile entries exceed the 2^31 a u32 offset with a flag bit addresses; use fewer directions or tiles"
        );
        let mut layer = Layer {
            tile_first: Vec::with_capacity(parts.iter().map(|p| p.tile_first.len()).sum::<usize>() + 1),
            ids: Vec::with_capacity(total_ids),
            boxes: Vec::with_capacity(total_ids),
            triangles: subset.len(),
        };
        huge_pages(&layer.tile_first);
        huge_pages(&layer.ids);
        huge_pages(&layer.boxes);
        for p in parts {
            let base = layer.ids.len() as u32;
            layer.tile_first.extend(p.tile_first.iter().map(|f| f + base));
            layer.ids.extend_from_slice(&p.ids);
            layer.boxes.extend_from_slice(&p.boxes);
        }
        layer.tile_first.push(layer.ids.len() as u32);
        Ok(layer)
    }
}

/// Tile coordinates (x, y in tiles, z in ball units) of world point `p` for direction `k`.
#[inline]
pub fn to_tile(frame: &Frame, rot: &[DVec3; 3], p: DVec3) -> DVec3 {
    let q = p - frame.centre;
    let s = frame.inv_radius * frame.half_tiles;
    DVec3::new(
        rot[0].dot(q) * s + frame.half_tiles,
        rot[1].dot(q) * s + frame.half_tiles,
        rot[2].dot(q) * frame.inv_radius,
    )
}

fn direction_part(k: u32, world: &[[DVec3; 3]], subset: &[u32], frame: &Frame, settings: &VlfSettings) -> Part {
    let n = settings.tiles;
    let tiles = (n * n) as usize;
    let rot = frame.directions.rotation(k);
    let e = EPS * frame.half_tiles;
    let proj: Vec<[DVec3; 3]> = subset
        .iter()
        .map(|&t| world[t as usize].map(|p| to_tile(frame, &rot, p)))
        .collect();
    let mut pairs: Vec<(u32, u32)> = Vec::with_capacity(subset.len() * 4);
    for (i, p) in proj.iter().enumerate() {
        for_each_tile([p[0].truncate(), p[1].truncate(), p[2].truncate()], n, e, |tx, ty| {
            pairs.push((ty * n + tx, i as u32))
        });
    }
    let mut start = vec![0u32; tiles + 1];
    for &(t, _) in &pairs {
        start[t as usize + 1] += 1;
    }
    for t in 0..tiles {
        start[t + 1] += start[t];
    }
    let mut fill = start.clone();
    let mut sorted = vec![0u32; pairs.len()];
    for &(t, i) in &pairs {
        sorted[fill[t as usize] as usize] = i;
        fill[t as usize] += 1;
    }
    drop(pairs);
    let mut part = Part {
        tile_first: Vec::with_capacity(tiles),
        ids: Vec::with_capacity(sorted.len()),
        boxes: Vec::with_capacity(sorted.len()),
    };
    let (mut items, mut scratch) = (Vec::new(), Vec::new());
    for t in 0..tiles {
        let list = &sorted[start[t] as usize..start[t + 1] as usize];
        let at = part.ids.len() as u32;
        if settings.depth > 0 && list.len() > settings.leaf_size as usize {
            let (tx, ty) = (t as u32 % n, t as u32 / n);
            items.clear();
            items.extend(list.iter().map(|&i| {
                let (lo, hi) = clipped_z_range(&proj[i as usize], tx, ty, e);
                (
                    subset[i as usize],
                    lo - EPS,
                    hi + EPS,
                    sub_box(&proj[i as usize], tx, ty, e),
                )
            }));
            if bsp::build(
                &items,
                settings.split,
                settings.depth,
                &mut part.ids,
                &mut part.boxes,
                &mut scratch,
            ) {
                part.tile_first.push(at | SPLIT);
                continue;
            }
        }
        part.tile_first.push(at);
        let (tx, ty) = (t as u32 % n, t as u32 / n);
        part.ids.extend(list.iter().map(|&i| subset[i as usize]));
        part.boxes
            .extend(list.iter().map(|&i| sub_box(&proj[i as usize], tx, ty, e)));
    }
    part
}
