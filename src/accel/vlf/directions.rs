//! The stored directions of a visibility field and the constant-time nearest-direction lookup
//! (paper Section 3.1; Slater, "Constant time queries on uniformly distributed points on a
//! hemisphere", JGT 7(1), 2002).
//!
//! Level `L` gives the upper hemisphere of an octahedron whose face edges are cut into `L`: the
//! lattice points `(i, j, L - |i| - |j|)`, `|i| + |j| <= L`, normalised. Directions are lines, so
//! of each opposite pair on the equator (`|i| + |j| = L`) only the one with `j > 0`, or `j = 0`
//! and `i > 0`, is kept: `2 L^2 + 1` directions (513 at `L = 16`, the paper's count).
//!
//! The octahedral map `(u, v) = (x, y) / (|x| + |y| + |z|)` sends lattice point `(i, j)` to
//! `(i, j) / L` exactly, so the lookup table is a square grid over `[-1, 1]^2` in `(u, v)` whose
//! cells each hold the direction nearest (by angle between lines) to the cell's centre. A query
//! reads one cell; the direction it gets may not be the exact nearest, but only within the
//! cell's angular size. Measured over 1e6 seeded directions at level 16 (table 256 x 256,
//! `tests/visibility_field.rs`): the table's line is at most 1.23 degrees farther than the
//! exact nearest (documented bound 1.3), at most 5.60 degrees off the query (the exact nearest:
//! at most 5.00, as the paper summary says). Picking a
//! non-nearest direction costs speed, never correctness: the tile walk covers any mismatch.

use glam::DVec3;

/// The direction set, each direction's rotation into canonical space, and the lookup table.
#[derive(Clone, Debug)]
pub struct Directions {
    /// Subdivision level `L` (16 for the paper's 513 directions).
    pub level: u32,
    /// Per direction, the rows `a, b, w` of the rotation taking `w` onto `+z` (Section 3.1's
    /// M_i): 9 f64 each, direction `k` at `9 k`.
    pub rows: Vec<f64>,
    /// Lookup table side (cells per side over `[-1, 1]^2` in octahedral coordinates).
    pub table_side: u32,
    /// Row-major `table_side^2` direction indices.
    pub table: Vec<u32>,
}

/// An orthonormal basis `(a, b)` completing unit `w` (Duff et al., "Building an orthonormal
/// basis, revisited", JCGT 6(1), 2017): continuous over the hemisphere `z >= 0`.
fn basis(w: DVec3) -> (DVec3, DVec3) {
    let sign = 1f64.copysign(w.z);
    let a = -1.0 / (sign + w.z);
    let b = w.x * w.y * a;
    (
        DVec3::new(1.0 + sign * w.x * w.x * a, sign * b, -sign * w.x),
        DVec3::new(b, sign + w.y * w.y * a, -w.y),
    )
}

impl Directions {
    /// The `2 L^2 + 1` directions of level `level` (>= 1) and their lookup table.
    pub fn new(level: u32) -> Directions {
        assert!((1..=128).contains(&level), "direction level {level} outside 1..=128");
        let l = level as i32;
        let side = (2 * l + 1) as usize;
        // Lattice (i, j) -> direction index; a dropped equator point maps to its opposite.
        let mut lattice = vec![u32::MAX; side * side];
        let at = |i: i32, j: i32| (j + l) as usize * side + (i + l) as usize;
        let mut rows = Vec::new();
        let mut count = 0u32;
        for j in -l..=l {
            for i in -l..=l {
                let m = i.abs() + j.abs();
                if m > l || (m == l && !(j > 0 || (j == 0 && i > 0))) {
                    continue;
                }
                let w = DVec3::new(i as f64, j as f64, (l - m) as f64).normalize();
                let (a, b) = basis(w);
                rows.extend([a.x, a.y, a.z, b.x, b.y, b.z, w.x, w.y, w.z]);
                lattice[at(i, j)] = count;
                count += 1;
            }
        }
        for j in -l..=l {
            for i in -l..=l {
                if i.abs() + j.abs() == l && lattice[at(i, j)] == u32::MAX {
                    lattice[at(i, j)] = lattice[at(-i, -j)];
                }
            }
        }
        debug_assert_eq!(count, 2 * level * level + 1);
        let mut d = Directions {
            level,
            rows,
            table_side: 16 * level,
            table: Vec::new(),
        };
        let n = d.table_side as usize;
        let mut table = vec![0u32; n * n];
        for cy in 0..n {
            for cx in 0..n {
                let mut u = (cx as f64 + 0.5) / n as f64 * 2.0 - 1.0;
                let mut v = (cy as f64 + 0.5) / n as f64 * 2.0 - 1.0;
                let s = u.abs() + v.abs();
                if s > 1.0 {
                    (u, v) = (u / s, v / s);
                }
                let w = DVec3::new(u, v, 1.0 - u.abs() - v.abs()).normalize();
                let (ri, rj) = ((u * l as f64).round() as i32, (v * l as f64).round() as i32);
                let mut best = (f64::NEG_INFINITY, 0u32);
                for j in (rj - 3).max(-l)..=(rj + 3).min(l) {
                    for i in (ri - 3).max(-l)..=(ri + 3).min(l) {
                        if i.abs() + j.abs() > l {
                            continue;
                        }
                        let k = lattice[at(i, j)];
                        let c = d.direction(k).dot(w).abs();
                        if c > best.0 {
                            best = (c, k);
                        }
                    }
                }
                table[cy * n + cx] = best.1;
            }
        }
        d.table = table;
        d
    }

    /// Number of directions.
    pub fn len(&self) -> usize {
        self.rows.len() / 9
    }

    /// Whether there are none (never: level >= 1).
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    /// Direction `k` (unit, `z >= 0`).
    #[inline]
    pub fn direction(&self, k: u32) -> DVec3 {
        let r = &self.rows[9 * k as usize + 6..9 * k as usize + 9];
        DVec3::new(r[0], r[1], r[2])
    }

    /// Rotation rows of direction `k`.
    #[inline]
    pub fn rotation(&self, k: u32) -> [DVec3; 3] {
        let r = &self.rows[9 * k as usize..9 * k as usize + 9];
        [
            DVec3::new(r[0], r[1], r[2]),
            DVec3::new(r[3], r[4], r[5]),
            DVec3::new(r[6], r[7], r[8]),
        ]
    }

    /// The stored line nearest `d` (any non-zero vector), read from the table in constant
    /// time: one octahedral projection, one cell.
    #[inline]
    pub fn lookup(&self, d: DVec3) -> u32 {
        let s = d.x.abs() + d.y.abs() + d.z.abs();
        let flip = if d.z < 0.0 { -1.0 } else { 1.0 };
        let half = self.table_side as f64 * 0.5;
        let last = self.table_side as usize - 1;
        // `as usize` saturates (negative and NaN give 0).
        let cx = (((d.x * flip / s) + 1.0) * half) as usize;
        let cy = (((d.y * flip / s) + 1.0) * half) as usize;
        self.table[cy.min(last) * self.table_side as usize + cx.min(last)]
    }

    /// The exact nearest stored line to `d` by testing every direction (for checks).
    pub fn nearest_exhaustive(&self, d: DVec3) -> u32 {
        let d = d.normalize();
        (0..self.len() as u32)
            .map(|k| (self.direction(k).dot(d).abs(), k))
            .fold((f64::NEG_INFINITY, 0), |a, b| if b.0 > a.0 { b } else { a })
            .1
    }

    /// Angle in radians between the line of `d` and stored line `k`.
    pub fn angle(&self, d: DVec3, k: u32) -> f64 {
        self.direction(k).dot(d.normalize()).abs().min(1.0).acos()
    }
}
