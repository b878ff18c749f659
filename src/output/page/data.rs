//! page_data.js: the page's galleries and tables as one script (`window.PENUMBRA = {...}`), since
//! a `file://` page may load scripts but not read files. Image values are little-endian f32,
//! zlib-compressed, base64-encoded; an image equal to an earlier one of its gallery is stored once
//! (`same`); FLIP maps, which the page only shows and reads out to three decimals, as bytes
//! (value x 255, rounded).

use super::Gallery;
use flate2::write::ZlibEncoder;
use flate2::Compression;
use serde::Serialize;
use std::collections::BTreeMap;
use std::io::Write;

/// A gallery as the page reads it.
#[derive(Serialize)]
pub struct GalleryData {
    title: String,
    width: u32,
    height: u32,
    tone: super::Tone,
    reference: Option<usize>,
    shots: Vec<ShotData>,
}

#[derive(Serialize)]
struct ShotData {
    label: String,
    exr: String,
    png: String,
    key: BTreeMap<String, String>,
    /// Compressed values, or `None` where `same` names the equal earlier shot.
    data: Option<String>,
    same: Option<usize>,
    flip: Option<String>,
}

/// A CSV table as the page reads it (a table too large to show has no header and no rows).
#[derive(Serialize)]
pub struct TableData {
    file: String,
    header: Vec<String>,
    rows: Vec<Vec<String>>,
    shown: bool,
}

/// A table the page links to without showing it.
pub fn linked(file: &str) -> TableData {
    TableData {
        file: file.to_string(),
        header: vec![],
        rows: vec![],
        shown: false,
    }
}

/// Packs a gallery with its FLIP maps (one per shot, `None` where there is none).
pub fn gallery(g: &Gallery, flips: Vec<Option<Vec<f32>>>) -> anyhow::Result<GalleryData> {
    let n = g.width as usize * g.height as usize;
    let mut shots = Vec::with_capacity(g.shots.len());
    for (i, (s, flip)) in g.shots.iter().zip(flips).enumerate() {
        anyhow::ensure!(
            s.values.len() == n,
            "image {:?} has {} values, its gallery {:?} is {}x{}",
            s.label,
            s.values.len(),
            g.title,
            g.width,
            g.height
        );
        let same = g.shots[..i].iter().position(|e| bits_equal(&e.values, &s.values));
        let data = match same {
            Some(_) => None,
            None => Some(pack(bytemuck::cast_slice(&to_le(&s.values)))?),
        };
        let flip = match flip {
            Some(f) => Some(pack(
                &f.iter()
                    .map(|v| (v.clamp(0.0, 1.0) * 255.0).round() as u8)
                    .collect::<Vec<_>>(),
            )?),
            None => None,
        };
        shots.push(ShotData {
            label: s.label.clone(),
            exr: s.exr.clone(),
            png: s.png.clone(),
            key: s.key.iter().cloned().collect(),
            data,
            same,
            flip,
        });
    }
    Ok(GalleryData {
        title: g.title.clone(),
        width: g.width,
        height: g.height,
        tone: g.tone,
        reference: g.reference,
        shots,
    })
}

fn bits_equal(a: &[f32], b: &[f32]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

fn to_le(values: &[f32]) -> Vec<u32> {
    values.iter().map(|v| v.to_bits().to_le()).collect()
}

/// Reads a CSV file's text into the page's table.
pub fn table(file: &str, text: &str) -> anyhow::Result<TableData> {
    let mut reader = csv::ReaderBuilder::new().flexible(true).from_reader(text.as_bytes());
    let header = reader.headers()?.iter().map(str::to_string).collect();
    let rows = reader
        .records()
        .map(|r| r.map(|r| r.iter().map(str::to_string).collect()))
        .collect::<Result<_, _>>()
        .map_err(|e| anyhow::anyhow!("{file}: {e}"))?;
    Ok(TableData {
        file: file.to_string(),
        header,
        rows,
        shown: true,
    })
}

/// The script that hands galleries and tables to the page.
pub fn script(galleries: &[GalleryData], tables: &[TableData]) -> anyhow::Result<String> {
    #[derive(Serialize)]
    struct All<'a> {
        galleries: &'a [GalleryData],
        tables: &'a [TableData],
    }
    let json = serde_json::to_string(&All { galleries, tables })?;
    Ok(format!("window.PENUMBRA = {json};\n"))
}

/// zlib then base64.
fn pack(bytes: &[u8]) -> anyhow::Result<String> {
    let mut z = ZlibEncoder::new(Vec::new(), Compression::best());
    z.write_all(bytes)?;
    Ok(base64(&z.finish()?))
}

/// Standard base64 with padding (RFC 4648), what the page's `atob` reads.
fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [chunk[0], *chunk.get(1).unwrap_or(&0), *chunk.get(2).unwrap_or(&0)];
        let n = (b[0] as u32) << 16 | (b[1] as u32) << 8 | b[2] as u32;
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(ALPHABET[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use flate2::read::ZlibDecoder;
    use std::io::Read;

    #[test]
    fn base64_matches_the_rfc_vectors() {
        for (plain, coded) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(base64(plain.as_bytes()), coded);
        }
        assert_eq!(base64(&[0xfb, 0xff, 0xbf]), "+/+/");
    }

    fn unbase64(s: &str) -> Vec<u8> {
        const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
        let mut bits = 0u32;
        let mut n = 0;
        let mut out = vec![];
        for c in s.bytes().filter(|&c| c != b'=') {
            bits = bits << 6 | ALPHABET.iter().position(|&a| a == c).unwrap() as u32;
            n += 6;
            if n >= 8 {
                n -= 8;
                out.push((bits >> n) as u8);
            }
        }
        out
    }

    #[test]
    fn packed_values_unpack_to_the_same_bits_and_equal_images_are_stored_once() {
        let values = vec![0.0f32, -0.0, 1.0, -1.0, 0.1, f32::MIN_POSITIVE, 3.0e38, f32::INFINITY];
        let shot = |label: &str, values: Vec<f32>| super::super::Shot {
            label: label.into(),
            exr: format!("{label}.exr"),
            png: format!("{label}.png"),
            values,
            key: vec![("scheme".into(), label.into())],
        };
        let g = Gallery {
            title: "t".into(),
            width: 8,
            height: 1,
            tone: super::super::Tone::Linear,
            reference: Some(0),
            shots: vec![
                shot("a", values.clone()),
                shot("b", values.clone()),
                shot("c", vec![0.5; 8]),
            ],
        };
        let d = gallery(
            &g,
            vec![None, Some(vec![0.0, 0.5, 1.0, 2.0, -1.0, 0.2, 0.0, 0.0]), None],
        )
        .unwrap();
        let mut bytes = vec![];
        ZlibDecoder::new(unbase64(d.shots[0].data.as_ref().unwrap()).as_slice())
            .read_to_end(&mut bytes)
            .unwrap();
        let back: Vec<u32> = bytes
            .chunks(4)
            .map(|c| u32::from_le_bytes(c.try_into().unwrap()))
            .collect();
        assert_eq!(back, values.iter().map(|v| v.to_bits()).collect::<Vec<_>>());
        assert_eq!((d.shots[1].same, d.shots[1].data.is_none()), (Some(0), true));
        assert_eq!(d.shots[2].same, None);
        let mut flip = vec![];
        ZlibDecoder::new(unbase64(d.shots[1].flip.as_ref().unwrap()).as_slice())
            .read_to_end(&mut flip)
            .unwrap();
        assert_eq!(flip, vec![0, 128, 255, 255, 0, 51, 0, 0]);
        let wrong = Gallery { width: 9, ..g };
        assert!(gallery(&wrong, vec![None; 3]).is_err());
    }
}
