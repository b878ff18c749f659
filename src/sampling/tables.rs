//! The tables the screen-arranged schemes read, packed into one buffer for the GPU, which reads
//! exactly the values the CPU computes from ([`super::pmj02`], [`super::bluenoise`],
//! [`super::stbn`]).
//!
//! Layout (u32 words): a header `[pmj02 offset, mask offset, D, n_1, offset_1, .., n_D,
//! offset_D]` (room for [`MAX_COUNTS`] pairs), then at [`POINTS_HEADER`] a points file's
//! header (data offset, layout, points per pixel, tile side, domain, mask offset), then at
//! [`STBN_HEADER`] the STBN masks' offset ([`HEADER_WORDS`] words in all); then the regions:
//! the pmj02 sequence (x, y per point, 24-bit), the two masks ([`TILE`]^2 offsets each,
//! 24-bit), one scramble table ([`TILE`]^2 seeds) per table ray count `n_i` the frame uses
//! ([`bluenoise::table_rays`]), the points file's points and mask ([`super::points`]), and the
//! two STBN masks (each [`stbn::DEPTH`] slices of [`stbn::SIDE`]^2 offsets, 24-bit, at
//! `(t * SIDE + y) * SIDE + x` as [`stbn::masks`] holds them; stbn-cp). A region the frame's
//! schemes do not read is left out (its offset is 0 and nothing reads it).

use super::bluenoise::{self, TILE};
use super::pmj02;
use super::points::{Domain, Layout};
use super::stbn;
use super::DiskScheme;

/// Most distinct scramble tables one frame carries: one per light and one for the ambient
/// pass, so no frame can ask for more.
pub const MAX_COUNTS: usize = super::MAX_LIGHTS + 1;

/// Where the points header starts: after the pmj02 and mask offsets and the count table.
pub const POINTS_HEADER: usize = 3 + 2 * MAX_COUNTS;

/// Words of the points header: data offset, layout, points per pixel, tile side, domain, mask
/// offset (render/gpu/shaders/sampling.wgsl, `points_point`).
const POINTS_WORDS: usize = 6;

/// Where the STBN masks' offset is (render/gpu/shaders/sampling.wgsl, `stbn_offset`): after
/// the points header.
pub const STBN_HEADER: usize = POINTS_HEADER + POINTS_WORDS;

/// Words of the whole header, before the first region.
pub const HEADER_WORDS: usize = STBN_HEADER + 1;

/// The WGSL constants of the layout, prepended to the shaders with the scheme ids.
pub fn wgsl_prelude() -> String {
    format!(
        "const PMJ02_POINTS: u32 = {}u;\nconst BLUE_TILE: u32 = {}u;\nconst TABLE_COUNTS: u32 = {}u;\nconst POINTS_HEADER: u32 = {}u;\n\
         const STBN_HEADER: u32 = {}u;\nconst STBN_SIDE: u32 = {}u;\nconst STBN_DEPTH: u32 = {}u;\n",
        pmj02::MAX_POINTS,
        TILE,
        MAX_COUNTS,
        POINTS_HEADER,
        STBN_HEADER,
        stbn::SIDE,
        stbn::DEPTH
    )
}

/// The tables for a frame whose schemes sample `uses` (scheme, ray count) pairs; the header
/// alone, all zeros, when none reads a table.
pub fn pack(uses: &[(DiskScheme, u32)]) -> Vec<u32> {
    let mut counts: Vec<u32> = uses
        .iter()
        .filter(|(s, _)| matches!(s, DiskScheme::SobolBluenoise | DiskScheme::SobolBluenoiseT))
        .map(|&(_, n)| bluenoise::table_rays(n))
        .collect();
    counts.sort_unstable();
    counts.dedup();
    assert!(
        counts.len() <= MAX_COUNTS,
        "a frame's lights and ambient pass use at most {MAX_COUNTS} ray counts"
    );
    let needs = |s: DiskScheme| uses.iter().any(|u| u.0 == s);
    let mut out = vec![0u32; HEADER_WORDS];
    if needs(DiskScheme::Pmj02) {
        out[0] = out.len() as u32;
        out.extend(pmj02::shared().iter().flatten());
    }
    if needs(DiskScheme::BluenoiseCp) {
        out[1] = out.len() as u32;
        let fix = |v: f64| (v * (1u32 << 24) as f64) as u32;
        for m in bluenoise::masks() {
            out.extend(m.iter().map(|&v| fix(v)));
        }
    }
    out[2] = counts.len() as u32;
    for (i, &n) in counts.iter().enumerate() {
        let offset = out.len() as u32;
        out[3 + 2 * i] = n;
        out[4 + 2 * i] = offset;
        out.extend(bluenoise::scrambles(n).iter());
    }
    let mut sets = uses.iter().filter_map(|(s, _)| match s {
        DiskScheme::Points(id) => Some(*id),
        _ => None,
    });
    if let Some(id) = sets.next() {
        assert!(sets.all(|other| other == id), "a frame samples one points file");
        let set = id.loaded();
        let (layout, side) = match set.layout {
            Layout::Shared => (0, 0),
            Layout::Tile(side) => (1, side),
            Layout::Mask(side) => (2, side),
        };
        let h = POINTS_HEADER;
        out[h] = out.len() as u32;
        out.extend(set.points.iter().flatten());
        out[h + 1] = layout;
        out[h + 2] = set.count;
        out[h + 3] = side;
        out[h + 4] = (set.domain == Domain::Disk) as u32;
        out[h + 5] = out.len() as u32;
        out.extend(set.offsets.iter().flatten());
    }
    if needs(DiskScheme::StbnCp) {
        out[STBN_HEADER] = out.len() as u32;
        // The 24-bit values stbn::offset adds, exactly: (rank + 0.5) / SIDE^2 scaled by 2^24.
        let fix = |v: f64| (v * (1u32 << 24) as f64) as u32;
        for m in stbn::masks() {
            out.extend(m.iter().map(|&v| fix(v)));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_layout_points_at_each_table() {
        let t = pack(&[
            (DiskScheme::Pmj02, 16),
            (DiskScheme::SobolBluenoise, 4),
            (DiskScheme::SobolBluenoise, 16),
        ]);
        let pmj = t[0] as usize;
        assert_eq!(&t[pmj..pmj + 2], &pmj02::shared()[0][..]);
        assert_eq!(t[1], 0, "no mask asked for");
        assert_eq!((t[2], t[3], t[5]), (2, 4, 16));
        let sixteen = t[6] as usize;
        assert_eq!(&t[sixteen..sixteen + TILE * TILE], bluenoise::scrambles(16));
        assert_eq!(t[STBN_HEADER], 0, "no STBN asked for");
        assert_eq!(pack(&[(DiskScheme::Uniform, 16)]), vec![0; HEADER_WORDS]);
    }

    /// The STBN region holds both masks, slice by slice, as the 24-bit values [`stbn::offset`]
    /// adds to the tile seed's shift; it comes only with stbn-cp.
    #[test]
    fn the_stbn_region_holds_both_masks() {
        let t = pack(&[(DiskScheme::BluenoiseCp, 4), (DiskScheme::StbnCp, 4)]);
        let (base, voxels) = (t[STBN_HEADER] as usize, stbn::SIDE * stbn::SIDE * stbn::DEPTH);
        assert!(base >= HEADER_WORDS && t[1] != 0);
        assert_eq!(t.len(), base + 2 * voxels);
        let tile_seed = bluenoise::tile_seed(5, 1);
        let (sx, sy) = bluenoise::cp_shift(tile_seed);
        let shift = stbn::time_shift(tile_seed) as usize;
        for (x, y, frame) in [(0u32, 0u32, 0u32), (9, 4, 3), (63, 63, 31), (100, 7, 77)] {
            let slice = (frame as usize + shift) % stbn::DEPTH;
            let i = slice * stbn::SIDE * stbn::SIDE + bluenoise::tile_index_in(x, y, tile_seed, stbn::SIDE as u32);
            let want = (
                (t[base + i] + sx) & 0x00ff_ffff,
                (t[base + voxels + i] + sy) & 0x00ff_ffff,
            );
            assert_eq!(stbn::offset(x, y, frame, tile_seed), want, "({x}, {y}) frame {frame}");
        }
        assert_eq!(pack(&[(DiskScheme::BluenoiseCp, 4)])[STBN_HEADER], 0);
        assert!(wgsl_prelude().contains(&format!("const STBN_HEADER: u32 = {STBN_HEADER}u;")));
    }
}
