//! Dynamic updates (paper Section 8, "Dynamic scenes": visit every parallel subfield,
//! rasterise the object as at build time, remove its id, change the geometry, insert it again).
//!
//! The flat base arrays cannot grow in place, so removal rasterises the object's triangles in
//! every direction and marks their entries removed in the tiles they cover (no array
//! changes size), and insertion puts the object into the overlay layer, a second field over
//! only the inserted or moved triangles, rebuilt from those alone (cost proportional to them,
//! not to the scene). Objects must stay inside the build's ball: anything else needs a full
//! rebuild, and is refused.

use super::layer::{entry_id, for_each_id, kill, to_tile, Layer};
use super::raster::for_each_tile;
use super::{VisibilityField, EPS};
use glam::DVec3;
use rayon::prelude::*;

impl VisibilityField {
    /// Triangles of `object` currently indexed (base or overlay).
    fn live_triangles(&self, object: u32) -> Vec<u32> {
        let overlay: std::collections::BTreeSet<u32> = self.overlay_ids.iter().copied().collect();
        (0..self.world.len() as u32)
            .filter(|&i| self.object_of[i as usize] == object && (self.in_base[i as usize] || overlay.contains(&i)))
            .collect()
    }

    /// Marks `tris` (all in the base layer) removed in every tile that lists them.
    fn kill_in_base(&mut self, tris: &[u32]) {
        if tris.is_empty() {
            return;
        }
        let n = self.settings.tiles;
        let n2 = (n * n) as usize;
        let e = EPS * self.frame.half_tiles;
        let dirs = self.frame.directions.len();
        let offsets = &self.base.offsets;
        let wide = self.base.wide;
        // Disjoint per-direction slices of `words`.
        let mut slices = Vec::with_capacity(dirs);
        let mut rest: &mut [u32] = &mut self.base.words;
        let mut at = 0usize;
        for k in 0..dirs {
            let end = offsets.block((k + 1) * n2 - 1).1;
            let (head, tail) = rest.split_at_mut(end - at);
            slices.push((k, at, head));
            rest = tail;
            at = end;
        }
        let (frame, world) = (&self.frame, &self.world);
        let header = super::bsp::header_len(self.settings.split, 1 << self.settings.depth);
        slices.into_par_iter().for_each(|(k, base, words)| {
            let rot = frame.directions.rotation(k as u32);
            for &t in tris {
                let p = world[t as usize].map(|v| to_tile(frame, &rot, v).truncate());
                for_each_tile(p, n, e, |tx, ty| {
                    let (start, end, split) = offsets.block(k * n2 + (ty * n + tx) as usize);
                    // A split tile's header (split values and leaf bounds) holds no triangles.
                    let s = start - base + if split { header } else { 0 };
                    for_each_id(&mut words[s..end - base], wide, |w| {
                        if entry_id(*w, wide) == t {
                            kill(w, wide);
                        }
                    });
                });
            }
        });
        for &t in tris {
            self.in_base[t as usize] = false;
        }
    }

    fn rebuild_overlay(&mut self) -> anyhow::Result<()> {
        self.overlay_ids.sort_unstable();
        self.overlay = if self.overlay_ids.is_empty() {
            Layer::default()
        } else {
            Layer::build(&self.world, &self.overlay_ids, &self.frame, &self.settings)?
        };
        Ok(())
    }

    fn check_inside(&self, positions: &[[DVec3; 3]]) -> anyhow::Result<()> {
        let r = self.frame.radius;
        for p in positions.iter().flatten() {
            anyhow::ensure!(
                p.is_finite() && p.distance(self.frame.centre) <= r,
                "visibility field: {p} lies outside the ball the field was built in (centre {}, radius {r}): rebuild it",
                self.frame.centre
            );
        }
        Ok(())
    }

    /// Removes every triangle of `object` from the field; returns how many.
    pub fn remove_object(&mut self, object: u32) -> anyhow::Result<usize> {
        let live = self.live_triangles(object);
        let in_base: Vec<u32> = live.iter().copied().filter(|&t| self.in_base[t as usize]).collect();
        self.kill_in_base(&in_base);
        let before = self.overlay_ids.len();
        self.overlay_ids.retain(|&t| self.object_of[t as usize] != object);
        if self.overlay_ids.len() != before {
            self.rebuild_overlay()?;
        }
        Ok(live.len())
    }

    /// Adds a new object's triangles (indices continue the input order); returns their indices.
    pub fn insert_object(&mut self, object: u32, positions: &[[DVec3; 3]]) -> anyhow::Result<std::ops::Range<u32>> {
        self.check_inside(positions)?;
        let first = self.world.len() as u32;
        anyhow::ensure!(
            (first as usize + positions.len()) < u32::MAX as usize,
            "visibility field: {} triangles do not fit u32 indices",
            first as usize + positions.len()
        );
        self.world.extend_from_slice(positions);
        self.tri.extend(positions.iter().flat_map(super::query::pack));
        self.object_of.extend(std::iter::repeat_n(object, positions.len()));
        self.in_base.extend(std::iter::repeat_n(false, positions.len()));
        let last = self.world.len() as u32;
        self.overlay_ids.extend(first..last);
        self.rebuild_overlay()?;
        Ok(first..last)
    }

    /// Moves `object` by applying `f` to each of its corners (triangle indices unchanged).
    pub fn move_object(&mut self, object: u32, f: impl Fn(DVec3) -> DVec3) -> anyhow::Result<usize> {
        let live = self.live_triangles(object);
        let moved: Vec<[DVec3; 3]> = live.iter().map(|&t| self.world[t as usize].map(&f)).collect();
        self.check_inside(&moved)?;
        let in_base: Vec<u32> = live.iter().copied().filter(|&t| self.in_base[t as usize]).collect();
        self.kill_in_base(&in_base);
        for (&t, p) in live.iter().zip(moved) {
            self.world[t as usize] = p;
            self.tri[9 * t as usize..9 * t as usize + 9].copy_from_slice(&super::query::pack(&p));
        }
        self.overlay_ids.extend(in_base);
        self.rebuild_overlay()?;
        Ok(live.len())
    }
}
