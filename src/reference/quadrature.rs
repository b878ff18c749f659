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

/// Bisection depth at which a panel is accepted whatever its error estimate.
pub const MAX_DEPTH: u32 = 40;

/// Panels one integral may evaluate (15 integrand calls each): past it every panel is accepted
/// as it stands and counted as unresolved, so no integrand (a light as large as the world, a
/// tolerance below f64's reach everywhere) makes the rule run for hours.
pub const MAX_PANELS: u32 = 1 << 14;

/// An integral with what the adaptive rule knows of its accuracy.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Integral {
    /// The integral.
    pub value: f64,
    /// Sum of |Kronrod - Gauss| over the accepted panels: the rule's (usually pessimistic) bound
    /// on |value - integral|.
    pub error: f64,
    /// Panels accepted at [`MAX_DEPTH`], or once [`MAX_PANELS`] were spent, with their error
    /// still above their share of the tolerance: where the integrand could not be resolved (a
    /// jump, or a tolerance below what f64 can deliver). Never silent: callers report it.
    pub depth_limited: u32,
}

impl std::ops::Add for Integral {
    type Output = Integral;
    fn add(self, o: Integral) -> Integral {
        Integral {
            value: self.value + o.value,
            error: self.error + o.error,
            depth_limited: self.depth_limited + o.depth_limited,
        }
    }
}

/// Integral of `f` over [a, b] to absolute tolerance `tol`, starting from `panels` equal panels
/// (a feature narrower than all 15 nodes of a panel can be missed by any adaptive rule; the
/// initial grid bounds how narrow that is) and bisecting panels whose error estimate exceeds
/// their share of `tol`, down to [`MAX_DEPTH`].
pub fn integrate_panels(f: impl Fn(f64) -> f64, a: f64, b: f64, tol: f64, panels: u32) -> Integral {
    let h = (b - a) / panels as f64;
    (0..panels)
        .map(|i| {
            let (x0, x1) = (a + h * i as f64, a + h * (i + 1) as f64);
            integrate(&f, x0, x1, tol / panels as f64)
        })
        .fold(Integral::default(), |acc, e| acc + e)
}

/// Integral of `f` over [a, b] to absolute tolerance `tol` (bisecting panels whose error
/// estimate exceeds their share), stopping at [`MAX_DEPTH`] or when [`MAX_PANELS`] are spent.
pub fn integrate(f: impl Fn(f64) -> f64, a: f64, b: f64, tol: f64) -> Integral {
    struct Rule<'a, F> {
        f: &'a F,
        spent: std::cell::Cell<u32>,
    }
    impl<F: Fn(f64) -> f64> Rule<'_, F> {
        fn panel(&self, a: f64, b: f64) -> (f64, f64) {
            self.spent.set(self.spent.get() + 1);
            panel(self.f, a, b)
        }
        fn rec(&self, a: f64, b: f64, tol: f64, whole: (f64, f64), depth: u32) -> Integral {
            if whole.1 <= tol || depth >= MAX_DEPTH || self.spent.get() + 2 > MAX_PANELS {
                return Integral {
                    value: whole.0,
                    error: whole.1,
                    depth_limited: (whole.1 > tol) as u32,
                };
            }
            let m = 0.5 * (a + b);
            let (l, r) = (self.panel(a, m), self.panel(m, b));
            self.rec(a, m, 0.5 * tol, l, depth + 1) + self.rec(m, b, 0.5 * tol, r, depth + 1)
        }
    }
    let rule = Rule {
        f: &f,
        spent: std::cell::Cell::new(0),
    };
    let whole = rule.panel(a, b);
    rule.rec(a, b, tol, whole, 0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The estimate is within its own error bound of the known integral and the bound is within
    /// the tolerance asked for.
    fn converges(e: Integral, exact: f64, tol: f64) {
        assert!(
            (e.value - exact).abs() <= e.error + 4.0 * f64::EPSILON * exact.abs(),
            "{e:?} vs {exact}"
        );
        assert!(e.error <= tol, "{e:?}");
    }

    #[test]
    fn smooth_and_kinked_integrands() {
        let e = integrate(|x| x.sin(), 0.0, std::f64::consts::PI, 1e-13);
        converges(e, 2.0, 1e-13);
        assert_eq!(e.depth_limited, 0);
        let e = integrate(|x| (x - 0.3).abs(), 0.0, 1.0, 1e-12);
        converges(e, 0.29, 1e-12);
        assert_eq!(e.depth_limited, 0);
        // Square-root endpoint behaviour, as at a tangency of the occluder's silhouette: the
        // panels touching the endpoints reach the depth limit (their share of the tolerance
        // halves with every bisection, faster than their error falls), yet the total meets it.
        let e = integrate(|x| (1.0 - x * x).max(0.0).sqrt(), -1.0, 1.0, 1e-11);
        converges(e, std::f64::consts::FRAC_PI_2, 1e-11);
        assert!(e.depth_limited > 0, "{e:?}");
        let e = integrate_panels(|x| x.exp(), 0.0, 1.0, 1e-12, 16);
        converges(e, std::f64::consts::E - 1.0, 1e-12);
    }

    #[test]
    fn a_jump_reaches_the_depth_limit_and_says_so() {
        let e = integrate(|x| if x < 1.0 / 3.0 { 0.0 } else { 1.0 }, 0.0, 1.0, 1e-13);
        assert!(e.depth_limited >= 1, "{e:?}");
        assert!((e.value - 2.0 / 3.0).abs() <= e.error + 1e-15, "{e:?}");
        assert!(e.error < 1e-10, "the limit still bounds the damage: {e:?}");
        // A tolerance below f64 resolution cannot be met.
        let e = integrate(|x| x.sqrt(), 0.0, 1.0, 1e-30);
        assert!(e.depth_limited > 0 && e.error > 1e-30, "{e:?}");
    }

    /// An integrand no tolerance can resolve anywhere (a jump at every scale) spends the panel
    /// budget and stops, reporting what it could not resolve, instead of bisecting 2^40 panels.
    #[test]
    fn the_panel_budget_ends_an_unresolvable_integral() {
        let calls = std::cell::Cell::new(0u64);
        let wild = |x: f64| {
            calls.set(calls.get() + 1);
            ((x * 1e12).sin() * 1e6).signum()
        };
        let start = std::time::Instant::now();
        let e = integrate(wild, 0.0, 1.0, 1e-15);
        assert!(calls.get() <= 15 * MAX_PANELS as u64, "{} calls", calls.get());
        assert!(e.depth_limited > 0, "{e:?}");
        assert!(e.value.is_finite() && e.error.is_finite(), "{e:?}");
        eprintln!("{} integrand calls in {:?}", calls.get(), start.elapsed());
    }
}
