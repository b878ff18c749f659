//! One set of parallel subfields over a subset of the triangles, in flat arrays (paper Sections
//! 3.2 and 4): per direction, `n x n` tiles in CSR form, each tile either a plain list of
//! triangle entries or a tile BSP. Built direction by direction in parallel.
//!
//! Layout (flat `Vec`s of plain numbers, indexed with u32; the GPU reads the same words):
//! - [`Offsets`]: where tile `k = dir n^2 + ty n + tx` starts in `words`, and whether it is
//!   split; its block ends where tile `k + 1`'s starts. Where every tile starts under 2^15
//!   words after its row's first (all meshes here; a row's last block may run longer), a u32
//!   per row of tiles and a u16 per tile; otherwise a u32 per tile. An empty tile costs its
//!   offset alone.
//! - `words`: the blocks. A plain tile's block is its entries, in increasing triangle order. A
//!   split tile's starts with a header of [`bsp::header_len`] words (the split values as f32
//!   bits, `z0, scale` for uniform slabs or the `L - 1` planes for median splits,
//!   [`super::Split::stride`]; then two words per leaf, [`bsp::LeafBounds`]), then each leaf's
//!   entries, so one tile's lookup touches one region of memory.
//! - An entry is the triangle index and its footprint box within the tile on a 16 x 16
//!   sub-grid ([`super::raster::sub_box`]): one word `id | box << 16` when every index of the
//!   layer fits 16 bits (`id` 0xffff marks a removed triangle); otherwise entries go in pairs
//!   of three words `id0, id1, box0 | box1 << 16` (`u32::MAX` removed; a block with an odd
//!   count ends on a removed entry), six bytes each ([`id_word`], [`box_word`]). The box is
//!   not in the paper: the tiles' lateral resolution is what bounds the candidates (the beam
//!   through a surface seen at a grazing angle holds many triangles), and this refines it per
//!   entry for two bytes (measured on the body: 68 exact tests per AO ray without it, 9.5 with
//!   it); beside the id it costs no second cache line.
//!
//! Against the first layout (a u32 id with the leaf range in its top bits and a u16 box in a
//! second array, 6 bytes per entry; a u32 per tile) this takes 63-71 % of the bytes on the cow,
//! man and body at depths 2-4.

use super::bsp;
use super::raster::{clipped_z_range, for_each_tile, sub_box};
use super::{UnitBall, VlfSettings, EPS};
use glam::DVec3;
use rayon::prelude::*;

/// Largest triangle index a narrow (one-word) entry holds; the next value marks a removed one.
const NARROW_DEAD: u32 = 0xffff;

/// Where each tile's block starts in a layer's `words`, and which tiles are split.
#[derive(Clone, Debug)]
pub enum Offsets {
    /// Per row of tiles (`dir n + ty`; one more closes the last) its first word; per tile (one
    /// more, 0, closes the last) its start relative to its row's, bit 15 marking a split tile.
    Rows {
        /// Tiles per side.
        n: usize,
        /// First word of each row of tiles.
        row: Vec<u32>,
        /// Offset of each tile from its row's first word, bit 15 = split.
        tile: Vec<u16>,
    },
    /// Per tile (one more closes the last) its first word, bit 31 marking a split tile.
    Flat(Vec<u32>),
}

impl Default for Offsets {
    fn default() -> Self {
        Offsets::Flat(Vec::new())
    }
}

/// Split flag of a [`Offsets::Flat`] offset.
pub const SPLIT: u32 = 1 << 31;
/// Split flag of a [`Offsets::Rows`] tile offset.
const ROW_SPLIT: u16 = 1 << 15;

impl Offsets {
    /// Words `start..end` of tile `k`'s block, and whether the tile is split.
    #[inline(always)]
    pub fn block(&self, k: usize) -> (usize, usize, bool) {
        match self {
            Offsets::Rows { n, row, tile } => {
                let (a, b) = (tile[k], tile[k + 1]);
                (
                    (row[k / n] + (a & !ROW_SPLIT) as u32) as usize,
                    (row[(k + 1) / n] + (b & !ROW_SPLIT) as u32) as usize,
                    a & ROW_SPLIT != 0,
                )
            }
            Offsets::Flat(first) => {
                let (a, b) = (first[k], first[k + 1]);
                ((a & !SPLIT) as usize, (b & !SPLIT) as usize, a & SPLIT != 0)
            }
        }
    }

    /// Hints that tile `k`'s offsets are read soon.
    #[inline(always)]
    pub fn prefetch(&self, k: usize) {
        match self {
            Offsets::Rows { n, row, tile } => {
                super::bundle::prefetch(&row[k / n]);
                super::bundle::prefetch(&tile[k]);
            }
            Offsets::Flat(first) => super::bundle::prefetch(&first[k]),
        }
    }

    /// Tiles (all directions).
    pub fn tiles(&self) -> usize {
        match self {
            Offsets::Rows { tile, .. } => tile.len().saturating_sub(1),
            Offsets::Flat(first) => first.len().saturating_sub(1),
        }
    }

    /// Bytes the offsets occupy.
    pub fn bytes(&self) -> usize {
        match self {
            Offsets::Rows { row, tile, .. } => 4 * row.len() + 2 * tile.len(),
            Offsets::Flat(first) => 4 * first.len(),
        }
    }

    /// Every tile's first word with [`SPLIT`], and one more closing the last (the GPU's form).
    pub fn flat(&self) -> Vec<u32> {
        match self {
            Offsets::Flat(first) => first.clone(),
            Offsets::Rows { .. } => {
                // `compact` makes rows only for layers with tiles.
                let last = self.block(self.tiles() - 1).1 as u32;
                (0..self.tiles())
                    .map(|k| {
                        let (start, _, split) = self.block(k);
                        start as u32 | if split { SPLIT } else { 0 }
                    })
                    .chain([last])
                    .collect()
            }
        }
    }

    /// The compact form of `flat` (tiles per side `n`) where every row's offsets fit 15 bits.
    fn compact(flat: Vec<u32>, n: usize) -> Offsets {
        let tiles = flat.len() - 1;
        let start = |k: usize| flat[k] & !SPLIT;
        let fits = (0..tiles).all(|k| start(k) - start(k / n * n) < ROW_SPLIT as u32);
        if !fits || tiles == 0 || tiles % n != 0 {
            return Offsets::Flat(flat);
        }
        let mut row: Vec<u32> = (0..tiles / n).map(|r| start(r * n)).collect();
        row.push(start(tiles));
        let mut tile: Vec<u16> = Vec::with_capacity(tiles + 1);
        huge_pages(&tile);
        tile.extend(
            (0..tiles).map(|k| (start(k) - row[k / n]) as u16 | if flat[k] & SPLIT != 0 { ROW_SPLIT } else { 0 }),
        );
        tile.push(0);
        Offsets::Rows { n, row, tile }
    }
}

/// The flat arrays of one layer (see the module doc).
#[derive(Clone, Debug, Default)]
pub struct Layer {
    /// Each tile's block in `words`.
    pub offsets: Offsets,
    /// The blocks: split-tile headers and entries.
    pub words: Vec<u32>,
    /// Whether entries go in three-word pairs (some triangle index exceeds 16 bits).
    pub wide: bool,
    /// Words of split-tile headers (the rest are entries).
    pub header_words: usize,
    /// Triangles indexed (distinct).
    pub triangles: usize,
}

/// One direction's part before merging (offsets relative to its own words, bit 31 = split).
struct Part {
    tile_first: Vec<u32>,
    words: Vec<u32>,
    header_words: usize,
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
        self.offsets.bytes() + 4 * self.words.len()
    }

    /// Bytes per part: tile offsets, split-tile headers, entries.
    pub fn parts(&self) -> [(&'static str, usize); 3] {
        [
            ("tile offsets", self.offsets.bytes()),
            ("split headers", 4 * self.header_words),
            ("entries", 4 * (self.words.len() - self.header_words)),
        ]
    }

    /// Entries the layer stores (a wide block's padding entry included).
    pub fn entries(&self) -> usize {
        entries_in(self.words.len() - self.header_words, self.wide)
    }

    /// Split tiles.
    pub fn split_tiles(&self) -> usize {
        (0..self.offsets.tiles()).filter(|&k| self.offsets.block(k).2).count()
    }

    /// Marks the entry whose id is the word at `at` as a removed triangle.
    pub fn kill_at(&mut self, at: usize) {
        kill(&mut self.words[at], self.wide);
    }

    /// Builds the layer over triangles `subset` of `world`.
    pub fn build(
        world: &[[DVec3; 3]],
        subset: &[u32],
        frame: &UnitBall,
        settings: &VlfSettings,
    ) -> anyhow::Result<Layer> {
        let dirs = frame.directions.len();
        let wide = subset.iter().any(|&t| t >= NARROW_DEAD);
        let parts: Vec<Part> = (0..dirs as u32)
            .into_par_iter()
            .map(|k| direction_part(k, world, subset, frame, settings, wide))
            .collect();
        let total: usize = parts.iter().map(|p| p.words.len()).sum();
        anyhow::ensure!(
            total < SPLIT as usize,
            "visibility field: {total} words of tile entries exceed the 2^31 a u32 offset with a flag bit addresses; use fewer directions or tiles"
        );
        let mut tile_first = Vec::with_capacity(parts.iter().map(|p| p.tile_first.len()).sum::<usize>() + 1);
        let mut words = Vec::with_capacity(total);
        huge_pages(&words);
        let mut header_words = 0;
        for p in parts {
            let base = words.len() as u32;
            tile_first.extend(p.tile_first.iter().map(|f| f + base));
            words.extend_from_slice(&p.words);
            header_words += p.header_words;
        }
        tile_first.push(words.len() as u32);
        Ok(Layer {
            offsets: Offsets::compact(tile_first, settings.tiles as usize),
            words,
            wide,
            header_words,
            triangles: subset.len(),
        })
    }
}

/// Marks the entry whose first word is `w` removed.
#[inline]
pub fn kill(w: &mut u32, wide: bool) {
    *w |= dead_id(wide);
}

/// The id field of the entry whose first word is `w`: a triangle index, or all ones
/// ([`dead_id`]) for a removed one.
#[inline(always)]
pub fn entry_id(w: u32, wide: bool) -> u32 {
    if wide {
        w
    } else {
        w & NARROW_DEAD
    }
}

/// The id field of a removed entry.
#[inline(always)]
pub fn dead_id(wide: bool) -> u32 {
    if wide {
        u32::MAX
    } else {
        NARROW_DEAD
    }
}

/// The word holding entry `i`'s id, counted from the first word of its block's entries: the
/// entry's own word, or in a wide layer the `i % 2`-th word of its pair.
#[inline(always)]
pub fn id_word(i: usize, wide: bool) -> usize {
    if wide {
        3 * (i >> 1) + (i & 1)
    } else {
        i
    }
}

/// The word holding entry `i`'s box and the shift that brings it to the low bits (bits above
/// the box's 16 may remain).
#[inline(always)]
pub fn box_word(i: usize, wide: bool) -> (usize, u32) {
    if wide {
        (3 * (i >> 1) + 2, 16 * (i as u32 & 1))
    } else {
        (i, 16)
    }
}

/// Entries in `words` words of entries (a wide block's padding entry included).
#[inline(always)]
pub fn entries_in(words: usize, wide: bool) -> usize {
    if wide {
        2 * (words / 3)
    } else {
        words
    }
}

/// Calls `f` with every id word among `words` (a block's entries, from its first).
pub fn for_each_id(words: &mut [u32], wide: bool, f: impl FnMut(&mut u32)) {
    if wide {
        words.chunks_exact_mut(3).flat_map(|pair| &mut pair[..2]).for_each(f);
    } else {
        words.iter_mut().for_each(f);
    }
}

/// Appends the entry for triangle `id` with footprint `b` (a wide one as two words, `id, b`,
/// until [`pack_pairs`] closes its block).
#[inline]
fn push_entry(words: &mut Vec<u32>, id: u32, b: u16, wide: bool) {
    if wide {
        words.extend([id, b as u32]);
    } else {
        words.push(id | (b as u32) << 16);
    }
}

/// Rewrites the two-word entries from word `from` on in pairs of three words (see the module
/// doc), padding an odd count with a removed entry. In place: pair `p` is read from words
/// `4p..4p + 4` before words `3p..3p + 3` are written.
fn pack_pairs(words: &mut Vec<u32>, from: usize) {
    let entries = (words.len() - from) / 2;
    if entries % 2 == 1 {
        words.extend([u32::MAX, 0]);
    }
    for p in 0..entries.div_ceil(2) {
        let r = from + 4 * p;
        let [id0, b0, id1, b1] = [words[r], words[r + 1], words[r + 2], words[r + 3]];
        let w = from + 3 * p;
        words[w..w + 3].copy_from_slice(&[id0, id1, b0 | b1 << 16]);
    }
    words.truncate(from + 3 * entries.div_ceil(2));
}

/// Tile coordinates (x, y in tiles, z in ball units) of world point `p` for direction `k`.
#[inline]
pub fn to_tile(frame: &UnitBall, rot: &[DVec3; 3], p: DVec3) -> DVec3 {
    let q = p - frame.centre;
    let s = frame.inv_radius * frame.half_tiles;
    DVec3::new(
        rot[0].dot(q) * s + frame.half_tiles,
        rot[1].dot(q) * s + frame.half_tiles,
        rot[2].dot(q) * frame.inv_radius,
    )
}

fn direction_part(
    k: u32,
    world: &[[DVec3; 3]],
    subset: &[u32],
    frame: &UnitBall,
    settings: &VlfSettings,
    wide: bool,
) -> Part {
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
        words: Vec::with_capacity(sorted.len() * (1 + usize::from(wide))),
        header_words: 0,
    };
    let header = bsp::header_len(settings.split, 1 << settings.depth);
    let push = |words: &mut Vec<u32>, id: u32, b: u16| push_entry(words, id, b, wide);
    let (mut items, mut scratch) = (Vec::new(), Vec::new());
    for t in 0..tiles {
        let list = &sorted[start[t] as usize..start[t + 1] as usize];
        let at = part.words.len() as u32;
        let (tx, ty) = (t as u32 % n, t as u32 / n);
        if settings.depth > 0 && list.len() > settings.leaf_size as usize {
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
                &mut part.words,
                &mut scratch,
                push,
            ) {
                part.tile_first.push(at | SPLIT);
                part.header_words += header;
                if wide {
                    pack_pairs(&mut part.words, at as usize + header);
                }
                continue;
            }
        }
        part.tile_first.push(at);
        for &i in list {
            push(
                &mut part.words,
                subset[i as usize],
                sub_box(&proj[i as usize], tx, ty, e),
            );
        }
        if wide {
            pack_pairs(&mut part.words, at as usize);
        }
    }
    part
}

#[cfg(test)]
mod tests {
    use super::{box_word, entries_in, for_each_id, id_word, pack_pairs, push_entry, Offsets, SPLIT};

    /// Wide entries packed in pairs read back by [`id_word`] and [`box_word`] after a header
    /// word, six bytes each; an odd count ends on a removed entry that [`for_each_id`] visits
    /// like any other id.
    #[test]
    fn wide_pairs_take_six_bytes_and_read_back() {
        for m in [0usize, 1, 2, 5, 6] {
            let mut words = vec![0xdead_beef];
            let entry = |i: usize| (0x1_0000 + 7 * i as u32, 0x1234u16.wrapping_add(i as u16 * 0x0f0f));
            for i in 0..m {
                let (id, b) = entry(i);
                push_entry(&mut words, id, b, true);
            }
            pack_pairs(&mut words, 1);
            assert_eq!(words[0], 0xdead_beef, "m = {m}: the header is untouched");
            let region = &words[1..];
            assert_eq!(region.len(), 3 * m.div_ceil(2), "m = {m}");
            assert_eq!(entries_in(region.len(), true), m + m % 2);
            for i in 0..m {
                let (id, b) = entry(i);
                let (at, shift) = box_word(i, true);
                assert_eq!(region[id_word(i, true)], id, "m = {m}, entry {i}");
                assert_eq!((region[at] >> shift) & 0xffff, b as u32, "m = {m}, entry {i}");
            }
            if m % 2 == 1 {
                assert_eq!(region[id_word(m, true)], u32::MAX, "m = {m}: padding is removed");
            }
            let mut ids = Vec::new();
            for_each_id(&mut words[1..], true, |w| ids.push(*w));
            let want: Vec<u32> = (0..m)
                .map(|i| entry(i).0)
                .chain((m % 2 == 1).then_some(u32::MAX))
                .collect();
            assert_eq!(ids, want, "m = {m}");
        }
    }

    /// Every tile's block and split flag read back from `o` as written in `flat`.
    fn same_blocks(o: &Offsets, flat: &[u32]) {
        assert_eq!(o.tiles(), flat.len() - 1);
        for k in 0..o.tiles() {
            let want = (
                (flat[k] & !SPLIT) as usize,
                (flat[k + 1] & !SPLIT) as usize,
                flat[k] & SPLIT != 0,
            );
            assert_eq!(o.block(k), want, "tile {k}");
        }
        assert_eq!(o.flat(), flat);
    }

    /// A row whose last tile starts 32767 words after the row's first fits 15 bits (a split
    /// flag beside it included); one at 32768 falls back to u32 offsets; a row spanning more
    /// than 2^15 words in its last tile still fits.
    #[test]
    fn rows_at_the_15_bit_bound() {
        // 2 tiles per side, 1 direction: rows (0, 1) and (2, 3).
        let fit = vec![0, 32_767 | SPLIT, 100_000, 100_000 + 32_767, 200_000];
        let o = Offsets::compact(fit.clone(), 2);
        assert!(matches!(o, Offsets::Rows { .. }));
        same_blocks(&o, &fit);
        let over = vec![0, 32_768 | SPLIT, 100_000, 100_001 | SPLIT, 100_002];
        let o = Offsets::compact(over.clone(), 2);
        assert!(matches!(o, Offsets::Flat(_)));
        same_blocks(&o, &over);
        let second_row_over = vec![5 | SPLIT, 6, 7, 7 + 32_768, 7 + 32_769];
        assert!(matches!(Offsets::compact(second_row_over, 2), Offsets::Flat(_)));
        let empty_tiles = vec![9, 9, 9 | SPLIT, 9, 9];
        let o = Offsets::compact(empty_tiles.clone(), 2);
        same_blocks(&o, &empty_tiles);
    }
}
