//! The keys every experiment file shares, read and validated once by the driver before the
//! kind reads the rest: `kind`, `name` (the results folder's name: a plain name, never a path),
//! `backend` and the `[timing]` table ([`crate::timing::Schedule`]).

use super::kind::Kind;
use crate::config::{ConfigError, Source};
use crate::key_path;
use crate::render::BackendChoice;
use crate::timing::{Schedule, DEFAULT_SEED};
use serde::Deserialize;

/// Longest experiment, mesh or scene name that becomes a file name.
pub const MAX_NAME: usize = 64;

/// The shared keys of an experiment file, validated.
#[derive(Clone, Debug, PartialEq)]
pub struct Header {
    /// The kind that reads the rest of the file.
    pub kind: Kind,
    /// Whether the file says `kind` (a file without it is read as a sweep).
    pub kind_declared: bool,
    /// Results folder name.
    pub name: String,
    /// The renderer the file asks for, if it names one.
    pub backend: Option<BackendChoice>,
    /// How the kind's timed units are visited.
    pub schedule: Schedule,
}

#[derive(Deserialize)]
struct File {
    kind: Option<Kind>,
    name: Option<toml::Value>,
    backend: Option<BackendChoice>,
    timing: Option<TimingTable>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TimingTable {
    warmup: Option<u32>,
    repeats: Option<u32>,
    seed: Option<u32>,
}

/// Declares an experiment kind's file struct: the kind's own keys plus the shared header's
/// (`kind`, `name`, `backend`, `[timing]`), which [`Header::read`] validates, so that
/// `deny_unknown_fields` accepts them and no kind reads them twice.
#[macro_export]
macro_rules! experiment_file {
    ($(#[$meta:meta])* struct $name:ident { $($(#[$fmeta:meta])* $field:ident : $ty:ty),* $(,)? }) => {
        $(#[$meta])*
        #[derive(Debug, serde::Deserialize)]
        #[serde(deny_unknown_fields)]
        struct $name {
            #[allow(dead_code)]
            kind: Option<serde::de::IgnoredAny>,
            #[allow(dead_code)]
            name: Option<serde::de::IgnoredAny>,
            #[allow(dead_code)]
            backend: Option<serde::de::IgnoredAny>,
            #[allow(dead_code)]
            timing: Option<serde::de::IgnoredAny>,
            $($(#[$fmeta])* $field: $ty),*
        }
    };
}

/// Whether `name` may become a file or folder name under an output folder: 1 to [`MAX_NAME`]
/// letters, digits, `-`, `_` or `.`, starting with a letter or digit (so never `.`, `..`, a
/// hidden name, a path or an absolute path).
pub fn plain_name(name: &str) -> Result<(), String> {
    let ok = |c: char| c.is_ascii_alphanumeric() || "-_.".contains(c);
    if name.is_empty() {
        Err("must not be empty".into())
    } else if name.len() > MAX_NAME {
        Err(format!("is {} characters long; at most {MAX_NAME}", name.len()))
    } else if !name.starts_with(|c: char| c.is_ascii_alphanumeric()) || !name.chars().all(ok) {
        Err(format!(
            "`{}` is not a plain name: use letters, digits, `-`, `_` and `.`, starting with a letter or digit (it names a folder or file, never a path)",
            name.escape_debug()
        ))
    } else {
        Ok(())
    }
}

impl Header {
    /// Reads and validates the shared keys; `kind` defaults to a sweep; `repeats` must be 0
    /// (nothing timed, where the kind allows it) or at least the kind's minimum.
    pub fn read(source: &Source) -> Result<Header, ConfigError> {
        let f: File = source.parse()?;
        let kind = f.kind.unwrap_or_default();
        let name = match f.name {
            None => {
                return Err(source.error(
                    &key_path!["name"],
                    "missing: every experiment names its results folder, e.g. name = \"sphere\"",
                ))
            }
            Some(toml::Value::String(s)) => s,
            Some(other) => {
                return Err(source.error(
                    &key_path!["name"],
                    format!("must be a string, got {}", other.type_str()),
                ))
            }
        };
        plain_name(&name).map_err(|m| source.error(&key_path!["name"], m))?;
        let t = f.timing.unwrap_or(TimingTable {
            warmup: None,
            repeats: None,
            seed: None,
        });
        let schedule = Schedule {
            seed: t.seed.unwrap_or(DEFAULT_SEED),
            warmup: t.warmup.unwrap_or(1),
            repeats: t.repeats.unwrap_or(kind.default_repeats()),
        };
        let (min, untimed) = (kind.min_repeats(), kind.may_skip_timing());
        if (schedule.repeats == 0 && !untimed) || (schedule.repeats > 0 && schedule.repeats < min) {
            let zero = if untimed { "0 (no timing) or " } else { "" };
            return Err(source.error(
                &key_path!["timing", "repeats"],
                format!(
                    "must be {zero}at least {min} (interleaved rounds behind each median and its 95 % interval), got {}",
                    schedule.repeats
                ),
            ));
        }
        if schedule.repeats > MAX_REPEATS || schedule.warmup > MAX_REPEATS {
            let key = if schedule.warmup > MAX_REPEATS {
                "warmup"
            } else {
                "repeats"
            };
            return Err(source.error(&key_path!["timing", key], format!("must be at most {MAX_REPEATS}")));
        }
        Ok(Header {
            kind,
            kind_declared: f.kind.is_some(),
            name,
            backend: f.backend,
            schedule,
        })
    }
}

/// Most timed or warm-up frames per unit a file may ask for: beyond it a run never ends in
/// practice.
pub const MAX_REPEATS: u32 = 1000;

#[cfg(test)]
mod tests {
    use super::*;

    fn read(text: &str) -> Result<Header, ConfigError> {
        Header::read(&Source {
            path: "e.toml".into(),
            text: text.into(),
        })
    }

    #[test]
    fn names_are_plain_folder_names() {
        for good in ["sphere", "body-structures", "a.b_c", "X1"] {
            assert!(plain_name(good).is_ok(), "{good}");
        }
        for bad in [
            "",
            ".",
            "..",
            "../x",
            "/abs/x",
            "a/b",
            ".hidden",
            "a\\b",
            "a b",
            "é",
            &"x".repeat(65),
        ] {
            assert!(plain_name(bad).is_err(), "{bad:?}");
        }
    }

    #[test]
    fn the_header_is_read_and_located() {
        let h = read("name = \"a\"\nkind = \"ao\"\n[timing]\nrepeats = 7\nseed = 3\n").unwrap();
        assert_eq!(
            (h.kind, h.schedule.repeats, h.schedule.seed, h.schedule.warmup),
            (Kind::Ao, 7, 3, 1)
        );
        let e = read("kind = \"ao\"\n").unwrap_err();
        assert_eq!((e.key.as_str(), e.position), ("name", None), "{e}");
        let e = read("name = \"../../x\"\n").unwrap_err();
        assert_eq!((e.key.as_str(), e.position.map(|p| p.0)), ("name", Some(1)), "{e}");
        let e = read("name = 3\n").unwrap_err();
        assert!(e.message.contains("string"), "{e}");
        let e = read("name = \"a\"\n[timing]\nrepeats = 2\n").unwrap_err();
        assert_eq!(e.key, "timing.repeats", "{e}");
        assert!(
            read("name = \"a\"\n[timing]\nrepeats = 0\n").is_ok(),
            "a sweep may time nothing"
        );
        let e = read("name = \"a\"\nkind = \"frames\"\n[timing]\nrepeats = 0\n").unwrap_err();
        assert_eq!(e.key, "timing.repeats", "{e}");
        let e = read("name = \"a\"\n[timing]\nrepeats = 4294967295\n").unwrap_err();
        assert!(e.message.contains("at most"), "{e}");
        let e = read("name = \"a\"\n[timing]\nrepeat = 5\n").unwrap_err();
        assert!(e.key.contains("repeat") && e.message.contains("unknown"), "{e}");
    }
}
