//! `--filter AXIS=VALUE`: runs a subset of an experiment's sweep. Each filter keeps, on its axis,
//! only the values named (repeating an axis keeps each value named); a value the experiment does
//! not sweep is an error, so a typo never runs an empty or unintended sweep.

use super::spec::{Axes, Spec};
use crate::sampling::{DiskScheme, Pattern};
use std::collections::BTreeMap;

/// Axis names a filter may use, as in the experiment file's `[sweep]` table (singular).
pub const AXES: [&str; 6] = ["scheme", "pattern", "samples", "light_radius", "lights", "seed"];

/// One `AXIS=VALUE` filter.
#[derive(Clone, Debug, PartialEq)]
pub struct Filter {
    /// One of [`AXES`].
    pub axis: String,
    /// The value as written.
    pub value: String,
}

impl std::str::FromStr for Filter {
    type Err = String;

    fn from_str(s: &str) -> Result<Filter, String> {
        let (axis, value) = s
            .split_once('=')
            .ok_or_else(|| format!("`{s}`: a filter is AXIS=VALUE, AXIS one of {}", AXES.join(", ")))?;
        let (axis, value) = (axis.trim(), value.trim());
        if !AXES.contains(&axis) {
            return Err(format!("`{s}`: unknown axis `{axis}`; one of {}", AXES.join(", ")));
        }
        Ok(Filter {
            axis: axis.into(),
            value: value.into(),
        })
    }
}

/// Keeps the values of `list` that some filter on `axis` names; every named value must be in it.
fn keep<T: PartialEq + Copy>(
    list: &mut Vec<T>,
    axis: &str,
    named: &BTreeMap<&str, Vec<&str>>,
    parse: impl Fn(&str) -> Option<T>,
) -> Result<(), String> {
    let Some(values) = named.get(axis) else {
        return Ok(());
    };
    let mut wanted = Vec::new();
    for v in values {
        let x = parse(v).ok_or_else(|| format!("--filter {axis}={v}: not a valid {axis}"))?;
        if !list.contains(&x) {
            return Err(format!("--filter {axis}={v}: the experiment does not sweep this value"));
        }
        wanted.push(x);
    }
    list.retain(|x| wanted.contains(x));
    Ok(())
}

/// `axes` restricted by `filters`.
pub fn restrict(axes: &Axes, filters: &[Filter]) -> Result<Axes, String> {
    let mut named: BTreeMap<&str, Vec<&str>> = BTreeMap::new();
    for f in filters {
        named.entry(f.axis.as_str()).or_default().push(f.value.as_str());
    }
    let mut a = axes.clone();
    keep(&mut a.schemes, "scheme", &named, |v| v.parse::<DiskScheme>().ok())?;
    keep(&mut a.patterns, "pattern", &named, |v| v.parse::<Pattern>().ok())?;
    keep(&mut a.samples, "samples", &named, |v| v.parse().ok())?;
    keep(&mut a.light_radii, "light_radius", &named, |v| v.parse().ok())?;
    keep(&mut a.light_counts, "lights", &named, |v| v.parse().ok())?;
    keep(&mut a.seeds, "seed", &named, |v| v.parse().ok())?;
    Ok(a)
}

/// A results-folder suffix naming the filters, e.g. `scheme=paper,samples=16`.
pub fn label(filters: &[Filter]) -> String {
    filters
        .iter()
        .map(|f| format!("{}={}", f.axis, f.value))
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

    fn axes() -> Axes {
        Axes {
            schemes: vec![DiskScheme::Uniform, DiskScheme::Paper, DiskScheme::Sobol],
            patterns: vec![Pattern::PerPixel, Pattern::Shared],
            samples: vec![4, 16, 64],
            light_radii: vec![0.01, 0.02],
            seeds: vec![1, 2, 3],
            light_counts: vec![1],
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
