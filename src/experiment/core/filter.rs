//! `--filter AXIS=VALUE`: runs a subset of any experiment. A kind declares its axes
//! ([`Axis`]: a name and the values its file lists); each filter keeps, on its axis, only the
//! values named (repeating an axis keeps each value named). An axis the kind does not have, or a
//! value its file does not list, is an error naming what there is, so a typo never runs an empty
//! or unintended experiment.

pub use crate::experiment::args::{Filter, FILTER_HELP as HELP};

/// A kind's axis, by a typed key (an enum per kind, declared with [`axis_keys!`]): a filter,
/// a dry run or the core names an axis by its key, never by its place in a list.
pub trait AxisKey: Copy + PartialEq + std::fmt::Debug {
    /// Its column and filter name.
    fn name(self) -> &'static str;
}

/// Declares a kind's axis keys: an enum whose variants name their axis's column and filter
/// name (`Scene => "scene"`), implementing [`AxisKey`].
#[macro_export]
macro_rules! axis_keys {
    ($(#[$meta:meta])* $vis:vis enum $name:ident { $($(#[$doc:meta])* $var:ident => $text:literal,)* }) => {
        $(#[$meta])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq)]
        $vis enum $name {
            $($(#[$doc])* $var,)*
        }

        impl $crate::experiment::core::filter::AxisKey for $name {
            fn name(self) -> &'static str {
                match self {
                    $($name::$var => $text,)*
                }
            }
        }
    };
}

/// One axis of a kind, as filters, dry runs and results-folder names see it.
#[derive(Clone, Debug, PartialEq)]
pub struct Axis<K> {
    /// Which axis.
    pub key: K,
    /// Its values' texts, in the experiment file's order.
    pub values: Vec<String>,
}

impl<K: AxisKey> Axis<K> {
    /// The axis `key` with `values`, written as filters and folder names write them.
    pub fn of(key: K, values: impl IntoIterator<Item = impl ToString>) -> Axis<K> {
        Axis {
            key,
            values: values.into_iter().map(|v| v.to_string()).collect(),
        }
    }

    /// Its column and filter name.
    pub fn name(&self) -> &'static str {
        self.key.name()
    }
}

/// What `filters` keep of `axes`: per filtered axis (in declared order), its key and the
/// indices of the values kept, in the file's order. `same` says whether two value texts name the
/// same value (numbers written two ways, `0.02` and `2e-2`, are one).
pub fn select<K: AxisKey>(
    axes: &[Axis<K>],
    filters: &[Filter],
    same: impl Fn(&str, &str) -> bool,
) -> Result<Vec<(K, Vec<usize>)>, String> {
    let names: Vec<&str> = axes.iter().map(Axis::name).collect();
    for f in filters {
        if !names.contains(&f.axis.as_str()) {
            return Err(format!(
                "--filter {f}: unknown axis `{}`; this experiment's axes are {}",
                f.axis,
                names.join(", ")
            ));
        }
    }
    let mut out = Vec::new();
    for axis in axes {
        let named: Vec<&Filter> = filters.iter().filter(|f| f.axis == axis.name()).collect();
        if named.is_empty() {
            continue;
        }
        let mut keep = Vec::new();
        for f in named {
            let at = axis.values.iter().position(|v| same(v, &f.value)).ok_or_else(|| {
                format!(
                    "--filter {f}: not among the experiment's {} values: {}",
                    axis.name(),
                    axis.values.join(", ")
                )
            })?;
            keep.push(at);
        }
        keep.sort_unstable();
        keep.dedup();
        out.push((axis.key, keep));
    }
    Ok(out)
}

/// Value texts that name the same value: equal, or equal as numbers.
pub fn same_text(a: &str, b: &str) -> bool {
    a == b || matches!((a.parse::<f64>(), b.parse::<f64>()), (Ok(x), Ok(y)) if x == y)
}

/// `list` keeping only the entries at `keep` (sorted indices).
pub fn keep_at<T>(list: &mut Vec<T>, keep: &[usize]) {
    let mut i = 0;
    list.retain(|_| {
        i += 1;
        keep.contains(&(i - 1))
    });
}

/// A results-folder suffix naming the filters, e.g. `scheme=paper,samples=16`.
pub fn label(filters: &[Filter]) -> String {
    filters.iter().map(Filter::to_string).collect::<Vec<_>>().join(",")
}

#[cfg(test)]
mod tests {
    use super::*;

    crate::axis_keys! {
        enum Key {
            Scheme => "scheme",
            Radius => "light_radius",
        }
    }

    fn axes() -> Vec<Axis<Key>> {
        vec![
            Axis {
                key: Key::Scheme,
                values: vec!["uniform".into(), "paper".into(), "sobol".into()],
            },
            Axis {
                key: Key::Radius,
                values: vec!["0.01".into(), "0.02".into()],
            },
        ]
    }

    fn filters(s: &[&str]) -> Vec<Filter> {
        s.iter().map(|f| f.parse().unwrap()).collect()
    }

    #[test]
    fn filters_keep_the_named_values_in_file_order() {
        let got = select(
            &axes(),
            &filters(&["scheme=sobol", "scheme=uniform", "light_radius=2e-2"]),
            same_text,
        )
        .unwrap();
        assert_eq!(got, vec![(Key::Scheme, vec![0, 2]), (Key::Radius, vec![1])]);
        let mut list = vec!['a', 'b', 'c'];
        keep_at(&mut list, &[0, 2]);
        assert_eq!(list, ['a', 'c']);
        assert_eq!(
            label(&filters(&["scheme=paper", "samples=16"])),
            "scheme=paper,samples=16"
        );
    }

    #[test]
    fn unknown_axes_and_unlisted_values_are_errors_naming_what_there_is() {
        assert!("scheme".parse::<Filter>().unwrap_err().contains("AXIS=VALUE"));
        assert!("=x".parse::<Filter>().is_err());
        let e = select(&axes(), &filters(&["colour=red"]), same_text).unwrap_err();
        assert!(
            e.contains("unknown axis `colour`") && e.contains("scheme, light_radius"),
            "{e}"
        );
        let e = select(&axes(), &filters(&["scheme=halton"]), same_text).unwrap_err();
        assert!(
            e.contains("not among the experiment's scheme values") && e.contains("uniform, paper, sobol"),
            "{e}"
        );
    }
}
