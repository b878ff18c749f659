//! `--filter AXIS=VALUE`: runs a subset of an experiment's sweep. AXIS is any axis's name
//! ([`Axis::name`]). Each filter keeps, on its axis, only the values named (repeating an axis keeps
//! each value named); a value the experiment does not sweep is an error, so a typo never runs an
//! empty or unintended sweep.

use super::axes::{Axes, Axis};
use super::spec::Spec;

/// One `AXIS=VALUE` filter.
#[derive(Clone, Debug, PartialEq)]
pub struct Filter {
    /// The axis.
    pub axis: Axis,
    /// The value as written.
    pub value: String,
}

impl std::str::FromStr for Filter {
    type Err = String;

    fn from_str(s: &str) -> Result<Filter, String> {
        let names: Vec<&str> = Axis::ALL.iter().map(|a| a.name()).collect();
        let (axis, value) = s
            .split_once('=')
            .ok_or_else(|| format!("`{s}`: a filter is AXIS=VALUE, AXIS one of {}", names.join(", ")))?;
        let (axis, value) = (axis.trim(), value.trim());
        let axis =
            Axis::named(axis).ok_or_else(|| format!("`{s}`: unknown axis `{axis}`; one of {}", names.join(", ")))?;
        Ok(Filter {
            axis,
            value: value.into(),
        })
    }
}

/// `axes` restricted by `filters`.
pub fn restrict(axes: &Axes, filters: &[Filter]) -> Result<Axes, String> {
    let mut a = axes.clone();
    for &axis in Axis::ALL {
        let values: Vec<&str> = filters
            .iter()
            .filter(|f| f.axis == axis)
            .map(|f| f.value.as_str())
            .collect();
        if !values.is_empty() {
            a.restrict(axis, &values)?;
        }
    }
    Ok(a)
}

/// `--filter`'s help, naming the axes.
pub fn help() -> String {
    let names: Vec<&str> = Axis::ALL.iter().map(|a| a.name()).collect();
    format!(
        "Run only the runs whose AXIS has VALUE (axes: {}); repeat to keep several values or restrict several axes",
        names.join(", ")
    )
}

/// A results-folder suffix naming the filters, e.g. `scheme=paper,samples=16`.
pub fn label(filters: &[Filter]) -> String {
    filters
        .iter()
        .map(|f| format!("{}={}", f.axis.name(), f.value))
        .collect::<Vec<_>>()
        .join(",")
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
        assert_eq!(
            label(&filters(&["scheme=paper", "samples=16"])),
            "scheme=paper,samples=16"
        );
    }

    #[test]
    fn unknown_axes_values_and_unswept_values_are_errors() {
        assert!("scheme".parse::<Filter>().unwrap_err().contains("AXIS=VALUE"));
        assert!("colour=red"
            .parse::<Filter>()
            .unwrap_err()
            .contains("unknown axis `colour`"));
        let e = restrict(&axes(), &filters(&["scheme=halton"])).unwrap_err();
        assert!(e.contains("not a valid scheme"), "{e}");
        let e = restrict(&axes(), &filters(&["samples=32"])).unwrap_err();
        assert!(e.contains("does not sweep"), "{e}");
    }
}
