//! A Wavefront OBJ reader for triangle meshes: `v` positions, `f` faces (any of the `v`,
//! `v/vt`, `v//vn`, `v/vt/vn` forms, negative indices relative to the end), `g`/`o` groups.
//! Polygons are split into triangles ([`MeshFile::push_face`]). Everything else (normals,
//! texture coordinates, materials) is ignored. Errors name the file and line.

use super::file::{coordinate, face_fits, MeshFile, MeshFileError, MAX_FACE_CORNERS};
use std::collections::HashMap;
use std::path::Path;

/// Parses OBJ text; `file` is only used in errors.
pub fn parse(text: &str, file: &Path) -> Result<MeshFile, MeshFileError> {
    let err = |line: usize, message: String| MeshFileError {
        file: file.to_path_buf(),
        line: Some(line),
        message,
    };
    let mut positions: Vec<[f64; 3]> = Vec::new();
    let mut mesh = MeshFile::default();
    let mut group: Option<u32> = None;
    let mut group_ids: HashMap<String, u32> = HashMap::new();
    for (i, raw) in text.lines().enumerate() {
        let line_no = i + 1;
        let line = raw.split('#').next().unwrap_or("").trim();
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                let mut p = [0.0; 3];
                for c in &mut p {
                    let w = words
                        .next()
                        .ok_or_else(|| err(line_no, "vertex needs 3 coordinates".into()))?;
                    *c = coordinate(w).map_err(|e| err(line_no, e))?;
                }
                positions.push(p);
            }
            Some("f") => {
                let mut corners = Vec::new();
                for w in words {
                    let idx = w.split('/').next().unwrap_or("");
                    let k: i64 = idx
                        .parse()
                        .map_err(|_| err(line_no, format!("bad face index: {}", crate::files::shown(w))))?;
                    let n = positions.len() as i64;
                    let resolved = if k > 0 { k - 1 } else { n + k };
                    if k == 0 || resolved < 0 || resolved >= n {
                        return Err(err(
                            line_no,
                            format!("face index {k} refers to no vertex ({n} defined so far)"),
                        ));
                    }
                    corners.push(positions[resolved as usize]);
                    if corners.len() > MAX_FACE_CORNERS {
                        break;
                    }
                }
                if corners.len() < 3 {
                    return Err(err(
                        line_no,
                        format!("a face needs at least 3 vertices, got {}", corners.len()),
                    ));
                }
                if corners.len() > MAX_FACE_CORNERS {
                    return Err(err(
                        line_no,
                        format!("a face of more than {MAX_FACE_CORNERS} corners; split it into smaller polygons"),
                    ));
                }
                face_fits(mesh.triangles.len(), corners.len()).map_err(|e| err(line_no, e))?;
                let g = match group {
                    Some(g) => g,
                    None => *group.insert(id_of(&mut mesh, &mut group_ids, "default".into())),
                };
                mesh.push_face(&corners, g).map_err(|e| err(line_no, e))?;
            }
            Some("g") | Some("o") => {
                let name = words.collect::<Vec<_>>().join(" ");
                let name = if name.is_empty() { "default".to_string() } else { name };
                group = Some(id_of(&mut mesh, &mut group_ids, name));
            }
            _ => {}
        }
    }
    Ok(mesh)
}

/// The index of group `name`, added on first sight (a map: files with many groups stay linear).
fn id_of(mesh: &mut MeshFile, ids: &mut HashMap<String, u32>, name: String) -> u32 {
    *ids.entry(name).or_insert_with_key(|name| {
        mesh.groups.push(name.clone());
        mesh.groups.len() as u32 - 1
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quads_split_groups_and_index_forms() {
        let text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\ng a\nf 1/1/1 2/2/2 3/3/3 4/4/4\ng b\nf -4//1 -3//1 -2//1\n";
        let m = parse(text, Path::new("t.obj")).unwrap();
        assert_eq!(m.triangles.len(), 3);
        assert_eq!(m.groups, vec!["a", "b"]);
        assert_eq!(m.group_of, vec![0, 0, 1]);
        assert_eq!(m.triangles[1], [[0.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]]);
        assert_eq!(m.select(&["b".into()], Path::new("t.obj")).unwrap().len(), 1);
        let e = m.select(&["c".into()], Path::new("t.obj")).unwrap_err();
        assert!(e.message.contains("a, b"), "{e}");
    }

    #[test]
    fn malformed_faces_are_located() {
        for (text, line, what) in [
            ("v 0 0 0\nv 1 0 0\nf 1 2\n", 3, "at least 3"),
            ("v 0 0 0\nf 1 2 3\n", 2, "refers to no vertex"),
            ("v 0 0\n", 1, "3 coordinates"),
            ("v 0 0 x\n", 1, "bad vertex"),
            ("v 0 0 0\nv 0 0 0\nv 0 0 0\n\nf 1 2 z\n", 5, "bad face index"),
            ("v 0 0 0\nv 0 0 0\nv 0 0 0\nf 0 1 2\n", 4, "refers to no vertex"),
        ] {
            let e = parse(text, Path::new("m.obj")).unwrap_err();
            assert_eq!(e.line, Some(line), "{text:?}: {e}");
            assert!(e.message.contains(what), "{e}");
            assert!(e.to_string().starts_with(&format!("m.obj:{line}:")));
        }
    }

    #[test]
    fn missing_file_is_named() {
        let e = crate::mesh::file::load(Path::new("/nonexistent/x.obj")).unwrap_err();
        assert!(e.to_string().contains("/nonexistent/x.obj") && e.to_string().contains("cannot read"));
    }
}
