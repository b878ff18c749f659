//! A structure's build parameters, read from its own table (`[accel.NAME]` in scene and
//! experiment files; pbrt-v4's `CreateAccelerator(name, parameters)`). Each structure declares
//! a typed parameter struct ([`Params`]) with its defaults and ranges; the rest of the program
//! carries the validated table ([`AccelSettings`]) and never names a structure's keys.
//!
//! In an experiment that tunes, a key may hold a list: every combination is a candidate
//! ([`candidates`]); where the file gives no list, the structure's own grid is tried
//! ([`Params::tuning`]).
//!
//! In tables the parameters are spread one value per column ([`ParameterColumns`]): a column
//! per parameter of every registered structure, `STRUCTURE_KEY` (`vlf_depth`,
//! `kdtree_max_depth`, `bvh_preset`), empty where a row's structure is another.

use super::{registered, Registered};
use crate::config::{ConfigError, Seg, Source};
use serde::de::{DeserializeOwned, SeqAccess, Visitor};
use serde::ser::SerializeStruct;
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use std::collections::BTreeMap;
use std::sync::OnceLock;

/// A structure's typed parameters: serde with defaults for absent keys and unknown keys
/// refused, plus the checks serde cannot make.
pub trait Params: Serialize + DeserializeOwned + Default {
    /// The first key out of range and why.
    fn check(&self) -> Result<(), (&'static str, String)>;

    /// The same structure's parameters with the keys it ignores set to their defaults (a
    /// kd-tree's SAH constants under a median split), so that candidates building the same
    /// structure compare equal and a tuning grid times each once.
    fn canonical(self) -> Self {
        self
    }

    /// The candidates an experiment tunes over when its file lists none: each key's values
    /// (the paper's among them), as a table of lists.
    fn tuning() -> toml::Table {
        toml::Table::new()
    }
}

/// A registered structure and its parameters, validated with every default filled in (made
/// only by this module's constructors, so the parameters are always the named structure's).
#[derive(Clone, Debug, PartialEq)]
pub struct AccelSettings {
    /// Registry name.
    pub name: &'static str,
    params: toml::Table,
}

/// Settings journaled with a unit's outcome: the name and the parameters, validated again when
/// read back.
impl serde::Serialize for AccelSettings {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        let mut st = s.serialize_struct("AccelSettings", 2)?;
        st.serialize_field("name", self.name)?;
        st.serialize_field("params", &self.params)?;
        st.end()
    }
}

impl<'de> serde::Deserialize<'de> for AccelSettings {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<AccelSettings, D::Error> {
        #[derive(serde::Deserialize)]
        struct Raw {
            name: String,
            params: toml::Table,
        }
        let raw = Raw::deserialize(d)?;
        AccelSettings::with(&raw.name, &raw.params).map_err(serde::de::Error::custom)
    }
}

/// A structure's registry name, as rows carry it (one of the registry's own strings).
pub type RegistryName = &'static str;

/// Serde for a structure's registry name held as `&'static str` (rows journaled by the
/// experiment core): read back as the registry's own name, or refused.
pub mod registry_name {
    /// Writes the name.
    pub fn serialize<S: serde::Serializer>(name: &&'static str, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(name)
    }

    /// Reads a registered name.
    pub fn deserialize<'de, D: serde::Deserializer<'de>>(d: D) -> Result<&'static str, D::Error> {
        let name = <String as serde::Deserialize>::deserialize(d)?;
        super::registered(&name)
            .map(|r| r.name)
            .ok_or_else(|| serde::de::Error::custom(format!("unknown acceleration structure `{name}`")))
    }
}

impl AccelSettings {
    /// `r`'s defaults.
    pub fn default_for(r: &Registered) -> AccelSettings {
        AccelSettings {
            name: r.name,
            params: (r.params)(&toml::Table::new()).expect("a structure's defaults are valid"),
        }
    }

    /// The defaults of the structure registered as `name`.
    pub fn named(name: &str) -> Option<AccelSettings> {
        registered(name).map(AccelSettings::default_for)
    }

    /// The structure registered as `name` with `params` (absent keys take defaults), or why not.
    pub fn with(name: &str, params: &toml::Table) -> Result<AccelSettings, String> {
        let r = registered(name).ok_or_else(|| format!("unknown acceleration structure `{name}`"))?;
        let params = (r.params)(params).map_err(|(k, m)| format!("key `{k}`: {m}"))?;
        Ok(AccelSettings { name: r.name, params })
    }

    /// Its parameters, one value per key.
    pub fn params(&self) -> &toml::Table {
        &self.params
    }

    /// The typed parameters of structure `P` (validated when these settings were made).
    pub fn typed<P: Params>(&self) -> P {
        toml::Value::Table(self.params.clone())
            .try_into()
            .expect("settings hold validated parameters")
    }

    /// The text of parameter `key`'s value (a string without quotes), if it has that key.
    pub fn value(&self, key: &str) -> Option<String> {
        self.params.get(key).map(|v| match v {
            toml::Value::String(s) => s.clone(),
            v => v.to_string(),
        })
    }

    /// `key=value` pairs, in key order: the parameters in a few words.
    pub fn describe(&self) -> String {
        if self.params.is_empty() {
            return "defaults".into();
        }
        self.params
            .keys()
            .map(|k| format!("{k}={}", self.value(k).unwrap_or_default()))
            .collect::<Vec<_>>()
            .join(" ")
    }
}

impl Default for AccelSettings {
    fn default() -> Self {
        AccelSettings::default_for(&super::REGISTRY[0])
    }
}

/// A parameter of a registered structure, as a table column.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ParameterColumn {
    /// The structure's registry name.
    pub structure: &'static str,
    /// The parameter's key in `[accel.STRUCTURE]`.
    pub key: String,
    /// The column's name, `STRUCTURE_KEY`.
    pub name: String,
}

/// One column per parameter of every registered structure, in registry and then key order.
pub fn parameter_columns() -> &'static [ParameterColumn] {
    static COLUMNS: OnceLock<Vec<ParameterColumn>> = OnceLock::new();
    COLUMNS.get_or_init(|| {
        super::REGISTRY
            .iter()
            .flat_map(|r| {
                keys(r).into_iter().map(|key| ParameterColumn {
                    structure: r.name,
                    name: format!("{}_{key}", r.name),
                    key,
                })
            })
            .collect()
    })
}

/// Every key a structure's parameters can hold: its defaults' and, since a choice can bring
/// keys of its own (the kd-tree's SAH costs come with `split = "sah"`), those of each value of
/// its tuning grid taken alone; in the order first met.
fn keys(r: &super::Registered) -> Vec<String> {
    let mut keys: Vec<String> = AccelSettings::default_for(r).params.keys().cloned().collect();
    for (key, values) in (r.tuning)() {
        for v in values.as_array().into_iter().flatten() {
            let one = toml::Table::from_iter([(key.clone(), v.clone())]);
            for (k, _) in (r.params)(&one).into_iter().flatten() {
                if !keys.contains(&k) {
                    keys.push(k);
                }
            }
        }
    }
    keys
}

/// A row's structure parameters as table columns, one value per column
/// ([`parameter_columns`]): its own structure's columns hold its values, every other column is
/// empty, so that a table can be filtered on any one parameter.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ParameterColumns(Vec<String>);

impl ParameterColumns {
    /// No structure: every column empty.
    pub fn none() -> ParameterColumns {
        ParameterColumns(vec![String::new(); parameter_columns().len()])
    }

    /// The columns of `settings`.
    pub fn of(settings: &AccelSettings) -> ParameterColumns {
        ParameterColumns(
            parameter_columns()
                .iter()
                .map(|c| {
                    (c.structure == settings.name)
                        .then(|| settings.value(&c.key))
                        .flatten()
                        .unwrap_or_default()
                })
                .collect(),
        )
    }

    /// The value in column `name` (empty where the row's structure has no such parameter).
    pub fn get(&self, name: &str) -> Option<&str> {
        let i = parameter_columns().iter().position(|c| c.name == name)?;
        self.0.get(i).map(String::as_str)
    }
}

impl Serialize for ParameterColumns {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let columns = parameter_columns();
        let mut row = s.serialize_struct("ParameterColumns", columns.len())?;
        for (c, v) in columns.iter().zip(&self.0) {
            row.serialize_field(c.name.as_str(), v)?;
        }
        row.end()
    }
}

impl<'de> Deserialize<'de> for ParameterColumns {
    /// Reads the columns by position, as many as [`parameter_columns`] names.
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<ParameterColumns, D::Error> {
        struct Columns;
        impl<'de> Visitor<'de> for Columns {
            type Value = ParameterColumns;

            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                write!(f, "{} parameter columns", parameter_columns().len())
            }

            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<ParameterColumns, A::Error> {
                let n = parameter_columns().len();
                let mut values = Vec::with_capacity(n);
                for i in 0..n {
                    values.push(
                        seq.next_element::<String>()?
                            .ok_or_else(|| serde::de::Error::invalid_length(i, &self))?,
                    );
                }
                Ok(ParameterColumns(values))
            }
        }
        d.deserialize_tuple(parameter_columns().len(), Columns)
    }
}

/// Validates `table` as `P`'s parameters and completes it with defaults; an error names the
/// key that is wrong.
pub fn validate<P: Params>(table: &toml::Table) -> Result<toml::Table, (String, String)> {
    // Key by key first, so a wrong type or unknown key is blamed on its own key.
    for (k, v) in table {
        let one = toml::Table::from_iter([(k.clone(), v.clone())]);
        if let Err(e) = toml::Value::Table(one).try_into::<P>() {
            return Err((k.clone(), e.to_string().trim().to_string()));
        }
    }
    let p: P = toml::Value::Table(table.clone())
        .try_into()
        .map_err(|e: toml::de::Error| (String::new(), e.to_string()))?;
    p.check().map_err(|(k, m)| (k.to_string(), m))?;
    toml::Table::try_from(p.canonical()).map_err(|e| (String::new(), e.to_string()))
}

/// The `[accel.*]` tables of a file at `at` (e.g. `["accel"]`): each name a registered
/// structure, each table its parameters. With `lists`, a key may list values to tune over (the
/// combinations, each validated); otherwise one value each. Returns every combination per named
/// structure, by structure name. An empty table is the structure's defaults, one candidate.
pub fn read_tables(
    source: &Source,
    at: &[Seg],
    tables: &BTreeMap<String, toml::Table>,
    lists: bool,
) -> Result<BTreeMap<&'static str, Vec<AccelSettings>>, ConfigError> {
    let mut out = BTreeMap::new();
    for (name, table) in tables {
        let mut path = at.to_vec();
        path.push(Seg::Key(name.clone()));
        let r = registered(name).ok_or_else(|| {
            source.error(
                &path,
                format!(
                    "unknown acceleration structure `{name}`; known: {}",
                    super::names().join(", ")
                ),
            )
        })?;
        if !lists {
            if let Some((k, _)) = table.iter().find(|(_, v)| v.is_array()) {
                let mut p = path.clone();
                p.push(Seg::Key(k.clone()));
                return Err(source.error(&p, "one value here: only a tuning experiment lists candidates"));
            }
        }
        out.insert(
            r.name,
            candidates(r, table).map_err(|(k, m)| located(source, &path, &k, m))?,
        );
    }
    Ok(out)
}

fn located(source: &Source, table: &[Seg], key: &str, message: String) -> ConfigError {
    let mut p = table.to_vec();
    if !key.is_empty() {
        p.push(Seg::Key(key.to_string()));
    }
    source.error(&p, message)
}

/// Most candidates one structure's lists may expand to.
pub const MAX_CANDIDATES: usize = 256;

/// Every combination of `table`'s listed values (a key with one value is one choice), each
/// validated by `r`.
pub fn candidates(r: &Registered, table: &toml::Table) -> Result<Vec<AccelSettings>, (String, String)> {
    let mut combos = vec![toml::Table::new()];
    for (k, v) in table {
        let values = match v {
            toml::Value::Array(a) if a.is_empty() => return Err((k.clone(), "lists no value".into())),
            toml::Value::Array(a) => a.clone(),
            v => vec![v.clone()],
        };
        if combos.len() * values.len() > MAX_CANDIDATES {
            return Err((k.clone(), format!("more than {MAX_CANDIDATES} candidates in all")));
        }
        combos = combos
            .into_iter()
            .flat_map(|c| {
                values.iter().map(move |v| {
                    let mut c = c.clone();
                    c.insert(k.clone(), v.clone());
                    c
                })
            })
            .collect();
    }
    let mut out: Vec<AccelSettings> = Vec::new();
    for c in combos {
        let s = AccelSettings {
            name: r.name,
            params: (r.params)(&c)?,
        };
        if !out.contains(&s) {
            out.push(s);
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::table::{read_rows, write_rows};

    #[test]
    fn every_parameter_of_every_structure_has_its_own_column() {
        let names: Vec<&str> = parameter_columns().iter().map(|c| c.name.as_str()).collect();
        assert_eq!(
            names,
            [
                "bvh_preset",
                "vlf_depth",
                "vlf_leaf_size",
                "vlf_level",
                "vlf_split",
                "vlf_tiles",
                "kdtree_leaf_size",
                "kdtree_max_depth",
                "kdtree_split",
                "kdtree_empty_factor",
                "kdtree_intersection_cost",
                "kdtree_traversal_cost",
                "kdtree-sah_empty_factor",
                "kdtree-sah_intersection_cost",
                "kdtree-sah_leaf_size",
                "kdtree-sah_max_depth",
                "kdtree-sah_split",
                "kdtree-sah_traversal_cost",
                "cwbvh_preset"
            ]
        );
        // The SAH's costs, which only a SAH tree has, have their columns too.
        let sah = AccelSettings::with("kdtree", &toml::toml! { split = "sah" traversal_cost = 5.0 }).unwrap();
        assert_eq!(ParameterColumns::of(&sah).get("kdtree_traversal_cost"), Some("5.0"));
        let kd = AccelSettings::with("kdtree", &toml::toml! { max_depth = 7 }).unwrap();
        let columns = ParameterColumns::of(&kd);
        assert_eq!(columns.get("kdtree_max_depth"), Some("7"));
        assert_eq!(columns.get("kdtree_leaf_size"), Some("8"));
        assert_eq!(columns.get("vlf_leaf_size"), Some(""));
        assert_eq!(columns.get("parameters"), None);
        let bvh = ParameterColumns::of(&AccelSettings::named("bvh").unwrap());
        assert_eq!(bvh.get("bvh_preset"), Some("medium"));
        assert_eq!(bvh.get("kdtree_max_depth"), Some(""));
    }

    #[derive(Serialize, Deserialize, Debug, PartialEq)]
    struct Key {
        structure: String,
    }

    #[test]
    fn parameter_columns_read_back_as_written() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.csv");
        let rows: Vec<(Key, ParameterColumns, Key)> = ["vlf", "brute", "kdtree"]
            .iter()
            .map(|name| {
                let key = || Key {
                    structure: name.to_string(),
                };
                (key(), ParameterColumns::of(&AccelSettings::named(name).unwrap()), key())
            })
            .chain([(
                Key {
                    structure: "none".into(),
                },
                ParameterColumns::none(),
                Key {
                    structure: "none".into(),
                },
            )])
            .collect();
        write_rows(&path, &rows).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.starts_with("structure,bvh_preset,vlf_depth,"), "{text}");
        assert!(text.contains("\nbrute,,,,,,,,,,,,,,,,,,,,brute\n"), "{text}");
        assert_eq!(read_rows::<(Key, ParameterColumns, Key)>(&path), rows);
    }
}
