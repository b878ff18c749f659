//! CSV tables as serde rows, written and read by the csv crate. A row's columns are its fields;
//! a row made of parts (a tuple, or a type that serializes as one) has its parts' fields in
//! order. Floats are written in their shortest round-trip form (`format!("{x}")`, never exponent
//! notation) and NaN as an empty field, so a row read back and written again is byte for byte
//! the same.

use crate::files::write_atomic;
use anyhow::Context;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use std::fmt::Display;
use std::fs::OpenOptions;
use std::io::Write;
use std::os::unix::fs::OpenOptionsExt;
use std::path::Path;
use std::str::FromStr;

/// Writes `rows` to `path` atomically, under the header csv names from the first row.
pub fn write_rows<T: Serialize>(path: &Path, rows: impl IntoIterator<Item = T>) -> anyhow::Result<()> {
    let mut w = csv::Writer::from_writer(Vec::new());
    for r in rows {
        w.serialize(r)?;
    }
    write_atomic(path, &w.into_inner()?)
}

/// The seal of an appended table `path`: `PATH.seal`, holding the length of the table as last
/// appended and the FNV-1a of those bytes.
fn seal_of(path: &Path) -> std::path::PathBuf {
    let mut name = path.as_os_str().to_owned();
    name.push(".seal");
    name.into()
}

/// The (length, FNV-1a) a seal holds; none where there is no seal; an error where it does not
/// read as one.
fn read_seal(path: &Path) -> anyhow::Result<Option<(u64, u64)>> {
    let seal = seal_of(path);
    if std::fs::symlink_metadata(&seal).is_err() {
        return Ok(None);
    }
    let text = crate::files::read_regular_text(&seal)?;
    let parsed = text
        .trim()
        .split_once(' ')
        .and_then(|(len, hash)| Some((len.parse().ok()?, u64::from_str_radix(hash, 16).ok()?)));
    parsed
        .map(Some)
        .ok_or_else(|| anyhow::anyhow!("{}: not a seal (`LENGTH HASH`)", seal.display()))
}

/// A journal table that is not what its appends wrote: bad input, with what to do about it.
fn tampered(path: &Path, why: &str) -> anyhow::Error {
    crate::files::Refused(format!(
        "{}: {why}; remove the journal to measure again, or rerun with --fresh",
        path.display()
    ))
    .into()
}

/// Appends `rows` to the CSV file at `path` (a new file gets the header first; a symbolic link
/// there is refused), flushes them to disk and seals the table ([`read_sealed`] reads it): rows
/// a killed append left past the seal are dropped first, so the seal always covers the table.
pub fn append_sealed<T: Serialize>(path: &Path, rows: impl IntoIterator<Item = T>) -> anyhow::Result<()> {
    let (len, hash) = read_seal(path)?.unwrap_or((0, crate::fingerprint::FNV1A_BASIS));
    let on_disk = std::fs::symlink_metadata(path).map_or(0, |m| m.len());
    if on_disk < len {
        return Err(tampered(path, "shorter than its seal says"));
    }
    if on_disk > len {
        OpenOptions::new()
            .write(true)
            .custom_flags(libc::O_NOFOLLOW)
            .open(path)
            .and_then(|f| f.set_len(len))
            .with_context(|| format!("dropping the unsealed end of {}", path.display()))?;
    }
    let mut w = csv::WriterBuilder::new().has_headers(len == 0).from_writer(Vec::new());
    for r in rows {
        w.serialize(r)?;
    }
    let bytes = w.into_inner()?;
    let mut f = OpenOptions::new()
        .create(true)
        .append(true)
        .custom_flags(libc::O_NOFOLLOW)
        .open(path)
        .with_context(|| format!("appending to {}", path.display()))?;
    f.write_all(&bytes)?;
    f.sync_data()?;
    let sealed = format!(
        "{} {:016x}\n",
        len + bytes.len() as u64,
        crate::fingerprint::fnv1a_on(hash, &bytes)
    );
    write_atomic(&seal_of(path), sealed.as_bytes())
}

/// The rows of a table [`append_sealed`] wrote, as [`read_rows`] reads them, from the bytes its
/// seal covers (an append killed before sealing is not read); refused where those bytes are not
/// the ones sealed (an edited or cut journal is never taken as measured). A table without a
/// seal holds nothing sealed: none of its rows are read.
pub fn read_sealed<T: Serialize + DeserializeOwned>(path: &Path) -> anyhow::Result<Vec<T>> {
    let exists = std::fs::symlink_metadata(path).is_ok();
    // No seal: nothing was sealed (a run killed during its first append), so nothing is read,
    // and the next append starts the table again.
    let Some((len, hash)) = read_seal(path)? else {
        return Ok(vec![]);
    };
    let bytes = if exists {
        crate::files::read_regular(path)?
    } else {
        Vec::new()
    };
    if (bytes.len() as u64) < len {
        return Err(tampered(path, "shorter than its seal says (cut)"));
    }
    let sealed = &bytes[..len as usize];
    if crate::fingerprint::fnv1a(sealed) != hash {
        return Err(tampered(path, "changed since it was sealed (its hash does not match)"));
    }
    let text = std::str::from_utf8(sealed).map_err(|_| tampered(path, "not UTF-8"))?;
    Ok(rows_of(text))
}

/// The rows of the CSV file at `path`, if its header is the one `T` is written under: a missing
/// file or another header gives none; a torn last line (from a crash) and rows that do not read
/// as a `T` are dropped. Rows are read by position, so that rows made of parts read back.
pub fn read_rows<T: Serialize + DeserializeOwned>(path: &Path) -> Vec<T> {
    let Ok(text) = crate::files::read_regular_text(path) else {
        return vec![];
    };
    rows_of(&text)
}

/// The rows of CSV `text` ([`read_rows`]).
fn rows_of<T: Serialize + DeserializeOwned>(text: &str) -> Vec<T> {
    let complete = &text[..text.rfind('\n').map_or(0, |i| i + 1)];
    let mut reader = csv::ReaderBuilder::new()
        .flexible(true)
        .from_reader(complete.as_bytes());
    let Ok(header) = reader.headers().cloned() else {
        return vec![];
    };
    let rows: Vec<T> = reader
        .records()
        .filter_map(Result::ok)
        .filter(|r| r.len() == header.len())
        .filter_map(|r| r.deserialize(None).ok())
        .collect();
    match rows.first().map(header_of) {
        Some(Ok(h)) if h == header => rows,
        _ => vec![],
    }
}

/// A row as (column, cell) pairs, the text a table holds: how a picture names the table rows it
/// belongs to.
pub fn cells<T: Serialize>(row: &T) -> anyhow::Result<Vec<(String, String)>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.serialize(row)?;
    let bytes = w.into_inner()?;
    let mut r = csv::Reader::from_reader(bytes.as_slice());
    let header = r.headers()?.clone();
    let record = r.records().next().transpose()?.unwrap_or_default();
    Ok(header
        .iter()
        .zip(record.iter())
        .map(|(h, c)| (h.to_string(), c.to_string()))
        .collect())
}

/// The header csv writes for `row`.
fn header_of<T: Serialize>(row: &T) -> anyhow::Result<csv::StringRecord> {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.serialize(row)?;
    let bytes = w.into_inner()?;
    Ok(csv::Reader::from_reader(bytes.as_slice()).headers()?.clone())
}

/// A float as a table writes it: shortest round-trip text, NaN empty.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Float(pub f64);

impl Serialize for Float {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        if self.0.is_nan() {
            s.serialize_str("")
        } else {
            s.collect_str(&self.0)
        }
    }
}

/// `#[serde(with = "float")]` on an `f64` field: written as [`Float`], an empty field read as NaN.
pub mod float {
    use super::*;

    /// Writes `x` as [`Float`].
    pub fn serialize<S: Serializer>(x: &f64, s: S) -> Result<S::Ok, S::Error> {
        Float(*x).serialize(s)
    }

    /// Reads a float; an empty field is NaN.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        let s = String::deserialize(d)?;
        if s.is_empty() {
            Ok(f64::NAN)
        } else {
            s.parse().map_err(serde::de::Error::custom)
        }
    }
}

/// `#[serde(with = "text")]`: a value as its `Display` text, read back with `FromStr` (axis
/// values, which are written as they are named in experiment files and filters).
pub mod text {
    use super::*;

    /// Writes `value`'s text.
    pub fn serialize<T: Display, S: Serializer>(value: &T, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(value)
    }

    /// Reads a value from its text.
    pub fn deserialize<'de, T, D>(d: D) -> Result<T, D::Error>
    where
        T: FromStr,
        T::Err: Display,
        D: Deserializer<'de>,
    {
        String::deserialize(d)?.parse().map_err(serde::de::Error::custom)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::fs;

    #[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
    struct Head {
        key: String,
        #[serde(with = "float")]
        x: f64,
    }

    #[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
    struct Tail {
        n: Option<u64>,
        #[serde(with = "float")]
        y: f64,
    }

    #[test]
    fn rows_of_parts_round_trip_byte_for_byte() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.csv");
        let rows = [
            (
                Head {
                    key: "a".into(),
                    x: 1e-5,
                },
                Tail {
                    n: Some(3),
                    y: f64::NAN,
                },
            ),
            (
                Head {
                    key: "b,c".into(),
                    x: 1.0,
                },
                Tail { n: None, y: -0.25 },
            ),
        ];
        append_sealed(&path, rows[..1].iter().cloned()).unwrap();
        append_sealed(&path, rows[1..].iter().cloned()).unwrap();
        let text = fs::read_to_string(&path).unwrap();
        assert_eq!(text, "key,x,n,y\na,0.00001,3,\n\"b,c\",1,,-0.25\n");
        assert_eq!(read_rows::<(Head, Tail)>(&path).len(), 2);
        let back: Vec<(Head, Tail)> = read_sealed(&path).unwrap();
        assert_eq!(back.len(), 2);
        assert!(back[0].1.y.is_nan());
        write_rows(&dir.path().join("u.csv"), &back).unwrap();
        assert_eq!(fs::read_to_string(dir.path().join("u.csv")).unwrap(), text);
    }

    /// A sealed table reads back only as its appends wrote it: a changed byte, a cut, a missing
    /// seal are refused; rows a killed append left past the seal are not read, and the next
    /// append drops them.
    #[test]
    fn a_sealed_table_refuses_edits_and_cuts_and_drops_an_unsealed_end() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("j.csv");
        let row = |k: &str, x: f64| Head { key: k.into(), x };
        assert!(read_sealed::<Head>(&path).unwrap().is_empty());
        append_sealed(&path, [row("a", 1.0), row("b", 2.0)]).unwrap();
        let good = fs::read_to_string(&path).unwrap();
        for (bad, why) in [
            (good.replace("b,2", "b,3"), "changed since it was sealed"),
            (good[..good.len() - 2].to_string(), "cut"),
        ] {
            fs::write(&path, &bad).unwrap();
            let e = format!("{:#}", read_sealed::<Head>(&path).unwrap_err());
            assert!(e.contains(why) && e.contains("j.csv") && e.contains("--fresh"), "{e}");
        }
        fs::write(&path, format!("{good}c,3\n")).unwrap();
        assert_eq!(
            read_sealed::<Head>(&path).unwrap().len(),
            2,
            "the unsealed row is not read"
        );
        append_sealed(&path, [row("d", 4.0)]).unwrap();
        let keys: Vec<String> = read_sealed::<Head>(&path).unwrap().into_iter().map(|h| h.key).collect();
        assert_eq!(keys, ["a", "b", "d"]);
        fs::remove_file(dir.path().join("j.csv.seal")).unwrap();
        assert!(
            read_sealed::<Head>(&path).unwrap().is_empty(),
            "nothing sealed, nothing read"
        );
        append_sealed(&path, [row("e", 5.0)]).unwrap();
        assert_eq!(
            fs::read_to_string(&path).unwrap(),
            "key,x\ne,5\n",
            "the unsealed table starts again"
        );
    }

    #[test]
    fn torn_lines_and_other_headers_are_dropped() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.csv");
        fs::write(&path, "key,x\na,1\nb,2\nc,").unwrap();
        assert_eq!(read_rows::<Head>(&path).len(), 2);
        fs::write(&path, "key,z\na,1\n").unwrap();
        assert!(read_rows::<Head>(&path).is_empty());
        assert!(read_rows::<Head>(&dir.path().join("missing.csv")).is_empty());
    }

    #[test]
    fn an_append_through_a_planted_link_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let (outside, path) = (dir.path().join("outside.csv"), dir.path().join("t.csv"));
        fs::write(&outside, "theirs\n").unwrap();
        std::os::unix::fs::symlink(&outside, &path).unwrap();
        let e = append_sealed(
            &path,
            [Head {
                key: "a".into(),
                x: 1.0,
            }],
        )
        .unwrap_err();
        assert!(format!("{e:#}").contains("t.csv"), "{e:#}");
        assert_eq!(fs::read_to_string(&outside).unwrap(), "theirs\n");
        assert!(read_rows::<Head>(&path).is_empty(), "nothing read through the link");
    }
}

/// A list of rows held as the CSV text a table of them would be (header and rows), for a
/// record that carries its own table inside a TOML journal: the rows read back exactly as the
/// table's reader reads them.
pub mod csv_text {
    use super::*;

    /// Writes `rows` as CSV text.
    pub fn serialize<T: Serialize, S: Serializer>(rows: &[T], s: S) -> Result<S::Ok, S::Error> {
        let mut w = csv::Writer::from_writer(Vec::new());
        for r in rows {
            w.serialize(r).map_err(serde::ser::Error::custom)?;
        }
        let bytes = w.into_inner().map_err(serde::ser::Error::custom)?;
        s.serialize_str(&String::from_utf8(bytes).map_err(serde::ser::Error::custom)?)
    }

    /// Reads rows from CSV text, by position (so rows made of parts read back); a row that does
    /// not read is an error.
    pub fn deserialize<'de, T: DeserializeOwned, D: Deserializer<'de>>(d: D) -> Result<Vec<T>, D::Error> {
        let text = String::deserialize(d)?;
        csv::Reader::from_reader(text.as_bytes())
            .records()
            .map(|r| r.and_then(|r| r.deserialize(None)))
            .collect::<Result<Vec<T>, _>>()
            .map_err(serde::de::Error::custom)
    }
}

/// An image of f32 values held as the hex of their little-endian bits: exact, NaN payloads
/// included, and a third the size of their decimal text.
pub mod f32_hex {
    use super::*;

    /// Writes `values` as hex.
    pub fn serialize<S: Serializer>(values: &[f32], s: S) -> Result<S::Ok, S::Error> {
        let mut text = String::with_capacity(values.len() * 8);
        for v in values {
            for b in v.to_bits().to_le_bytes() {
                text.push_str(&format!("{b:02x}"));
            }
        }
        s.serialize_str(&text)
    }

    /// Reads values from hex; text that is not whole values' hex is an error.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<f32>, D::Error> {
        let text = String::deserialize(d)?;
        let bad = || serde::de::Error::custom("an image's hex is not a whole number of f32 values");
        if text.len() % 8 != 0 || !text.is_ascii() {
            return Err(bad());
        }
        (0..text.len() / 8)
            .map(|i| {
                let mut bytes = [0u8; 4];
                for (k, b) in bytes.iter_mut().enumerate() {
                    let at = 8 * i + 2 * k;
                    *b = u8::from_str_radix(&text[at..at + 2], 16).map_err(|_| bad())?;
                }
                Ok(f32::from_bits(u32::from_le_bytes(bytes)))
            })
            .collect()
    }
}
