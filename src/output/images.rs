//! Float images to files: EXR keeps the measured values, PNG shows them (visibility in grey,
//! signed errors on a blue-white-red scale). Receiver-less pixels are drawn dark blue.

use crate::files::write_atomic;
use crate::render::NO_RECEIVER;
use anyhow::anyhow;
use std::io::Cursor;
use std::path::Path;

/// An 8-bit RGB picture, row-major.
#[derive(Clone, Debug)]
pub struct Rgb {
    /// Width.
    pub width: u32,
    /// Height.
    pub height: u32,
    /// 3 bytes per pixel.
    pub data: Vec<u8>,
}

const NO_RECEIVER_RGB: [u8; 3] = [20, 24, 60];

fn to_byte(x: f64) -> u8 {
    (x.clamp(0.0, 1.0) * 255.0).round() as u8
}

/// Visibility (or any [0, 1] quantity) as grey; [`NO_RECEIVER`] as dark blue.
pub fn grey(values: &[f32], width: u32, height: u32) -> Rgb {
    let data = values
        .iter()
        .flat_map(|&v| {
            if v == NO_RECEIVER {
                NO_RECEIVER_RGB
            } else {
                [to_byte(v as f64); 3]
            }
        })
        .collect();
    Rgb { width, height, data }
}

/// Radiance tone-mapped for display with its own exposure ([`exposure`]).
pub fn tonemap(values: &[f32], width: u32, height: u32) -> Rgb {
    tonemap_with(values, width, height, exposure(values))
}

/// The exposure of a picture: the 99th percentile of its positive radiance.
pub fn exposure(values: &[f32]) -> f64 {
    let mut sorted: Vec<f32> = values.iter().copied().filter(|v| *v > 0.0).collect();
    sorted.sort_by(f32::total_cmp);
    sorted.get(sorted.len() * 99 / 100).copied().unwrap_or(1.0).max(1e-12) as f64
}

/// Radiance tone-mapped for display: x / (1 + x) after scaling `p99` to 1, then sRGB-like gamma
/// 1/2.2. Pictures compared with each other share one exposure (the reference's).
pub fn tonemap_with(values: &[f32], width: u32, height: u32, p99: f64) -> Rgb {
    let data = values
        .iter()
        .flat_map(|&v| {
            let x = 2.0 * v as f64 / p99;
            [to_byte((x / (1.0 + x)).powf(1.0 / 2.2)); 3]
        })
        .collect();
    Rgb { width, height, data }
}

/// Signed difference a - b on a diverging scale saturating at +-`scale` (blue negative, red
/// positive); pixels where either is [`NO_RECEIVER`] are dark blue.
pub fn diverging(a: &[f32], b: &[f32], scale: f64, width: u32, height: u32) -> Rgb {
    let data = a
        .iter()
        .zip(b)
        .flat_map(|(&x, &y)| {
            if x == NO_RECEIVER || y == NO_RECEIVER {
                return NO_RECEIVER_RGB;
            }
            diverging_colour((x - y) as f64 / scale)
        })
        .collect();
    Rgb { width, height, data }
}

/// The colour [`diverging`] gives a difference of `t` times its scale: white at 0, full red at
/// +1 and beyond, full blue at -1 and below (also what a colour bar beside the map shows).
pub fn diverging_colour(t: f64) -> [u8; 3] {
    let t = t.clamp(-1.0, 1.0);
    if t >= 0.0 {
        [255, to_byte(1.0 - t), to_byte(1.0 - t)]
    } else {
        [to_byte(1.0 + t), to_byte(1.0 + t), 255]
    }
}

/// Writes a PNG atomically.
pub fn write_png(path: &Path, img: &Rgb) -> anyhow::Result<()> {
    let buf = image::RgbImage::from_raw(img.width, img.height, img.data.clone())
        .ok_or_else(|| anyhow!("image buffer size mismatch"))?;
    let mut bytes = Vec::new();
    buf.write_to(&mut Cursor::new(&mut bytes), image::ImageFormat::Png)?;
    write_atomic(path, &bytes)
}

/// Writes a one-channel float EXR (channel `Y`) atomically.
pub fn write_exr(path: &Path, values: &[f32], width: u32, height: u32) -> anyhow::Result<()> {
    write_exr_as(path, values, width, height, |v| v)
}

/// Writes a one-channel EXR at half precision: for pictures that are looked at, not measured
/// (the page stores them at the same precision, so its readouts equal the file).
pub fn write_exr_half(path: &Path, values: &[f32], width: u32, height: u32) -> anyhow::Result<()> {
    write_exr_as(path, values, width, height, half::f16::from_f32)
}

fn write_exr_as<T: exr::prelude::IntoSample>(
    path: &Path,
    values: &[f32],
    width: u32,
    height: u32,
    sample: impl Fn(f32) -> T + Sync,
) -> anyhow::Result<()> {
    let bytes = exr_bytes_as(values, width, height, sample).map_err(|e| anyhow!("encoding {}: {e}", path.display()))?;
    write_atomic(path, &bytes)
}

/// A one-channel float EXR (channel `Y`) as bytes, for files written as part of a set.
pub fn exr_bytes(values: &[f32], width: u32, height: u32) -> anyhow::Result<Vec<u8>> {
    exr_bytes_as(values, width, height, |v| v)
}

fn exr_bytes_as<T: exr::prelude::IntoSample>(
    values: &[f32],
    width: u32,
    height: u32,
    sample: impl Fn(f32) -> T + Sync,
) -> anyhow::Result<Vec<u8>> {
    use exr::prelude::*;
    let w = width as usize;
    let channels = SpecificChannels::build()
        .with_channel("Y")
        .with_pixel_fn(|p: Vec2<usize>| (sample(values[p.y() * w + p.x()]),));
    let image = Image::from_channels((w, height as usize), channels);
    let mut bytes = Cursor::new(Vec::new());
    image.write().to_buffered(&mut bytes).map_err(|e| anyhow!("{e}"))?;
    Ok(bytes.into_inner())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exr_round_trips_values() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("v.exr");
        let values = vec![0.0, 0.25, 1.0, NO_RECEIVER, 0.5, 0.125];
        write_exr(&p, &values, 3, 2).unwrap();
        let img = exr::prelude::read_first_flat_layer_from_file(&p).unwrap();
        let ch = &img.layer_data.channel_data.list[0];
        let read: Vec<f32> = ch.sample_data.values_as_f32().collect();
        assert_eq!(read, values);
    }

    #[test]
    fn colour_scales() {
        assert_eq!(
            grey(&[0.0, 1.0, NO_RECEIVER], 3, 1).data,
            vec![0, 0, 0, 255, 255, 255, 20, 24, 60]
        );
        let d = diverging(&[1.0, 0.0, 0.5], &[0.0, 1.0, 0.5], 0.5, 3, 1).data;
        assert_eq!(d, vec![255, 0, 0, 0, 0, 255, 255, 255, 255]);
    }
}
