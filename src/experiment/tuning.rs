//! What the kinds that tune a structure per scene (ao, frames) share: the verdict each candidate
//! got ([`crate::timing::tuning`]), the per-round times behind it, and `--tuning FILE`, which
//! takes the settings an earlier run kept from its `tuning.csv` instead of timing them again, so
//! that shards, merges, resumes and reruns build the same structures and count the same work.

use crate::accel::settings::parameter_columns;
use crate::accel::AccelSettings;
use crate::timing::tuning::{considered_word, Kept};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// How one candidate was judged, as tuning.csv records it.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Verdict {
    /// Its index among its structure's candidates (0: the default, the first listed values).
    pub candidate: usize,
    /// The candidate it was compared with (the one kept when it was considered).
    pub against: usize,
    /// `default`, the rule's word against `against`, or `reused` (kept by `--tuning`).
    pub word: String,
    /// Its time per round, seconds (empty where it was not timed).
    pub rounds: Vec<f64>,
}

/// The word a candidate kept from `--tuning FILE` carries.
pub const REUSED: &str = "reused";

impl Verdict {
    /// Candidate `candidate`, kept by `--tuning` and not timed.
    pub fn reused(candidate: usize) -> Verdict {
        Verdict {
            candidate,
            against: candidate,
            word: REUSED.into(),
            rounds: vec![],
        }
    }

    /// Whether it was timed here (not taken from `--tuning`).
    pub fn timed(&self) -> bool {
        self.word != REUSED
    }
}

/// One verdict per candidate of `kept`, with the rounds timed (`times`, one series per candidate).
pub fn verdicts(kept: &Kept, times: Vec<Vec<f64>>) -> Vec<Verdict> {
    kept.considered
        .iter()
        .zip(times)
        .enumerate()
        .map(|(candidate, (c, rounds))| Verdict {
            candidate,
            against: c.against,
            word: considered_word(c).to_string(),
            rounds,
        })
        .collect()
}

/// A row of tuning_rounds.csv: a candidate's time in one round. `scene` is the kind's scene key
/// (ao: the mesh; frames: the scene's name), as in tuning.csv.
#[derive(serde::Serialize)]
pub struct RoundRow<'a> {
    /// The mesh or scene.
    pub scene: &'a str,
    /// Structure name.
    pub structure: &'a str,
    /// Candidate index ([`Verdict::candidate`]).
    pub candidate: usize,
    /// Round.
    pub round: usize,
    /// Seconds.
    #[serde(with = "crate::output::table::float")]
    pub time_s: f64,
}

/// Every round of `verdict`, as rows of tuning_rounds.csv.
pub fn round_rows<'a>(
    scene: &'a str,
    structure: &'a str,
    verdict: &'a Verdict,
) -> impl Iterator<Item = RoundRow<'a>> + 'a {
    verdict.rounds.iter().enumerate().map(move |(round, &time_s)| RoundRow {
        scene,
        structure,
        candidate: verdict.candidate,
        round,
        time_s,
    })
}

/// The settings an earlier run kept, per scene and structure, read from its tuning.csv
/// (`--tuning FILE`).
#[derive(Clone, Debug, PartialEq)]
pub struct KeptTuning {
    /// The file read.
    pub path: PathBuf,
    kept: BTreeMap<(String, String), AccelSettings>,
}

impl KeptTuning {
    /// Reads the rows of `path` whose `chosen` is true; `scene_column` names the kind's scene
    /// key. An error names the file, the line and the column.
    pub fn read(path: &Path, scene_column: &str) -> Result<KeptTuning, String> {
        let at = |line: u64, what: String| format!("{}:{line}: {what}", path.display());
        let mut reader = csv::Reader::from_path(path).map_err(|e| format!("{}: cannot read: {e}", path.display()))?;
        let headers = reader
            .headers()
            .map_err(|e| format!("{}: cannot read its header: {e}", path.display()))?
            .clone();
        let column = |name: &str| {
            headers
                .iter()
                .position(|h| h == name)
                .ok_or_else(|| at(1, format!("no `{name}` column (not a tuning.csv of this kind?)")))
        };
        let (scene, structure, chosen) = (column(scene_column)?, column("structure")?, column("chosen")?);
        let mut kept = BTreeMap::new();
        for record in reader.records() {
            let record = record.map_err(|e| format!("{}: {e}", path.display()))?;
            let line = record.position().map_or(0, |p| p.line());
            match &record[chosen] {
                "true" => {}
                "false" => continue,
                other => return Err(at(line, format!("`chosen` is `{other}`, not true or false"))),
            }
            let name = &record[structure];
            let mut params = toml::Table::new();
            for c in parameter_columns().iter().filter(|c| c.structure == name) {
                let Some(i) = headers.iter().position(|h| h == c.name) else {
                    continue;
                };
                if !record[i].is_empty() {
                    params.insert(c.key.clone(), parameter_value(&record[i]));
                }
            }
            let settings =
                AccelSettings::with(name, &params).map_err(|e| at(line, format!("structure `{name}`: {e}")))?;
            let key = (record[scene].to_string(), name.to_string());
            if kept.insert(key, settings).is_some() {
                return Err(at(
                    line,
                    format!("a second kept setting of `{name}` on `{}`", &record[scene]),
                ));
            }
        }
        Ok(KeptTuning {
            path: path.to_path_buf(),
            kept,
        })
    }

    /// The settings kept for `structure` on `scene`, if the file has them.
    pub fn get(&self, scene: &str, structure: &str) -> Option<&AccelSettings> {
        self.kept.get(&(scene.to_string(), structure.to_string()))
    }

    /// Checks that the file keeps a setting for every `(scene, structure)` the experiment tunes
    /// (`tuned` lists each one's candidates; one candidate is not tuned), and that it is one of
    /// the candidates there: a file from another experiment, or from a run filtered to fewer
    /// scenes, would otherwise slip in a setting never offered or leave a structure to be timed
    /// again, apart from the rest.
    pub fn check<'a>(&self, tuned: impl IntoIterator<Item = (&'a str, &'a [AccelSettings])>) -> Result<(), String> {
        for (scene, candidates) in tuned {
            let [first, _, ..] = candidates else { continue };
            let Some(kept) = self.get(scene, first.name) else {
                return Err(format!(
                    "{}: keeps no setting of `{}` on `{scene}`, which this experiment tunes (a file from a filtered run, or another experiment?)",
                    self.path.display(),
                    first.name
                ));
            };
            if !candidates.contains(kept) {
                return Err(format!(
                    "{}: `{}` on `{scene}` kept {}, which is not among the experiment's candidates",
                    self.path.display(),
                    first.name,
                    kept.describe()
                ));
            }
        }
        Ok(())
    }
}

/// A parameter's text from a table cell as the TOML value an experiment file would give.
fn parameter_value(text: &str) -> toml::Value {
    if let Ok(i) = text.parse::<i64>() {
        toml::Value::Integer(i)
    } else if let Ok(x) = text.parse::<f64>() {
        toml::Value::Float(x)
    } else if let Ok(b) = text.parse::<bool>() {
        toml::Value::Boolean(b)
    } else {
        toml::Value::String(text.to_string())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::settings::ParameterColumns;

    /// A tuning.csv as the ao kind writes it: mesh, structure, the parameter columns, chosen.
    fn write(dir: &Path, rows: &[(&str, &AccelSettings, bool)]) -> PathBuf {
        let path = dir.join("tuning.csv");
        let mut w = csv::Writer::from_path(&path).unwrap();
        #[derive(serde::Serialize)]
        struct Row<'a> {
            mesh: &'a str,
            structure: &'a str,
        }
        #[derive(serde::Serialize)]
        struct Chosen {
            chosen: bool,
        }
        for (mesh, s, chosen) in rows {
            w.serialize((
                Row {
                    mesh,
                    structure: s.name,
                },
                ParameterColumns::of(s),
                Chosen { chosen: *chosen },
            ))
            .unwrap();
        }
        w.flush().unwrap();
        path
    }

    fn kd(depth: i64, split: &str) -> AccelSettings {
        let t = toml::toml! { max_depth = depth };
        let mut t = t.clone();
        t.insert("split".into(), split.into());
        AccelSettings::with("kdtree", &t).unwrap()
    }

    #[test]
    fn kept_settings_read_back_equal_to_those_written() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (kd(16, "median"), kd(23, "sah"));
        let vlf = AccelSettings::with("vlf", &toml::toml! { depth = 3 }).unwrap();
        let path = write(
            dir.path(),
            &[
                ("cow", &a, false),
                ("cow", &b, true),
                ("cow", &vlf, true),
                ("man", &a, true),
            ],
        );
        let kept = KeptTuning::read(&path, "mesh").unwrap();
        assert_eq!(kept.get("cow", "kdtree"), Some(&b));
        assert_eq!(kept.get("cow", "vlf"), Some(&vlf));
        assert_eq!(kept.get("man", "kdtree"), Some(&a));
        assert_eq!(kept.get("man", "vlf"), None);
        assert!(kept.check([("cow", &[a.clone(), b.clone()][..])]).is_ok());
        let err = kept.check([("man", &[vlf.clone(), vlf.clone()][..])]).unwrap_err();
        assert!(err.contains("keeps no setting of `vlf` on `man`"), "{err}");
        assert!(
            kept.check([("man", &[vlf.clone()][..])]).is_ok(),
            "one candidate is not tuned"
        );
        let err = kept.check([("cow", &[a.clone(), kd(40, "median")][..])]).unwrap_err();
        assert!(err.contains("not among the experiment's candidates"), "{err}");
    }

    #[test]
    fn a_bad_file_is_refused_naming_its_line_and_column() {
        let dir = tempfile::tempdir().unwrap();
        let a = kd(16, "median");
        let path = write(dir.path(), &[("cow", &a, true), ("cow", &kd(19, "median"), true)]);
        let err = KeptTuning::read(&path, "mesh").unwrap_err();
        assert!(
            err.contains("tuning.csv:3:") && err.contains("second kept setting"),
            "{err}"
        );
        let err = KeptTuning::read(&path, "scene").unwrap_err();
        assert!(err.contains(":1:") && err.contains("no `scene` column"), "{err}");
        let bad = dir.path().join("bad.csv");
        let text = std::fs::read_to_string(&path).unwrap().replacen(",16,", ",-3,", 1);
        std::fs::write(&bad, text).unwrap();
        let err = KeptTuning::read(&bad, "mesh").unwrap_err();
        assert!(err.contains("bad.csv:2:") && err.contains("max_depth"), "{err}");
        assert!(KeptTuning::read(&dir.path().join("none.csv"), "mesh")
            .unwrap_err()
            .contains("cannot read"));
    }
}
