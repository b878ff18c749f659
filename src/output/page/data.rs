//! page_data.js: the page's galleries and tables as one script (`window.PENUMBRA = {...}`), since
//! a `file://` page may load scripts but not read files. An image's values are stored as the
//! gallery stores them (f32, or f16 for pictures: [`super::Gallery::stored`]): each value's bit
//! pattern minus the previous pixel's (wrapping), split into byte planes (low bytes first), then
//! zlib and base64. Neighbouring pixels share their high bytes, so the planes compress where raw
//! floats would not (a noisy 320x240 radiance picture: 400 KB as f32, ~35 KB so). An image equal
//! to an earlier one of its gallery is stored once (`same`); FLIP maps, which the page only shows
//! and reads out to three decimals, as bytes (value x 255, rounded), with their exact mean; each
//! table as its packed JSON.

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
    /// Bits per stored value: 32 or 16.
    bits: u32,
    reference: Option<usize>,
    against: Option<usize>,
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
    /// Mean of the FLIP map before it was quantised to bytes.
    flip_mean: Option<f64>,
}

/// A CSV table as the page reads it: its header and rows as packed JSON (`None` for a table too
/// large to show, which the page only links to).
#[derive(Serialize)]
pub struct TableData {
    file: String,
    packed: Option<String>,
}

/// A table the page links to without showing it.
pub fn linked(file: &str) -> TableData {
    TableData {
        file: file.to_string(),
        packed: None,
    }
}

/// Packs a gallery, its values at half precision where `half`, with its FLIP maps (one per shot,
/// `None` where there is none).
pub fn gallery(g: &Gallery, half: bool, flips: Vec<Option<Vec<f32>>>) -> anyhow::Result<GalleryData> {
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
            None => Some(pack(&planes(&super::stored_as(s, half), half))?),
        };
        let flip_mean = flip
            .as_ref()
            .map(|f| f.iter().map(|&v| v as f64).sum::<f64>() / f.len().max(1) as f64);
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
            flip_mean,
        });
    }
    Ok(GalleryData {
        title: g.title.clone(),
        width: g.width,
        height: g.height,
        tone: g.tone,
        bits: if half { 16 } else { 32 },
        reference: g.reference,
        against: g.against,
        shots,
    })
}

fn bits_equal(a: &[f32], b: &[f32]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

/// The values' bit patterns (f32, or f16 when `half`), each minus the previous one (wrapping),
/// as byte planes: every value's lowest byte, then every value's next byte, and so on.
fn planes(values: &[f32], half: bool) -> Vec<u8> {
    let bits: Vec<u32> = if half {
        values
            .iter()
            .map(|&v| half::f16::from_f32(v).to_bits() as u32)
            .collect()
    } else {
        values.iter().map(|v| v.to_bits()).collect()
    };
    let width = if half { 2 } else { 4 };
    let mask = if half { 0xffff } else { u32::MAX };
    let mut out = vec![0u8; bits.len() * width];
    let mut previous = 0u32;
    for (i, &b) in bits.iter().enumerate() {
        let delta = b.wrapping_sub(previous) & mask;
        previous = b;
        for plane in 0..width {
            out[plane * bits.len() + i] = (delta >> (8 * plane)) as u8;
        }
    }
    out
}

/// Reads a CSV file's text into the page's table.
pub fn table(file: &str, text: &str) -> anyhow::Result<TableData> {
    let mut reader = csv::ReaderBuilder::new().flexible(true).from_reader(text.as_bytes());
    let header: Vec<String> = reader.headers()?.iter().map(str::to_string).collect();
    let rows: Vec<Vec<String>> = reader
        .records()
        .map(|r| r.map(|r| r.iter().map(str::to_string).collect()))
        .collect::<Result<_, _>>()
        .map_err(|e| anyhow::anyhow!("{file}: {e}"))?;
    #[derive(Serialize)]
    struct Shown {
        header: Vec<String>,
        rows: Vec<Vec<String>>,
    }
    let json = serde_json::to_string(&Shown { header, rows })?;
    Ok(TableData {
        file: file.to_string(),
        packed: Some(pack(json.as_bytes())?),
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
            against: None,
            shots: vec![
                shot("a", values.clone()),
                shot("b", values.clone()),
                shot("c", vec![0.5; 8]),
            ],
        };
        let d = gallery(
            &g,
            false,
            vec![None, Some(vec![0.0, 0.5, 1.0, 2.0, -1.0, 0.2, 0.0, 0.0]), None],
        )
        .unwrap();
        assert_eq!(d.bits, 32);
        let back = unplanes(&inflate(d.shots[0].data.as_ref().unwrap()), 4);
        assert_eq!(back, values.iter().map(|v| v.to_bits()).collect::<Vec<_>>());
        assert_eq!((d.shots[1].same, d.shots[1].data.is_none()), (Some(0), true));
        assert_eq!(d.shots[2].same, None);
        assert_eq!(
            inflate(d.shots[1].flip.as_ref().unwrap()),
            vec![0, 128, 255, 255, 0, 51, 0, 0]
        );
        // The exact mean, not the bytes' (2.7 / 8 before clamping and rounding).
        let exact: f64 = [0.5f32, 1.0, 2.0, -1.0, 0.2].iter().map(|&v| v as f64).sum();
        assert_eq!(d.shots[1].flip_mean, Some(exact / 8.0));
        let wrong = Gallery { width: 9, ..g.clone() };
        assert!(gallery(&wrong, false, vec![None; 3]).is_err());
        // A picture gallery stores half floats: the page's values are the f16 roundings, a
        // finite value beyond the half range its largest (3e38), infinity itself.
        let picture = Gallery {
            tone: super::super::Tone::Radiance { p99: 1.0 },
            ..g
        };
        let d = gallery(&picture, picture.half(), vec![None; 3]).unwrap();
        assert_eq!(d.bits, 16);
        let back = unplanes(&inflate(d.shots[0].data.as_ref().unwrap()), 2);
        let want: Vec<u32> = values
            .iter()
            .map(|&v| half::f16::from_f32(if v.is_finite() { v.clamp(-65504.0, 65504.0) } else { v }).to_bits() as u32)
            .collect();
        assert_eq!(back, want);
        assert_eq!(half::f16::from_bits(back[4] as u16).to_f32(), 0.099975586);
        assert_eq!(half::f16::from_bits(back[6] as u16), half::f16::MAX);
        assert_eq!(back[1], 0x8000, "negative zero keeps its sign");
        assert_eq!(picture.stored(&picture.shots[0])[7], f32::INFINITY);
        // The same gallery kept at full precision (a rebuilt folder's f32 pictures).
        let full = gallery(&picture, false, vec![None; 3]).unwrap();
        assert_eq!(full.bits, 32);
        let back = unplanes(&inflate(full.shots[0].data.as_ref().unwrap()), 4);
        assert_eq!(back, values.iter().map(|v| v.to_bits()).collect::<Vec<_>>());
    }

    fn inflate(b64: &str) -> Vec<u8> {
        let mut bytes = vec![];
        ZlibDecoder::new(unbase64(b64).as_slice())
            .read_to_end(&mut bytes)
            .unwrap();
        bytes
    }

    /// Byte planes back to bit patterns, each delta added to the previous value (what the page
    /// does).
    fn unplanes(bytes: &[u8], width: usize) -> Vec<u32> {
        let n = bytes.len() / width;
        let mask = if width == 2 { 0xffff } else { u32::MAX };
        let mut previous = 0u32;
        (0..n)
            .map(|i| {
                let delta = (0..width).fold(0u32, |d, p| d | (bytes[p * n + i] as u32) << (8 * p));
                previous = previous.wrapping_add(delta) & mask;
                previous
            })
            .collect()
    }
}
