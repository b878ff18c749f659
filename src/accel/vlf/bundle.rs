//! Bundles through the field (the paper's Section 9 question, ray bundling): a bundle's rays
//! are put in the order of the stored direction they use and the tile they enter first, so
//! consecutive walks read the same tile headers and leaf lists while they are in cache, and the
//! headers and first entries of the walks a few places ahead are prefetched. The walk of each ray
//! is [`VisibilityField::any_hit`]'s, so answers and work counters equal the single queries';
//! only the order of memory traffic changes.

use super::query::{tile_cell, TileRay};
use super::VisibilityField;
use crate::accel::Query;

/// How many walks ahead a tile header is prefetched; its first entries are prefetched at half
/// that distance, once the header is likely in cache.
const AHEAD: usize = 8;

/// A hint that `value` is read soon.
#[inline(always)]
pub(super) fn prefetch<T>(value: &T) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: a prefetch only hints the cache; it cannot fault and changes no value.
    unsafe {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        _mm_prefetch::<_MM_HINT_T0>(value as *const T as *const i8);
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = value;
}

impl VisibilityField {
    /// The header index (direction x tile) of the tile `ray` enters first.
    fn entry_tile(&self, ray: &TileRay) -> usize {
        let n = self.settings.tiles as usize;
        let (x, y) = (ray.o.x + ray.d.x * ray.t0, ray.o.y + ray.d.y * ray.t0);
        ray.dir as usize * n * n + tile_cell(y, n) * n + tile_cell(x, n)
    }

    /// Any hit for each query, walked in (direction, entry tile) order with prefetching.
    pub fn any_hits(&self, queries: &[Query], hits: &mut [bool]) {
        let rays: Vec<Option<TileRay>> = queries.iter().map(|q| self.tile_ray(q.origin, q.dir, q.tmax)).collect();
        let mut order: Vec<(usize, u32)> = rays
            .iter()
            .enumerate()
            .filter_map(|(i, r)| r.as_ref().map(|r| (self.entry_tile(r), i as u32)))
            .collect();
        order.sort_unstable();
        hits.fill(false);
        let overlay = !self.overlay_ids.is_empty();
        let offsets = &self.base.offsets;
        for (p, &(_, i)) in order.iter().enumerate() {
            if let Some(&(k, _)) = order.get(p + AHEAD) {
                offsets.prefetch(k);
            }
            if let Some(&(k, _)) = order.get(p + AHEAD / 2) {
                if let Some(w) = self.base.words.get(offsets.block(k).0) {
                    prefetch(w);
                }
            }
            let (q, ray) = (
                &queries[i as usize],
                rays[i as usize].as_ref().expect("ordered rays exist"),
            );
            hits[i as usize] = self.any_in(&self.base, ray, q.origin, q.dir, q.tmax, q.skip)
                || (overlay && self.any_in(&self.overlay, ray, q.origin, q.dir, q.tmax, q.skip));
        }
    }
}
