//! Building blocks of generated scenes: tessellated boxes, cylinders, spheres and grids.

use glam::{DMat3, DVec3};
use std::f64::consts::TAU;

/// One object of a generated scene: its triangles and material.
#[derive(Clone, Debug)]
pub struct Part {
    /// Name (dynamic experiments move a part by name).
    pub name: String,
    /// Lambertian albedo.
    pub albedo: f64,
    /// Mirror weight (Whitted's k_r).
    pub mirror: f64,
    /// World-space triangles.
    pub triangles: Vec<[DVec3; 3]>,
}

impl Part {
    /// An empty diffuse part.
    pub fn new(name: &str, albedo: f64) -> Part {
        Part {
            name: name.to_string(),
            albedo,
            mirror: 0.0,
            triangles: Vec::new(),
        }
    }

    /// The same part with mirror weight `m`.
    pub fn mirror(mut self, m: f64) -> Part {
        self.mirror = m;
        self
    }

    /// Adds the quad a, b, c, d (in order round its edge) split into `nu` x `nv` cells of two
    /// triangles each.
    pub fn grid(&mut self, a: DVec3, b: DVec3, d: DVec3, nu: u32, nv: u32) -> &mut Part {
        let (u, v) = ((b - a) / nu as f64, (d - a) / nv as f64);
        for i in 0..nu {
            for j in 0..nv {
                let p = a + u * i as f64 + v * j as f64;
                self.triangles.push([p, p + u, p + u + v]);
                self.triangles.push([p, p + u + v, p + v]);
            }
        }
        self
    }

    /// Adds the axis-aligned box [lo, hi] (12 triangles).
    pub fn cuboid(&mut self, lo: DVec3, hi: DVec3) -> &mut Part {
        let s = hi - lo;
        let (x, y, z) = (DVec3::X * s.x, DVec3::Y * s.y, DVec3::Z * s.z);
        for (a, b, d) in [
            (lo, lo + y, lo + x),
            (lo + z, lo + z + x, lo + z + y),
            (lo, lo + x, lo + z),
            (lo + y, lo + y + z, lo + y + x),
            (lo, lo + z, lo + y),
            (lo + x, lo + x + y, lo + x + z),
        ] {
            self.grid(a, b, d, 1, 1);
        }
        self
    }

    /// Adds a closed vertical cylinder from `base` up `height`, `segments` around.
    pub fn cylinder(&mut self, base: DVec3, radius: f64, height: f64, segments: u32) -> &mut Part {
        let at = |k: u32, z: f64| {
            let a = TAU * k as f64 / segments as f64;
            base + DVec3::new(radius * a.cos(), radius * a.sin(), z)
        };
        let top = base + DVec3::Z * height;
        for k in 0..segments {
            let (p0, p1, q0, q1) = (at(k, 0.0), at(k + 1, 0.0), at(k, height), at(k + 1, height));
            self.triangles.push([p0, p1, q1]);
            self.triangles.push([p0, q1, q0]);
            self.triangles.push([base, p1, p0]);
            self.triangles.push([top, q0, q1]);
        }
        self
    }

    /// Adds a UV sphere of `rings` x `segments` cells (poles as fans).
    pub fn sphere(&mut self, centre: DVec3, radius: f64, rings: u32, segments: u32) -> &mut Part {
        let at = |i: u32, k: u32| {
            let (th, ph) = (
                std::f64::consts::PI * i as f64 / rings as f64,
                TAU * k as f64 / segments as f64,
            );
            centre + radius * DVec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos())
        };
        for i in 0..rings {
            for k in 0..segments {
                let (a, b, c, d) = (at(i, k), at(i + 1, k), at(i + 1, k + 1), at(i, k + 1));
                if i > 0 {
                    self.triangles.push([a, b, d]);
                }
                if i + 1 < rings {
                    self.triangles.push([b, c, d]);
                }
            }
        }
        self
    }

    /// Applies `f` to every corner added from triangle `from` on (placing a sub-assembly).
    pub fn transform_from(&mut self, from: usize, f: impl Fn(DVec3) -> DVec3) -> &mut Part {
        for t in &mut self.triangles[from..] {
            *t = t.map(&f);
        }
        self
    }
}

/// Rotation by `degrees` about the vertical axis through `pivot`.
pub fn turn(pivot: DVec3, degrees: f64) -> impl Fn(DVec3) -> DVec3 {
    let r = DMat3::from_rotation_z(degrees.to_radians());
    move |p| pivot + r * (p - pivot)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area(p: &Part) -> f64 {
        p.triangles
            .iter()
            .map(|t| 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length())
            .sum()
    }

    #[test]
    fn tessellations_have_their_closed_form_areas() {
        let mut b = Part::new("box", 0.5);
        b.cuboid(DVec3::ZERO, DVec3::new(1.0, 2.0, 3.0));
        assert_eq!(b.triangles.len(), 12);
        assert!((area(&b) - 22.0).abs() < 1e-12);
        let mut g = Part::new("grid", 0.5);
        g.grid(DVec3::ZERO, DVec3::X * 2.0, DVec3::Y * 3.0, 4, 5);
        assert_eq!(g.triangles.len(), 40);
        assert!((area(&g) - 6.0).abs() < 1e-12);
        let (n, r, h) = (64u32, 0.5, 2.0);
        let mut c = Part::new("cylinder", 0.5);
        c.cylinder(DVec3::ZERO, r, h, n);
        let polygon = 0.5 * n as f64 * r * r * (TAU / n as f64).sin();
        let side = n as f64 * 2.0 * r * (std::f64::consts::PI / n as f64).sin() * h;
        assert!((area(&c) - (2.0 * polygon + side)).abs() < 1e-9);
        let mut s = Part::new("sphere", 0.5);
        s.sphere(DVec3::ZERO, 1.0, 64, 128);
        assert_eq!(s.triangles.len(), 2 * 64 * 128 - 2 * 128);
        assert!((area(&s) - 4.0 * std::f64::consts::PI).abs() < 0.01);
    }
}
