//! `--filter AXIS=VALUE` on a sweep: the core's filters ([`crate::experiment::core::filter`])
//! over the sweep's axes ([`Axis`]), each keeping the values it names in the experiment's order.

use super::axes::{Axes, Axis};
use super::spec::Spec;
use crate::experiment::core::filter::{self, Filter};

impl Axes {
    /// The axes as filters see them: each one's name and its values' texts.
    pub fn declared(&self) -> Vec<filter::Axis> {
        self.texts()
            .into_iter()
            .map(|(a, values)| filter::Axis { name: a.name(), values })
            .collect()
    }
}

/// `axes` restricted by `filters`.
pub fn restrict(axes: &Axes, filters: &[Filter]) -> Result<Axes, String> {
    let mut a = axes.clone();
    for (i, keep) in filter::select(&axes.declared(), filters, filter::same_text)? {
        a.restrict(Axis::ALL[i], &keep);
    }
    Ok(a)
}

impl Spec {
    /// This experiment with its sweep restricted by `filters`.
    pub fn filtered(mut self, filters: &[Filter]) -> Result<Spec, String> {
        self.axes = restrict(&self.axes, filters)?;
        Ok(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::{DiskScheme, Pattern};

    fn axes() -> Axes {
        Axes {
            schemes: vec![DiskScheme::Uniform, DiskScheme::Paper, DiskScheme::Sobol],
            patterns: vec![Pattern::PerPixel, Pattern::Shared],
            samples: vec![4, 16, 64],
            light_radii: vec![0.01, 0.02],
            seeds: vec![1, 2, 3],
            light_counts: vec![1],
            accelerators: vec!["bvh".into()],
        }
    }

    fn filters(s: &[&str]) -> Vec<Filter> {
        s.iter().map(|f| f.parse().unwrap()).collect()
    }

    #[test]
    fn filters_keep_the_named_values_and_leave_other_axes() {
        let a = restrict(
            &axes(),
            &filters(&["scheme=paper", "scheme=uniform", "samples=16", "light_radius=0.02"]),
        )
        .unwrap();
        assert_eq!(
            a.schemes,
            [DiskScheme::Uniform, DiskScheme::Paper],
            "experiment order kept"
        );
        assert_eq!(a.samples, [16]);
        assert_eq!(a.light_radii, [0.02]);
        assert_eq!((a.patterns.len(), a.seeds.len()), (2, 3));
    }

    #[test]
    fn unknown_axes_and_unswept_values_are_errors() {
        let e = restrict(&axes(), &filters(&["colour=red"])).unwrap_err();
        assert!(e.contains("unknown axis `colour`"), "{e}");
        let e = restrict(&axes(), &filters(&["scheme=halton"])).unwrap_err();
        assert!(e.contains("not among the experiment's scheme values"), "{e}");
        let e = restrict(&axes(), &filters(&["samples=32"])).unwrap_err();
        assert!(e.contains("samples values: 4, 16, 64"), "{e}");
    }
}
