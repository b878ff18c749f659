//! The sweep's axes, declared once, in the `axes!` invocation below. Everything that names
//! axes reads this list: the experiment file's `[sweep]` lists ([`Axes`]), a run's and a
//! configuration's fields ([`Run`], [`Config`]), the identity columns of runs.csv, summary.csv
//! and timings.csv (in the order declared), run keys, `--filter AXIS=VALUE`, the dry run's lines,
//! the expansion order ([`Axes::configs`]), grouping (runs that differ only in the seed) and the
//! lookups of summaries, plots and the verdict (by [`Config`], holding the axes they do not name
//! at each value in turn: [`slices`]).
//!
//! Adding an axis is one entry: its variant and field name (the field name is its column and
//! filter name), its value type (an [`AxisValue`]), the `[sweep]` key that lists its values, and
//! its nesting level (lower levels vary slower; equal levels nest in the order declared). What a
//! value does is up to the code that builds a run's scene and sampling from its fields
//! ([`super::measure`], [`super::timing`], [`super::pictures`]); checks on its values beyond
//! "listed, and listed once" go in [`super::spec`] beside the others.

use crate::experiment::core::filter::keep_at;
use crate::output::table::text;
use crate::sampling::{DiskScheme, Pattern};
use serde::{Deserialize, Serialize};
use std::fmt::{self, Debug, Display};
use std::str::FromStr;

/// A value an axis takes: named in experiment files, CSV columns and filters by its `Display`
/// and `FromStr` text, hashed into run keys by [`AxisValue::key_text`].
pub trait AxisValue: Clone + PartialEq + Debug + Display + FromStr + for<'de> Deserialize<'de> {
    /// Its text in run keys.
    fn key_text(&self) -> String {
        self.to_string()
    }
}

impl AxisValue for DiskScheme {
    /// A points scheme's key carries its file's hash: an edited file never reuses a run.
    fn key_text(&self) -> String {
        match self {
            DiskScheme::Points(id) => format!("{}@{}", id.label(), id.set().map_or("unloaded", |s| s.hash.as_str())),
            s => s.to_string(),
        }
    }
}
impl AxisValue for Pattern {}
impl AxisValue for u32 {}
impl AxisValue for String {}

impl AxisValue for f64 {
    /// Exponent form: one text per value, whatever its magnitude.
    fn key_text(&self) -> String {
        format!("{self:e}")
    }
}

macro_rules! axes {
    (
        configuration {
            $( $(#[$doc:meta])* $var:ident $field:ident: $ty:ty, listed in $list:ident, nest $nest:literal; )*
        }
        seed {
            $(#[$seed_doc:meta])* $seed_var:ident $seed:ident: $seed_ty:ty, listed in $seeds:ident;
        }
    ) => {
        /// An axis of the sweep.
        #[derive(Clone, Copy, Debug, PartialEq, Eq)]
        pub enum Axis {
            $($(#[$doc])* $var,)*
            $(#[$seed_doc])* $seed_var,
        }

        impl Axis {
            /// Every axis, in column order.
            pub const ALL: &'static [Axis] = &[$(Axis::$var,)* Axis::$seed_var];

            /// Its column, field and filter name.
            pub fn name(self) -> &'static str {
                match self {
                    $(Axis::$var => stringify!($field),)*
                    Axis::$seed_var => stringify!($seed),
                }
            }

            /// The `[sweep]` key listing its values.
            pub fn list_key(self) -> &'static str {
                match self {
                    $(Axis::$var => stringify!($list),)*
                    Axis::$seed_var => stringify!($seeds),
                }
            }
        }

        /// A configuration: a value on every axis but the seed. Its runs, one per seed, form a
        /// group: their images give the per-pixel bias/variance split.
        #[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
        pub struct Config {
            $($(#[$doc])* #[serde(with = "text")] pub $field: $ty,)*
        }

        /// One point of the sweep: a configuration and a seed.
        #[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
        pub struct Run {
            $($(#[$doc])* #[serde(with = "text")] pub $field: $ty,)*
            $(#[$seed_doc])* #[serde(with = "text")] pub $seed: $seed_ty,
        }

        impl Run {
            /// The run's configuration.
            pub fn config(&self) -> Config {
                Config { $($field: self.$field.clone(),)* }
            }

            /// The axis values hashed into the run's key, in column order.
            pub fn key_text(&self) -> String {
                [$(self.$field.key_text(),)* self.$seed.key_text()].join(";")
            }
        }

        impl Config {
            /// The run of this configuration with `seed`.
            pub fn with_seed(&self, $seed: $seed_ty) -> Run {
                Run { $($field: self.$field.clone(),)* $seed }
            }

            /// Whether `other` has the same value on every axis outside `free`.
            pub fn agrees_except(&self, other: &Config, free: &[Axis]) -> bool {
                $((free.contains(&Axis::$var) || self.$field == other.$field))&&*
            }

            /// Each axis with its value's text, in column order.
            pub fn values(&self) -> Vec<(Axis, String)> {
                vec![$((Axis::$var, self.$field.to_string()),)*]
            }
        }

        /// The `[sweep]` table: the values of every axis, in the experiment's order.
        #[derive(Clone, Debug, Deserialize, PartialEq)]
        #[serde(deny_unknown_fields)]
        pub struct Axes {
            $($(#[$doc])* #[serde(default)] pub $list: Vec<$ty>,)*
            $(#[$seed_doc])* #[serde(default)] pub $seeds: Vec<$seed_ty>,
        }

        impl Axes {
            /// Every configuration, in expansion order.
            pub fn configs(&self) -> Vec<Config> {
                let lens = [$(self.$list.len(),)*];
                nested(&lens, &[$($nest,)*])
                    .into_iter()
                    .map(|index| {
                        let mut i = index.into_iter();
                        Config { $($field: self.$list[i.next().expect("one index per axis")].clone(),)* }
                    })
                    .collect()
            }

            /// Each axis with its values' texts.
            pub fn texts(&self) -> Vec<(Axis, Vec<String>)> {
                vec![
                    $((Axis::$var, texts(&self.$list)),)*
                    (Axis::$seed_var, texts(&self.$seeds)),
                ]
            }

            /// Keeps, on `axis`, only the values at `keep` (indices into its list, sorted).
            pub fn restrict(&mut self, axis: Axis, keep: &[usize]) {
                match axis {
                    $(Axis::$var => keep_at(&mut self.$list, keep),)*
                    Axis::$seed_var => keep_at(&mut self.$seeds, keep),
                }
            }
        }
    };
}

axes! {
    configuration {
        /// Disk sampling scheme.
        Scheme scheme: DiskScheme, listed in schemes, nest 2;
        /// Per-pixel or shared.
        Pattern pattern: Pattern, listed in patterns, nest 2;
        /// Shadow rays per receiver point.
        Samples samples: u32, listed in samples, nest 2;
        /// Light radius, metres (every light in use gets it).
        LightRadius light_radius: f64, listed in light_radii, nest 1;
        /// Lights on, the scene's first k (default: all of them).
        Lights lights: u32, listed in light_counts, nest 0;
        /// Acceleration structure over the meshes' triangles, by registry name (default: the
        /// scene's): what the choice of structure costs at equal accuracy.
        Accelerator accelerator: String, listed in accelerators, nest 2;
    }
    seed {
        /// Seed: the runs of a configuration differ only in it, and nest innermost.
        Seed seed: u32, listed in seeds;
    }
}

impl Display for Config {
    /// `scheme=uniform pattern=per-pixel ...`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let pairs: Vec<String> = self.values().iter().map(|(a, v)| format!("{}={v}", a.name())).collect();
        f.write_str(&pairs.join(" "))
    }
}

impl Axes {
    /// The axes as the core's filters and dry runs see them: each one's name and its values'
    /// texts.
    pub fn declared(&self) -> Vec<crate::experiment::core::filter::Axis<Axis>> {
        self.texts()
            .into_iter()
            .map(|(key, values)| crate::experiment::core::filter::Axis { key, values })
            .collect()
    }
}

impl crate::experiment::core::filter::AxisKey for Axis {
    fn name(self) -> &'static str {
        Axis::name(self)
    }
}

fn texts<T: Display>(values: &[T]) -> Vec<String> {
    values.iter().map(|v| v.to_string()).collect()
}

/// Every index tuple into lists of lengths `lens`, the lists nested by `levels` (lower levels
/// outside; equal levels in list order), the innermost varying fastest.
fn nested(lens: &[usize], levels: &[u32]) -> Vec<Vec<usize>> {
    let mut order: Vec<usize> = (0..lens.len()).collect();
    order.sort_by_key(|&i| levels[i]);
    let mut out = Vec::new();
    let mut index = vec![0; lens.len()];
    if lens.contains(&0) {
        return out;
    }
    loop {
        out.push(index.clone());
        // Advance the innermost axis; carry outwards.
        let mut k = order.len();
        loop {
            if k == 0 {
                return out;
            }
            k -= 1;
            let i = order[k];
            index[i] += 1;
            if index[i] < lens[i] {
                break;
            }
            index[i] = 0;
        }
    }
}

/// One combination of values on the axes a plot or report section does not name: it is drawn
/// once per slice, from the configurations that agree with [`Slice::config`] outside `named`.
#[derive(Clone, Debug, PartialEq)]
pub struct Slice {
    /// The slice's first configuration; its values outside `named` are the slice's.
    pub config: Config,
    /// The axes outside `named` that take more than one value, with this slice's value: what
    /// tells the slices apart (empty when there is one slice).
    pub varying: Vec<(Axis, String)>,
}

impl Slice {
    /// Whether `c` belongs to this slice.
    pub fn holds(&self, c: &Config, named: &[Axis]) -> bool {
        self.config.agrees_except(c, named)
    }

    /// `name=value, ...` of the axes that tell the slices apart, but those in `skip` (which the
    /// caller words itself).
    pub fn label(&self, skip: &[Axis]) -> String {
        let pairs: Vec<String> = self
            .varying
            .iter()
            .filter(|(a, _)| !skip.contains(a))
            .map(|(a, v)| format!("{}={v}", a.name()))
            .collect();
        pairs.join(", ")
    }
}

/// The slices of `configs` outside the axes `named`, in the order they first appear.
pub fn slices<'a>(configs: impl IntoIterator<Item = &'a Config>, named: &[Axis]) -> Vec<Slice> {
    let mut firsts: Vec<&Config> = Vec::new();
    for c in configs {
        if !firsts.iter().any(|f| f.agrees_except(c, named)) {
            firsts.push(c);
        }
    }
    let varies = |a: Axis| !named.contains(&a) && firsts.iter().any(|f| differs(f, firsts[0], a));
    firsts
        .iter()
        .map(|f| Slice {
            config: (*f).clone(),
            varying: f.values().into_iter().filter(|(a, _)| varies(*a)).collect(),
        })
        .collect()
}

fn differs(a: &Config, b: &Config, axis: Axis) -> bool {
    let value = |c: &Config| c.values().into_iter().find(|(x, _)| *x == axis).map(|(_, v)| v);
    value(a) != value(b)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn axes() -> Axes {
        Axes {
            schemes: vec![DiskScheme::Uniform, DiskScheme::Paper],
            patterns: vec![Pattern::PerPixel],
            samples: vec![4, 16],
            light_radii: vec![0.01, 0.02],
            light_counts: vec![1, 2],
            accelerators: vec!["bvh".into()],
            seeds: vec![1, 2],
        }
    }

    #[test]
    fn configurations_nest_by_level_then_in_declared_order() {
        let got: Vec<(u32, f64, DiskScheme, u32)> = axes()
            .configs()
            .iter()
            .map(|c| (c.lights, c.light_radius, c.scheme, c.samples))
            .collect();
        let mut want = Vec::new();
        for lights in [1, 2] {
            for r in [0.01, 0.02] {
                for s in [DiskScheme::Uniform, DiskScheme::Paper] {
                    for n in [4, 16] {
                        want.push((lights, r, s, n));
                    }
                }
            }
        }
        assert_eq!(got, want);
        assert_eq!(nested(&[2, 0], &[0, 1]), Vec::<Vec<usize>>::new());
    }

    #[test]
    fn slices_split_on_the_axes_not_named() {
        let configs = axes().configs();
        let named = [Axis::Scheme, Axis::Pattern, Axis::Samples, Axis::LightRadius];
        let s = slices(&configs, &named);
        assert_eq!(s.len(), 2);
        assert_eq!(s[1].varying, vec![(Axis::Lights, "2".to_string())]);
        assert_eq!(configs.iter().filter(|c| s[1].holds(c, &named)).count(), 8);
        let all: Vec<Axis> = Axis::ALL.to_vec();
        let one = slices(&configs, &all);
        assert_eq!((one.len(), one[0].varying.len()), (1, 0));
    }
}
