//! A user's own pattern: a sampling scheme read from a points file, so that a point set from an
//! optimiser, a paper's supplement or a notebook is swept, rendered on both backends, measured
//! and reported like a built-in scheme without writing Rust or WGSL.
//!
//! A points file is text: one sample per line, two numbers separated by a comma and/or spaces;
//! `#` starts a comment; the first line may be a header of names (`u,v`). Its layout, set in the
//! experiment's `[points.NAME]` table:
//! - `shared`: sample k of every pixel is line k (the paper's precomputed buffer, one pattern
//!   for the whole image and every seed);
//! - `tile`: a `tile` x `tile` tile of pixels, each with its own `count` samples, pixel-major
//!   (pixel (x, y) of the tile is lines (y tile + x) count .. + count), the tile shifted per seed
//!   and light as the built-in blue-noise tiles are ([`super::bluenoise::tile_index`]);
//! - `mask`: a shared set (the points file) rotated per pixel, modulo 1, by the offset at the
//!   pixel's place in a tile read from a second file (`mask`: `tile`^2 lines of (du, dv) in
//!   [0, 1), row-major) plus one random shift per seed and light, exactly as the built-in
//!   `bluenoise-cp` rotates its set (Cranley-Patterson; Georgiev & Fajardo 2016), so every pixel's
//!   samples are uniform over seeds.
//!
//! Points are in the unit square (`domain = "square"`, mapped to the disk by the concentric map
//! like the built-ins; values in [0, 1)) or already on the unit disk (`domain = "disk"`, |p| <= 1;
//! not with a mask). Values are stored as the GPU reads them, so that both backends see the same
//! numbers: square coordinates as 24-bit fractions (the built-ins' resolution), disk coordinates
//! as multiples of 2^-23.

mod table;

pub use table::{load_all, Table};

use super::bluenoise::{cp_shift, tile_index_in};
use crate::config::ConfigError;
use crate::fingerprint::fnv1a;
use glam::DVec2;
use std::path::{Path, PathBuf};
use std::sync::{OnceLock, RwLock};

/// Largest points file read (bytes): a 64 x 64 tile of 256 samples per pixel is ~25 MB of text.
pub const MAX_POINTS_BYTES: u64 = 64 << 20;

/// Most u32 words of points one set may hold: 32 MiB, a quarter of the smallest storage
/// binding wgpu offers by default (128 MiB), leaving room for the frame's other tables.
pub const MAX_POINTS_WORDS: u64 = 8 << 20;

/// Largest tile side of the `tile` and `mask` layouts.
pub const MAX_TILE: u32 = 256;

/// Where the file's coordinates live.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Domain {
    /// The unit square, mapped to the disk by the concentric map.
    Square,
    /// The unit disk itself.
    Disk,
}

/// How the file's samples are given to pixels (module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Layout {
    /// One set for every pixel.
    Shared,
    /// One set per pixel of a tile of this side.
    Tile(u32),
    /// One shared set rotated per pixel by a mask of offsets over a tile of this side.
    Mask(u32),
}

/// A loaded point set.
#[derive(Clone, Debug, PartialEq)]
pub struct PointSet {
    /// What experiment files, CSV columns and reports call it (`points:NAME`).
    pub name: String,
    /// The points file (and the mask file, for the `mask` layout).
    pub files: Vec<PathBuf>,
    /// FNV-1a of the files' bytes and the settings, in hex: part of every run key and the
    /// manifest, so an edited file never reuses a result.
    pub hash: String,
    /// Where the coordinates live.
    pub domain: Domain,
    /// How pixels get samples.
    pub layout: Layout,
    /// Samples each pixel has.
    pub count: u32,
    /// The samples, as stored for the GPU: 24-bit fractions (square) or i32 multiples of 2^-23
    /// as bits (disk); pixel-major for the tile layout.
    pub points: Vec<[u32; 2]>,
    /// The mask layout's offsets (24-bit fractions), row-major over the tile; empty otherwise.
    pub offsets: Vec<[u32; 2]>,
}

/// The settings of a points scheme, from the experiment's `[points.NAME]` table.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    /// The points file.
    pub path: PathBuf,
    /// Where the coordinates live.
    pub domain: Domain,
    /// How pixels get samples.
    pub layout: Layout,
    /// The mask file of the `mask` layout.
    pub mask: Option<PathBuf>,
}

/// Scale of disk coordinates: a value v is stored as round(v 2^23).
const DISK_SCALE: f64 = (1u32 << 23) as f64;

/// Scale of square coordinates: u is stored as floor(u 2^24).
const SQUARE_SCALE: f64 = (1u32 << 24) as f64;

/// An error about a points file as a whole.
fn whole_file(file: &Path, message: String) -> ConfigError {
    ConfigError {
        file: file.to_path_buf(),
        position: None,
        key: String::new(),
        message,
    }
}

/// An error about a line of a points file.
fn at_line(file: &Path, line: usize, message: String) -> ConfigError {
    ConfigError {
        file: file.to_path_buf(),
        position: Some((line, 1)),
        key: String::new(),
        message,
    }
}

/// One line's two numbers, with its 1-based line number and the text written.
struct Pair {
    line: usize,
    values: [f64; 2],
    texts: [String; 2],
}

/// A file's number pairs and its bytes (for its hash).
type Pairs = (Vec<Pair>, Vec<u8>);

/// Reads a points or mask file, refusing what is not a text file of number pairs.
fn read_pairs(file: &Path) -> Result<Pairs, ConfigError> {
    let meta = std::fs::metadata(file).map_err(|e| whole_file(file, format!("cannot read: {e}")))?;
    if !meta.is_file() {
        return Err(whole_file(file, "not a regular file".into()));
    }
    if meta.len() > MAX_POINTS_BYTES {
        return Err(whole_file(
            file,
            format!("larger than {MAX_POINTS_BYTES} bytes: not a points file"),
        ));
    }
    let bytes = std::fs::read(file).map_err(|e| whole_file(file, format!("cannot read: {e}")))?;
    if bytes.contains(&0) {
        return Err(whole_file(
            file,
            "a binary file (it holds NUL bytes), not a text file of points".into(),
        ));
    }
    let text = std::str::from_utf8(&bytes).map_err(|e| whole_file(file, format!("not UTF-8 text: {e}")))?;
    // Spreadsheets write a byte-order mark first: it is not part of the first value.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut pairs = Vec::new();
    let mut first = true;
    for (i, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let tokens: Vec<&str> = line
            .split(|c: char| c == ',' || c.is_whitespace())
            .filter(|t| !t.is_empty())
            .collect();
        // A header names columns: words that are not numbers (`nan` and `inf` are numbers, and
        // refused below as not finite).
        let is_header = first
            && tokens
                .iter()
                .all(|t| t.parse::<f64>().is_err() && t.chars().all(|c| c.is_ascii_alphabetic() || c == '_'));
        first = false;
        if is_header {
            continue;
        }
        if tokens.len() != 2 {
            return Err(at_line(
                file,
                i + 1,
                format!("expected two numbers, got {} value(s)", tokens.len()),
            ));
        }
        let mut v = [0.0; 2];
        let texts = [tokens[0].to_string(), tokens[1].to_string()];
        for (slot, t) in v.iter_mut().zip(&tokens) {
            *slot = t.parse::<f64>().ok().filter(|x| x.is_finite()).ok_or_else(|| {
                at_line(
                    file,
                    i + 1,
                    format!("{} is not a finite number", crate::files::shown(t)),
                )
            })?;
        }
        pairs.push(Pair {
            line: i + 1,
            values: v,
            texts,
        });
    }
    if pairs.is_empty() {
        return Err(whole_file(file, "holds no points".into()));
    }
    Ok((pairs, bytes))
}

/// A square coordinate as a 24-bit fraction; values outside [0, 1) are an error (naming the
/// text written: `0.99999999999999999` reads as 1).
fn square(file: &Path, line: usize, v: f64, text: &str) -> Result<u32, ConfigError> {
    if !(0.0..1.0).contains(&v) {
        return Err(at_line(file, line, format!("value `{text}` outside [0, 1)")));
    }
    Ok(((v * SQUARE_SCALE) as u32).min((1 << 24) - 1))
}

/// Slack on the unit disk's rim: a rim point printed with six decimals lies up to ~1e-6 out.
const RIM_SLACK: f64 = 1e-5;

impl PointSet {
    /// Loads the set `name` from `settings`, checking it holds at least `needed` samples per
    /// pixel (the most rays the experiment sweeps).
    pub fn load(name: &str, settings: &Settings, needed: u32) -> Result<PointSet, ConfigError> {
        let file = settings.path.as_path();
        let (pairs, bytes) = read_pairs(file)?;
        let mut points = Vec::with_capacity(pairs.len());
        if pairs.len() as u64 * 2 > MAX_POINTS_WORDS {
            return Err(whole_file(
                file,
                format!(
                    "{} points, more than the {} one GPU buffer holds",
                    pairs.len(),
                    MAX_POINTS_WORDS / 2
                ),
            ));
        }
        for p in &pairs {
            let ([a, b], [ta, tb]) = (p.values, &p.texts);
            points.push(match settings.domain {
                Domain::Square => [square(file, p.line, a, ta)?, square(file, p.line, b, tb)?],
                Domain::Disk => {
                    let r = (a * a + b * b).sqrt();
                    if r > 1.0 + RIM_SLACK {
                        return Err(at_line(
                            file,
                            p.line,
                            format!("point ({ta}, {tb}) outside the unit disk"),
                        ));
                    }
                    // Within the slack outside the rim: pulled onto it.
                    let scale = if r > 1.0 { 1.0 / r } else { 1.0 };
                    let fix = |v: f64| ((v * scale * DISK_SCALE).round() as i32).clamp(-(1 << 23), 1 << 23) as u32;
                    [fix(a), fix(b)]
                }
            });
        }
        let mut files = vec![settings.path.clone()];
        let mut hashed = bytes;
        let mut offsets = Vec::new();
        let count = match settings.layout {
            Layout::Shared | Layout::Mask(_) => points.len(),
            Layout::Tile(side) => {
                let pixels = (side * side) as usize;
                if points.len() % pixels != 0 {
                    return Err(whole_file(
                        file,
                        format!(
                            "{} points do not split evenly over the {side} x {side} tile's {pixels} pixels",
                            points.len()
                        ),
                    ));
                }
                points.len() / pixels
            }
        };
        if let Layout::Mask(side) = settings.layout {
            let mask = settings
                .mask
                .as_deref()
                .expect("validated: a mask layout names its mask");
            if settings.domain == Domain::Disk {
                return Err(whole_file(
                    file,
                    "a mask rotates points modulo 1 in the unit square: use domain = \"square\"".into(),
                ));
            }
            let (pairs, bytes) = read_pairs(mask)?;
            if pairs.len() != (side * side) as usize {
                return Err(whole_file(
                    mask,
                    format!(
                        "{} offsets for a {side} x {side} tile of {} pixels",
                        pairs.len(),
                        side * side
                    ),
                ));
            }
            for p in &pairs {
                let ([a, b], [ta, tb]) = (p.values, &p.texts);
                offsets.push([square(mask, p.line, a, ta)?, square(mask, p.line, b, tb)?]);
            }
            files.push(mask.to_path_buf());
            hashed.extend_from_slice(&bytes);
        }
        if (count as u64) < needed as u64 {
            return Err(whole_file(
                file,
                format!("{count} points per pixel, fewer than the {needed} rays the experiment sweeps"),
            ));
        }
        hashed.extend_from_slice(format!("{:?} {:?}", settings.domain, settings.layout).as_bytes());
        Ok(PointSet {
            name: name.to_string(),
            files,
            hash: format!("{:016x}", fnv1a(&hashed)),
            domain: settings.domain,
            layout: settings.layout,
            count: count as u32,
            points,
            offsets,
        })
    }

    /// Where it comes from, for reports: its files, hash, layout and domain.
    pub fn describe(&self) -> String {
        let files: Vec<String> = self.files.iter().map(|f| format!("`{}`", f.display())).collect();
        let layout = match self.layout {
            Layout::Shared => "one set shared by every pixel".to_string(),
            Layout::Tile(side) => format!("a set per pixel of a {side} x {side} tile"),
            Layout::Mask(side) => format!("a shared set rotated per pixel by a {side} x {side} mask"),
        };
        let domain = match self.domain {
            Domain::Square => "unit square, concentric map",
            Domain::Disk => "on the unit disk",
        };
        format!(
            "points file {} (set hash {}, FNV-1a of the files and settings; the manifest hashes each file): {layout}, {} points per pixel, {domain}",
            files.join(" + "),
            self.hash,
            self.count
        )
    }

    /// Sample `k` for the pixel at `pixel` under the tile shift of `tile_seed`, on the unit
    /// disk: the WGSL `points_point` computes the same from the same stored values.
    pub fn point(&self, k: u32, pixel: [u32; 2], tile_seed: u32) -> DVec2 {
        let q = match self.layout {
            Layout::Shared => self.points[k as usize],
            Layout::Tile(side) => {
                let i = tile_index_in(pixel[0], pixel[1], tile_seed, side);
                self.points[i * self.count as usize + k as usize]
            }
            Layout::Mask(side) => {
                let [ox, oy] = self.offsets[tile_index_in(pixel[0], pixel[1], tile_seed, side)];
                let (sx, sy) = cp_shift(tile_seed);
                let [px, py] = self.points[k as usize];
                let wrap = |a: u32, o: u32, s: u32| a.wrapping_add(o).wrapping_add(s) & 0x00ff_ffff;
                [wrap(px, ox, sx), wrap(py, oy, sy)]
            }
        };
        match self.domain {
            Domain::Square => super::concentric(super::rng::to_unit(q[0] << 8), super::rng::to_unit(q[1] << 8)),
            Domain::Disk => DVec2::new(q[0] as i32 as f64, q[1] as i32 as f64) / DISK_SCALE,
        }
    }
}

/// A name a `points:` scheme may have: letters, digits, `-` and `_` (it names files and columns).
pub fn valid_name(name: &str) -> bool {
    !name.is_empty() && name.len() <= 64 && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
}

/// A named slot of the registry: the scheme's label and, once loaded, its set.
struct Slot {
    label: &'static str,
    set: Option<&'static PointSet>,
}

/// Every `points:` name this process has seen, by [`PointsId`]: schemes stay small copyable
/// values, and the sets they name live here for the process (a handful per experiment).
fn registry() -> &'static RwLock<Vec<Slot>> {
    static SLOTS: OnceLock<RwLock<Vec<Slot>>> = OnceLock::new();
    SLOTS.get_or_init(Default::default)
}

/// Which point set a `points:NAME` scheme samples: one per name in a process.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct PointsId(u32);

impl PointsId {
    /// The id of `name` (a [`valid_name`]), known from now on whether or not its set is loaded.
    pub fn named(name: &str) -> PointsId {
        let label = format!("points:{name}");
        if let Some(i) = registry()
            .read()
            .unwrap_or_else(|p| p.into_inner())
            .iter()
            .position(|s| s.label == label)
        {
            return PointsId(i as u32);
        }
        let mut slots = registry().write().unwrap_or_else(|p| p.into_inner());
        if let Some(i) = slots.iter().position(|s| s.label == label) {
            return PointsId(i as u32);
        }
        slots.push(Slot {
            label: Box::leak(label.into_boxed_str()),
            set: None,
        });
        PointsId(slots.len() as u32 - 1)
    }

    /// Gives the name its set; a name already holding different points (another file, in the
    /// same process) is refused rather than changed under the runs that used it.
    pub fn install(set: PointSet) -> Result<PointsId, String> {
        let id = PointsId::named(&set.name);
        let mut slots = registry().write().unwrap_or_else(|p| p.into_inner());
        let slot = &mut slots[id.0 as usize];
        match slot.set {
            Some(old) if old.hash != set.hash => Err(format!(
                "`{}` already holds the points of {} in this run; give this set another name",
                slot.label,
                old.files[0].display()
            )),
            Some(_) => Ok(id),
            None => {
                slot.set = Some(Box::leak(Box::new(set)));
                Ok(id)
            }
        }
    }

    /// `points:NAME`.
    pub fn label(self) -> &'static str {
        registry().read().unwrap_or_else(|p| p.into_inner())[self.0 as usize].label
    }

    /// The set, once loaded.
    pub fn set(self) -> Option<&'static PointSet> {
        registry().read().unwrap_or_else(|p| p.into_inner())[self.0 as usize].set
    }

    /// The loaded set; sampling a name whose file was never loaded is a bug of the caller
    /// (experiments load every set they name before anything renders).
    pub fn loaded(self) -> &'static PointSet {
        self.set()
            .unwrap_or_else(|| panic!("{} sampled before its points file was loaded", self.label()))
    }
}
