//! The dynamic updates the visibility-field tests apply, each to the field and to the reference
//! triangles brute force reads, so the two stay in step: an object removed (its triangles shrunk
//! to a point in the reference, which nothing hits), an object moved inside the ball, an object
//! inserted.

use super::rays::{soup, v};
use glam::DVec3;
use penumbra::accel::vlf::VisibilityField;
use penumbra::mesh::Triangles;

/// Removes `object` from the field and from `current`.
pub fn remove(field: &mut VisibilityField, current: &mut Triangles, object: u32) {
    let removed = field.remove_object(object).unwrap();
    assert_eq!(removed, current.object_of.iter().filter(|o| **o == object).count());
    for (p, o) in current.positions.iter_mut().zip(&current.object_of) {
        if *o == object {
            *p = [p[0]; 3];
        }
    }
}

/// Moves object 2 (shrunk and shifted, staying inside the ball), then inserts object 9 (30 new
/// triangles of mixed sizes), in the field and in `current`.
pub fn move_and_insert(field: &mut VisibilityField, current: &mut Triangles) {
    let m = |p: DVec3| v(3.0, -2.0, 1.5) + (p - v(3.0, -2.0, 1.5)) * 0.8 + v(0.05, -0.1, 0.02);
    field.move_object(2, m).unwrap();
    for (p, o) in current.positions.iter_mut().zip(&current.object_of) {
        if *o == 2 {
            *p = p.map(m);
        }
    }
    let new: Vec<[DVec3; 3]> = soup(30, 77)
        .positions
        .iter()
        .map(|p| p.map(|c| v(3.0, -2.0, 1.5) + (c - v(3.0, -2.0, 1.5)) * 0.5))
        .collect();
    let range = field.insert_object(9, &new).unwrap();
    assert_eq!(range.start as usize, current.positions.len());
    current.positions.extend_from_slice(&new);
    current.object_of.extend(std::iter::repeat_n(9, new.len()));
}
