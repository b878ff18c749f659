//! Binary little-endian PLY for a mesh's world-space triangles (three vertices each, unshared:
//! the exported geometry is exactly the triangles penumbra traces, dropped ones excepted).

use glam::DVec3;

/// A PLY file of `triangles` (world space, metres), vertices in f32 as renderers read them.
pub fn triangles(triangles: &[[DVec3; 3]]) -> Vec<u8> {
    let header = format!(
        "ply\nformat binary_little_endian 1.0\ncomment penumbra export: world-space metres\n\
         element vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
         element face {}\nproperty list uchar int vertex_indices\nend_header\n",
        3 * triangles.len(),
        triangles.len()
    );
    let mut out = header.into_bytes();
    for t in triangles {
        for v in t {
            for c in [v.x, v.y, v.z] {
                out.extend_from_slice(&(c as f32).to_le_bytes());
            }
        }
    }
    for i in 0..triangles.len() as i32 {
        out.push(3);
        for k in 0..3 {
            out.extend_from_slice(&(3 * i + k).to_le_bytes());
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_triangle_reads_back_from_its_header_and_bytes() {
        let t = [[DVec3::new(1.0, 2.0, 3.0), DVec3::new(-1.0, 0.5, 0.0), DVec3::ZERO]];
        let bytes = triangles(&t);
        let end = bytes.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
        let header = std::str::from_utf8(&bytes[..end]).unwrap();
        assert!(header.contains("element vertex 3\n") && header.contains("element face 1\n"));
        let body = &bytes[end..];
        assert_eq!(body.len(), 9 * 4 + 1 + 3 * 4);
        let f = |k: usize| f32::from_le_bytes(body[4 * k..4 * k + 4].try_into().unwrap());
        assert_eq!([f(0), f(1), f(2), f(3), f(4)], [1.0, 2.0, 3.0, -1.0, 0.5]);
        assert_eq!(body[36], 3);
        let idx = |k: usize| i32::from_le_bytes(body[37 + 4 * k..41 + 4 * k].try_into().unwrap());
        assert_eq!([idx(0), idx(1), idx(2)], [0, 1, 2]);
    }
}
