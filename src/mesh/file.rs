//! A triangle mesh as read from a file, whatever its format, and the located error of a file that
//! could not be read.

use std::fmt;
use std::path::{Path, PathBuf};

/// A mesh file that could not be read, located.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshFileError {
    /// The file.
    pub file: PathBuf,
    /// 1-based line, when the error is on a line.
    pub line: Option<usize>,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for MeshFileError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(l) => write!(f, "{}:{l}: {}", self.file.display(), self.message),
            None => write!(f, "{}: {}", self.file.display(), self.message),
        }
    }
}

impl std::error::Error for MeshFileError {}

/// Triangles of a mesh file, as vertex positions, with the group each came from.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MeshFile {
    /// Triangle corner positions, in file units.
    pub triangles: Vec<[[f64; 3]; 3]>,
    /// Group index per triangle (into `groups`).
    pub group_of: Vec<u32>,
    /// Group names in order of first appearance (faces outside any named group are in group
    /// `default`; formats without groups put everything there).
    pub groups: Vec<String>,
}

impl MeshFile {
    /// The triangles of the named groups (all triangles when `names` is empty); an unknown name
    /// is an error listing the groups that exist.
    pub fn select(&self, names: &[String], file: &Path) -> Result<Vec<[[f64; 3]; 3]>, MeshFileError> {
        let mut wanted = Vec::new();
        for n in names {
            match self.groups.iter().position(|g| g == n) {
                Some(i) => wanted.push(i as u32),
                None => {
                    return Err(MeshFileError {
                        file: file.to_path_buf(),
                        line: None,
                        message: format!("no group `{n}`; the file has: {}", self.groups.join(", ")),
                    })
                }
            }
        }
        Ok(self
            .triangles
            .iter()
            .zip(&self.group_of)
            .filter(|(_, g)| names.is_empty() || wanted.contains(g))
            .map(|(t, _)| *t)
            .collect())
    }
}

/// Reads a mesh file, its format chosen by extension: `.obj` (Wavefront) or `.off` (Object File
/// Format, the visibility-field scenes' format).
pub fn load(path: &Path) -> Result<MeshFile, MeshFileError> {
    let parse = match path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("obj") => super::obj::parse,
        Some("off") => super::off::parse,
        _ => {
            return Err(MeshFileError {
                file: path.to_path_buf(),
                line: None,
                message: "unknown mesh format: expected a .obj or .off file".into(),
            })
        }
    };
    let fail = |message: String| MeshFileError {
        file: path.to_path_buf(),
        line: None,
        message,
    };
    let meta = std::fs::metadata(path).map_err(|e| fail(format!("cannot read: {e}")))?;
    if !meta.is_file() {
        return Err(fail("not a regular file".into()));
    }
    if meta.len() > MAX_MESH_BYTES {
        return Err(fail(format!(
            "{} bytes: larger than the {MAX_MESH_BYTES} bytes a mesh file may have",
            meta.len()
        )));
    }
    let text = std::fs::read_to_string(path).map_err(|e| fail(format!("cannot read: {e}")))?;
    parse(&text, path)
}

/// Largest mesh file read (a 1 GiB text file already describes tens of millions of triangles).
pub const MAX_MESH_BYTES: u64 = 1 << 30;

/// Most triangles a mesh file may expand into: polygons become fans, so a short file can ask
/// for many; the count is checked face by face, before the fan is stored.
pub const MAX_FILE_TRIANGLES: usize = 16 << 20;

/// Largest magnitude of a finite vertex coordinate (metres, or the file's units): beyond it f32
/// on the GPU and the structures' bounds lose the geometry; the scene file's bound too.
pub const MAX_COORDINATE: f64 = 1e7;

/// A vertex coordinate read from `word`, or why not (`inf` and `nan` pass: such triangles are
/// dropped and counted later).
pub fn coordinate(word: &str) -> Result<f64, String> {
    let c: f64 = word.parse().map_err(|_| format!("bad vertex coordinate `{word}`"))?;
    if c.is_finite() && c.abs() > MAX_COORDINATE {
        return Err(format!("vertex coordinate {c:e} beyond +-{MAX_COORDINATE:e}"));
    }
    Ok(c)
}

/// Refuses a face of `corners` corners that would take the file past [`MAX_FILE_TRIANGLES`]
/// when `stored` triangles are already kept.
pub fn fan_fits(stored: usize, corners: usize) -> Result<(), String> {
    if stored + corners.saturating_sub(2) > MAX_FILE_TRIANGLES {
        return Err(format!(
            "this face takes the file past {MAX_FILE_TRIANGLES} triangles (polygons count as fans of corners - 2)"
        ));
    }
    Ok(())
}
