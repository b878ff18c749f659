//! Adaptive Gauss-Kronrod (7, 15) quadrature: the outer integral over angle of the exact
//! visibility, whose integrand has kinks and square-root tangency points that adaptivity absorbs.

const XGK: [f64; 8] = [
    0.991_455_371_120_812_6,
    0.949_107_912_342_758_5,
    0.864_864_423_359_769_1,
    0.741_531_185_599_394_4,
    0.586_087_235_467_691_1,
    0.405_845_151_377_397_2,
    0.207_784_955_007_898_5,
    0.0,
];
const WGK: [f64; 8] = [
    0.022_935_322_010_529_22,
    0.063_092_092_629_978_55,
    0.104_790_010_322_250_2,
    0.140_653_259_715_525_9,
    0.169_004_726_639_267_9,
    0.190_350_578_064_785_4,
    0.204_432_940_075_298_9,
    0.209_482_141_084_728,
];
const WG: [f64; 4] = [
    0.129_484_966_168_869_7,
    0.279_705_391_489_276_7,
    0.381_830_050_505_118_9,
    0.417_959_183_673_469_4,
];

/// One G7-K15 panel: (Kronrod estimate, |Kronrod - Gauss|).
fn panel(f: &impl Fn(f64) -> f64, a: f64, b: f64) -> (f64, f64) {
    let (c, h) = (0.5 * (a + b), 0.5 * (b - a));
    let fc = f(c);
    let mut k = WGK[7] * fc;
    let mut g = WG[3] * fc;
    for i in 0..7 {
        let (f1, f2) = (f(c - h * XGK[i]), f(c + h * XGK[i]));
        k += WGK[i] * (f1 + f2);
        if i % 2 == 1 {
            g += WG[i / 2] * (f1 + f2);
        }
    }
    (k * h, ((k - g) * h).abs())
}

/// Integral of `f` over [a, b] to absolute tolerance `tol`, starting from `panels` equal panels
/// (a feature narrower than all 15 nodes of a panel can be missed by any adaptive rule; the
/// initial grid bounds how narrow that is) and bisecting panels whose error estimate exceeds
/// their share of `tol`, down to depth 40.
pub fn integrate_panels(f: impl Fn(f64) -> f64, a: f64, b: f64, tol: f64, panels: u32) -> f64 {
    let h = (b - a) / panels as f64;
    (0..panels)
        .map(|i| {
            let (x0, x1) = (a + h * i as f64, a + h * (i + 1) as f64);
            integrate(&f, x0, x1, tol / panels as f64)
        })
        .sum()
}

/// Integral of `f` over [a, b] to absolute tolerance `tol` (bisecting panels whose error
/// estimate exceeds their share), stopping at depth 40.
pub fn integrate(f: impl Fn(f64) -> f64, a: f64, b: f64, tol: f64) -> f64 {
    fn rec(f: &impl Fn(f64) -> f64, a: f64, b: f64, tol: f64, whole: (f64, f64), depth: u32) -> f64 {
        if whole.1 <= tol || depth >= 40 {
            return whole.0;
        }
        let m = 0.5 * (a + b);
        let (l, r) = (panel(f, a, m), panel(f, m, b));
        rec(f, a, m, 0.5 * tol, l, depth + 1) + rec(f, m, b, 0.5 * tol, r, depth + 1)
    }
    rec(&f, a, b, tol, panel(&f, a, b), 0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn smooth_and_kinked_integrands() {
        assert!((integrate(|x| x.sin(), 0.0, std::f64::consts::PI, 1e-13) - 2.0).abs() < 1e-12);
        assert!((integrate(|x| (x - 0.3).abs(), 0.0, 1.0, 1e-12) - 0.29).abs() < 1e-11);
        // Square-root endpoint behaviour, as at a tangency of the occluder's silhouette.
        let v = integrate(|x| (1.0 - x * x).max(0.0).sqrt(), -1.0, 1.0, 1e-11);
        assert!((v - std::f64::consts::FRAC_PI_2).abs() < 1e-9, "{v}");
    }
}
