//! A structure's build parameters, read from its own table (`[accel.NAME]` in scene and
//! experiment files; pbrt-v4's `CreateAccelerator(name, parameters)`). Each structure declares
//! a typed parameter struct ([`Params`]) with its defaults and ranges; the rest of the program
//! carries the validated table ([`AccelSettings`]) and never names a structure's keys.
//!
//! In an experiment that tunes, a key may hold a list: every combination is a candidate
//! ([`candidates`]); where the file gives no list, the structure's own grid is tried
//! ([`Params::tuning`]).

use super::{registered, Registered};
use crate::config::{ConfigError, Seg, Source};
use serde::de::DeserializeOwned;
use serde::Serialize;
use std::collections::BTreeMap;

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

    /// `key=value` pairs, in key order: the parameters in a few words.
    pub fn describe(&self) -> String {
        if self.params.is_empty() {
            return "defaults".into();
        }
        self.params
            .iter()
            .map(|(k, v)| match v {
                toml::Value::String(s) => format!("{k}={s}"),
                v => format!("{k}={v}"),
            })
            .collect::<Vec<_>>()
            .join(" ")
    }
}

impl Default for AccelSettings {
    fn default() -> Self {
        AccelSettings::default_for(&super::REGISTRY[0])
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
