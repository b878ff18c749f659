//! CSV tables as serde rows, written and read by the csv crate. A row's columns are its fields;
//! a row made of parts (a tuple, or a type that serializes as one) has its parts' fields in
//! order. Floats are written in their shortest round-trip form (`format!("{x}")`, never exponent
//! notation) and NaN as an empty field, so a row read back and written again is byte for byte
//! the same.

use crate::files::write_atomic;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use std::fmt::Display;
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
        write_rows(&path, rows.iter().cloned()).unwrap();
        let text = fs::read_to_string(&path).unwrap();
        assert_eq!(text, "key,x,n,y\na,0.00001,3,\n\"b,c\",1,,-0.25\n");
        let back: Vec<(Head, Tail)> = read_rows(&path);
        assert_eq!(back.len(), 2);
        assert!(back[0].1.y.is_nan());
        write_rows(&dir.path().join("u.csv"), &back).unwrap();
        assert_eq!(fs::read_to_string(dir.path().join("u.csv")).unwrap(), text);
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
