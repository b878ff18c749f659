//! The tables the screen-arranged schemes read, packed into one buffer for the GPU, which reads
//! exactly the values the CPU computes from ([`super::pmj02`], [`super::bluenoise`]).
//!
//! Layout (u32 words): a header `[pmj02 offset, mask offset, D, n_1, offset_1, .., n_D,
//! offset_D]` (room for [`MAX_COUNTS`] pairs), then at [`POINTS_HEADER`] a points file's
//! header (data offset, layout, points per pixel, tile side, domain, mask offset); then the
//! regions: the pmj02 sequence (x, y per point, 24-bit), the two masks ([`TILE`]^2 offsets
//! each, 24-bit), one scramble table ([`TILE`]^2 seeds) per table ray count `n_i` the frame uses
//! ([`bluenoise::table_rays`]), and the points file's points and mask ([`super::points`]). A
//! region the frame's schemes do not read is left out (its offset is 0 and nothing reads it).

use super::bluenoise::{self, TILE};
use super::pmj02;
use super::points::{Domain, Layout};
use super::DiskScheme;

/// Most distinct scramble tables one frame carries: one per light and one for the ambient
/// pass, so no frame can ask for more.
pub const MAX_COUNTS: usize = super::MAX_LIGHTS + 1;

/// Where the points header starts: after the pmj02 and mask offsets and the count table.
pub const POINTS_HEADER: usize = 3 + 2 * MAX_COUNTS;

/// Words of the points header: data offset, layout, points per pixel, tile side, domain, mask
/// offset (render/gpu/shaders/sampling.wgsl, `points_point`).
const POINTS_WORDS: usize = 6;

/// The WGSL constants of the layout, prepended to the shaders with the scheme ids.
pub fn wgsl_prelude() -> String {
    format!(
        "const PMJ02_POINTS: u32 = {}u;\nconst BLUE_TILE: u32 = {}u;\nconst TABLE_COUNTS: u32 = {}u;\nconst POINTS_HEADER: u32 = {}u;\n",
        pmj02::MAX_POINTS,
        TILE,
        MAX_COUNTS,
        POINTS_HEADER
    )
}

/// The tables for a frame whose schemes sample `uses` (scheme, ray count) pairs; a single zero
/// word when none reads a table.
pub fn pack(uses: &[(DiskScheme, u32)]) -> Vec<u32> {
    let mut counts: Vec<u32> = uses
        .iter()
        .filter(|(s, _)| *s == DiskScheme::SobolBluenoise)
        .map(|&(_, n)| bluenoise::table_rays(n))
        .collect();
    counts.sort_unstable();
    counts.dedup();
    assert!(
        counts.len() <= MAX_COUNTS,
        "a frame's lights and ambient pass use at most {MAX_COUNTS} ray counts"
    );
    let needs = |s: DiskScheme| uses.iter().any(|u| u.0 == s);
    let mut out = vec![0u32; POINTS_HEADER + POINTS_WORDS];
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
        assert_eq!(pack(&[(DiskScheme::Uniform, 16)]).len(), POINTS_HEADER + POINTS_WORDS);
    }
}
