//! An Object File Format (OFF) reader: the `OFF` header, `vertices faces edges`, then vertex
//! positions and faces as `n i0 .. i(n-1)` with zero-based indices. Colours after a vertex's
//! three coordinates or a face's indices are ignored; `#` starts a comment. Polygons are split
//! into triangles ([`MeshFile::push_face`]). OFF has no groups: every face is in group
//! `default`. Errors name the file and line.

use super::file::{coordinate, face_fits, MeshFile, MeshFileError};
use std::path::Path;

/// Parses OFF text; `file` is only used in errors.
pub fn parse(text: &str, file: &Path) -> Result<MeshFile, MeshFileError> {
    let err = |line: usize, message: String| MeshFileError {
        file: file.to_path_buf(),
        line: Some(line),
        message,
    };
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, raw)| (i + 1, raw.split('#').next().unwrap_or("").trim()))
        .filter(|(_, l)| !l.is_empty());
    let last_line = text.lines().count().max(1);
    let (header_line, header) = lines
        .next()
        .ok_or_else(|| err(1, "empty file: expected `OFF`".into()))?;
    let mut words: Vec<&str> = header.split_whitespace().collect();
    if words.first() != Some(&"OFF") {
        return Err(err(
            header_line,
            format!(
                "expected `OFF`, got {}",
                crate::files::shown(words.first().unwrap_or(&""))
            ),
        ));
    }
    words.remove(0);
    let (counts_line, counts) = if words.is_empty() {
        let (n, l) = lines
            .next()
            .ok_or_else(|| err(last_line, "missing `vertices faces edges` counts".into()))?;
        (n, l.split_whitespace().collect())
    } else {
        (header_line, words)
    };
    let count = |k: usize, what: &str| -> Result<usize, MeshFileError> {
        let w = counts
            .get(k)
            .ok_or_else(|| err(counts_line, format!("missing the {what} count")))?;
        w.parse()
            .map_err(|_| err(counts_line, format!("bad {what} count: {}", crate::files::shown(w))))
    };
    let (n_vertices, n_faces) = (count(0, "vertex")?, count(1, "face")?);
    // No more vertices than lines: a header's count sizes nothing by itself.
    let mut positions = Vec::with_capacity(n_vertices.min(last_line));
    for k in 0..n_vertices {
        let (n, l) = lines
            .next()
            .ok_or_else(|| err(last_line, format!("file ends after {k} of {n_vertices} vertices")))?;
        let mut p = [0.0; 3];
        let mut ws = l.split_whitespace();
        for c in &mut p {
            let w = ws.next().ok_or_else(|| err(n, "vertex needs 3 coordinates".into()))?;
            *c = coordinate(w).map_err(|e| err(n, e))?;
        }
        positions.push(p);
    }
    let mut mesh = MeshFile {
        groups: vec!["default".into()],
        ..MeshFile::default()
    };
    for k in 0..n_faces {
        let (n, l) = lines
            .next()
            .ok_or_else(|| err(last_line, format!("file ends after {k} of {n_faces} faces")))?;
        let mut ws = l.split_whitespace();
        let w = ws.next().unwrap_or("");
        let corners: usize = w
            .parse()
            .map_err(|_| err(n, format!("bad face vertex count: {}", crate::files::shown(w))))?;
        if corners < 3 {
            return Err(err(n, format!("a face needs at least 3 vertices, got {corners}")));
        }
        face_fits(mesh.triangles.len(), corners).map_err(|e| err(n, e))?;
        // The count is checked against the words on the line before anything is sized by it.
        let listed: Vec<&str> = ws.collect();
        if listed.len() < corners {
            return Err(err(n, format!("face lists fewer than its {corners} vertices")));
        }
        let mut face = Vec::with_capacity(corners);
        for &w in &listed[..corners] {
            let i: usize = w
                .parse()
                .map_err(|_| err(n, format!("bad face index: {}", crate::files::shown(w))))?;
            let p = positions
                .get(i)
                .ok_or_else(|| err(n, format!("face index {i} refers to no vertex ({n_vertices} defined)")))?;
            face.push(*p);
        }
        mesh.push_face(&face, 0).map_err(|e| err(n, e))?;
    }
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn triangles_quads_comments_and_colours() {
        let text = "OFF\n# a comment\n4 2 0\n0 0 0\n1 0 0\n1 1 0 255 0 0\n0 1 0\n3 0 1 2\n4 0 1 2 3 0.5 0.5 0.5\n";
        let m = parse(text, Path::new("t.off")).unwrap();
        assert_eq!(m.triangles.len(), 3);
        assert_eq!(m.groups, vec!["default"]);
        assert_eq!(m.group_of, vec![0, 0, 0]);
        assert_eq!(m.triangles[2], [[0.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]]);
        let same_line = parse("OFF 3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", Path::new("t.off")).unwrap();
        assert_eq!(same_line.triangles.len(), 1);
    }

    #[test]
    fn malformed_files_are_located() {
        for (text, line, what) in [
            ("", 1, "empty file"),
            ("PLY\n", 1, "expected `OFF`"),
            ("OFF\n3 x 0\n", 2, "bad face count"),
            ("OFF\n3\n", 2, "missing the face count"),
            ("OFF\n3 1 0\n0 0 0\n1 0\n", 4, "3 coordinates"),
            ("OFF\n3 1 0\n0 0 0\n1 0 0\n", 4, "after 2 of 3 vertices"),
            ("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", 6, "refers to no vertex"),
            ("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n", 6, "at least 3"),
            ("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1\n", 6, "fewer than"),
            ("OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", 6, "after 1 of 2 faces"),
            // Corner counts no face may have: refused, never allocated.
            (
                "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n18446744073709551615 0 1 2\n",
                6,
                "at most 65536",
            ),
            (
                "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n100000000000 0 1 2\n",
                6,
                "at most 65536",
            ),
            (
                "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n65537 0 1 2\n",
                6,
                "a face of 65537 corners",
            ),
            // Within the budget but longer than its line.
            ("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n1000 0 1 2\n", 6, "fewer than"),
            ("OFF\n3 1 0\n1e8 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", 3, "beyond"),
            ("OFF\n18446744073709551615 1 0\n0 0 0\n", 3, "after 1 of"),
        ] {
            let e = parse(text, Path::new("m.off")).unwrap_err();
            assert_eq!(e.line, Some(line), "{text:?}: {e}");
            assert!(e.message.contains(what), "{text:?}: {e}");
            assert!(e.to_string().starts_with(&format!("m.off:{line}:")));
        }
    }
}
