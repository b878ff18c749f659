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
    let bytes = std::fs::read(path).map_err(|e| fail(format!("cannot read: {e}")))?;
    let text = String::from_utf8(bytes).map_err(|e| {
        fail(format!(
            "not UTF-8 text (byte {} starts an invalid sequence)",
            e.utf8_error().valid_up_to()
        ))
    })?;
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
    let c: f64 = word
        .parse()
        .map_err(|_| format!("bad vertex coordinate: {}", crate::files::shown(word)))?;
    if c.is_finite() && c.abs() > MAX_COORDINATE {
        return Err(format!("vertex coordinate {c:e} beyond +-{MAX_COORDINATE:e}"));
    }
    Ok(c)
}

/// Most corners one face may have. A polygon of more is no modelled surface (a cylinder cap of
/// 65,536 segments is already far below a pixel), and a face of a million corners, a few
/// megabytes of text, would become a million overlapping triangles.
pub const MAX_FACE_CORNERS: usize = 1 << 16;

/// Refuses a face of `corners` corners: more than [`MAX_FACE_CORNERS`], or one that would take
/// the file past [`MAX_FILE_TRIANGLES`] when `stored` triangles are already kept.
pub fn face_fits(stored: usize, corners: usize) -> Result<(), String> {
    if corners > MAX_FACE_CORNERS {
        return Err(format!(
            "a face of {corners} corners; a face may have at most {MAX_FACE_CORNERS} (split it into smaller polygons)"
        ));
    }
    if stored + corners.saturating_sub(2) > MAX_FILE_TRIANGLES {
        return Err(format!(
            "this face takes the file past {MAX_FILE_TRIANGLES} triangles (a polygon counts as its corners - 2)"
        ));
    }
    Ok(())
}

/// Most corners of a face that is not a convex polygon listed in order: such a face is fanned
/// from its first corner, as the formats' readers do (right where every corner sees the first),
/// and a fan of more would be slivers crossing one another, whose boxes no tree separates.
pub const MAX_FAN_CORNERS: usize = 64;

impl MeshFile {
    /// Appends the triangles of the polygon `face` (3 corners or more, in order), in group
    /// `group`. Triangles and quads are fanned from the first corner, as the formats' readers
    /// do. A larger polygon that is convex with its corners listed once around in order is split
    /// by diagonals halving its corner range, so its triangles stay compact (a fan's are slivers
    /// all meeting at one corner, whose overlapping boxes no tree separates); any other is
    /// fanned up to [`MAX_FAN_CORNERS`] corners and refused beyond.
    pub fn push_face(&mut self, face: &[[f64; 3]], group: u32) -> Result<(), String> {
        let n = face.len();
        let mut push = |t: [[f64; 3]; 3]| {
            self.triangles.push(t);
            self.group_of.push(group);
        };
        if n <= 4 || !convex_in_order(face) {
            if n > MAX_FAN_CORNERS {
                return Err(format!(
                    "a face of {n} corners that is not a convex polygon listing its corners once around: \
                     only faces of up to {MAX_FAN_CORNERS} such corners are fanned; split it into convex polygons or triangles"
                ));
            }
            for k in 1..n.saturating_sub(1) {
                push([face[0], face[k], face[k + 1]]);
            }
            return Ok(());
        }
        // Each range (a, b) is the sub-polygon a, a + 1, .., b closed by the diagonal b -> a.
        let mut ranges = vec![(0, n - 1)];
        while let Some((a, b)) = ranges.pop() {
            if b - a < 2 {
                continue;
            }
            let m = (a + b) / 2;
            push([face[a], face[m], face[b]]);
            ranges.push((m, b));
            ranges.push((a, m));
        }
        Ok(())
    }
}

/// Whether `face` is a convex polygon listing its corners once around in order: about its
/// normal (Newell's), every turn goes the same way and the turns add up to one revolution.
/// Repeated corners (edges of no length) are passed over; straight corners are convex.
fn convex_in_order(face: &[[f64; 3]]) -> bool {
    use glam::DVec3;
    let p: Vec<DVec3> = face.iter().map(|&c| DVec3::from_array(c)).collect();
    let centre = p.iter().copied().sum::<DVec3>() / p.len() as f64;
    let normal: DVec3 = (0..p.len())
        .map(|i| (p[i] - centre).cross(p[(i + 1) % p.len()] - centre))
        .sum();
    let Some(normal) = normal.try_normalize() else {
        return false;
    };
    let edges: Vec<DVec3> = (0..p.len())
        .map(|i| p[(i + 1) % p.len()] - p[i])
        .filter(|e| *e != DVec3::ZERO)
        .collect();
    let mut turned = 0.0;
    for (i, e) in edges.iter().enumerate() {
        let next = edges[(i + 1) % edges.len()];
        let (sin, cos) = (e.cross(next).dot(normal), e.dot(next));
        if sin < -1e-12 * e.length() * next.length() {
            return false;
        }
        turned += sin.atan2(cos);
    }
    (turned - std::f64::consts::TAU).abs() < 1e-6
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area(t: &[[f64; 3]; 3]) -> f64 {
        let (a, b, c) = (t[0], t[1], t[2]);
        let (u, v) = ([b[0] - a[0], b[1] - a[1]], [c[0] - a[0], c[1] - a[1]]);
        0.5 * (u[0] * v[1] - u[1] * v[0])
    }

    fn circle(n: usize) -> Vec<[f64; 3]> {
        (0..n)
            .map(|k| {
                let a = std::f64::consts::TAU * k as f64 / n as f64;
                [a.cos(), a.sin(), 0.0]
            })
            .collect()
    }

    #[test]
    fn triangles_and_quads_are_fanned_from_the_first_corner() {
        let quad = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
        let mut m = MeshFile::default();
        m.push_face(&quad[..3], 7).unwrap();
        m.push_face(&quad, 7).unwrap();
        assert_eq!(
            m.triangles,
            vec![
                [quad[0], quad[1], quad[2]],
                [quad[0], quad[1], quad[2]],
                [quad[0], quad[2], quad[3]]
            ]
        );
        assert_eq!(m.group_of, vec![7; 3]);
    }

    #[test]
    fn a_large_polygon_is_covered_once_by_compact_triangles() {
        for n in [5, 6, 7, 64, 1000, MAX_FACE_CORNERS] {
            let face = circle(n);
            let mut m = MeshFile::default();
            m.push_face(&face, 0).unwrap();
            assert_eq!(m.triangles.len(), n - 2, "n = {n}");
            // Every triangle counter-clockwise (no fold) and the areas add up to the polygon's.
            let exact = 0.5 * n as f64 * (std::f64::consts::TAU / n as f64).sin();
            let total: f64 = m.triangles.iter().map(area).sum();
            assert!(m.triangles.iter().all(|t| area(t) > 0.0), "n = {n}");
            assert!((total - exact).abs() < 1e-9 * exact, "n = {n}: {total} vs {exact}");
            // No sliver spans the polygon the way a fan's do: the mean edge is far below its
            // diameter (a fan's mean edge is about 1.3 diameters / 2).
            let edge = |t: &[[f64; 3]; 3]| {
                (0..3)
                    .map(|i| {
                        let (p, q) = (t[i], t[(i + 1) % 3]);
                        ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2)).sqrt()
                    })
                    .sum::<f64>()
                    / 3.0
            };
            let mean = m.triangles.iter().map(edge).sum::<f64>() / m.triangles.len() as f64;
            if n >= 1000 {
                assert!(mean < 0.1, "n = {n}: mean edge {mean}");
            }
        }
    }

    #[test]
    fn other_polygons_are_fanned_as_before_or_refused_when_large() {
        // A concave pentagon: the fan from its first corner covers it exactly (area 14), where a
        // split across the notch would not.
        let notch = [
            [0.0, 0.0, 0.0],
            [4.0, 0.0, 0.0],
            [4.0, 4.0, 0.0],
            [2.0, 3.0, 0.0],
            [0.0, 4.0, 0.0],
        ];
        let mut m = MeshFile::default();
        m.push_face(&notch, 0).unwrap();
        assert_eq!(m.triangles.len(), 3);
        assert!(m.triangles.iter().all(|t| t[0] == notch[0]), "fanned");
        assert!((m.triangles.iter().map(area).sum::<f64>() - 14.0).abs() < 1e-12);
        // Corners of a convex polygon listed out of order (a star), or around twice.
        let star = |n: usize, step: usize| -> Vec<[f64; 3]> {
            let c = circle(n);
            (0..n).map(|k| c[k * step % n]).collect()
        };
        let twice: Vec<[f64; 3]> = circle(32).into_iter().cycle().take(64).collect();
        for (what, face) in [("star", star(63, 2)), ("twice around", twice)] {
            let mut m = MeshFile::default();
            m.push_face(&face, 0).unwrap();
            assert!(m.triangles.iter().all(|t| t[0] == face[0]), "{what}: fanned");
        }
        for (what, face) in [
            ("a star of 4096 corners", star(4096, 2047)),
            ("a notch in 65 corners", {
                let mut c = circle(65);
                c[30] = [0.0, 0.0, 0.0];
                c
            }),
            (
                "a quad listed 1000 times",
                (0..4000).map(|k| circle(4)[k % 4]).collect(),
            ),
        ] {
            let e = MeshFile::default().push_face(&face, 0).unwrap_err();
            assert!(
                e.contains("not a convex polygon") && e.contains("up to 64"),
                "{what}: {e}"
            );
        }
        // Repeated and straight corners keep a convex polygon convex.
        let mut ring = circle(100);
        ring.insert(10, ring[10]);
        ring.insert(
            50,
            [
                (ring[49][0] + ring[50][0]) / 2.0,
                (ring[49][1] + ring[50][1]) / 2.0,
                0.0,
            ],
        );
        let mut m = MeshFile::default();
        m.push_face(&ring, 0).unwrap();
        assert!(!m.triangles.iter().all(|t| t[0] == ring[0]), "split, not fanned");
    }

    #[test]
    fn faces_past_the_corner_or_file_limits_are_refused() {
        assert!(face_fits(0, MAX_FACE_CORNERS).is_ok());
        let e = face_fits(0, MAX_FACE_CORNERS + 1).unwrap_err();
        assert!(e.contains("65537 corners"), "{e}");
        let e = face_fits(MAX_FILE_TRIANGLES - 2, 5).unwrap_err();
        assert!(e.contains("past 16777216 triangles"), "{e}");
        assert!(face_fits(MAX_FILE_TRIANGLES - 3, 5).is_ok());
    }

    #[test]
    fn a_mesh_file_that_is_not_utf8_is_refused_at_its_first_bad_byte() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.obj");
        std::fs::write(&path, b"v 0 0 0\nv 1 0 0\nv 0 1 0\n# caf\xe9\nf 1 2 3\n").unwrap();
        let e = load(&path).unwrap_err().to_string();
        assert!(
            e.contains("m.obj") && e.contains("byte 29 starts an invalid sequence"),
            "{e}"
        );
    }
}
