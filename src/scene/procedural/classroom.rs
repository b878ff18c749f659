//! The walkthrough scene (the visibility-field paper's Fig. 6 'Classroom', 51,208 polygons, 4
//! point lights, 420 frames on a fixed path), rebuilt procedurally since the model is not
//! available: a 10 x 8 x 3.2 m room with tessellated walls, floor and ceiling, windows, a
//! blackboard, 20 desks with chairs, a teacher's desk, bookshelves with books, ceiling lamps,
//! two wall mirrors and a chrome ball on the teacher's desk (the part dynamic experiments move).

use super::parts::turn;
use super::{Generated, Part};
use crate::scene::camera::{Camera, Projection};
use crate::scene::Light;
use glam::DVec3;
use std::f64::consts::{PI, TAU};

const HALF_X: f64 = 5.0;
const HALF_Y: f64 = 4.0;
const HEIGHT: f64 = 3.2;

fn v(x: f64, y: f64, z: f64) -> DVec3 {
    DVec3::new(x, y, z)
}

/// The room's shell: floor and ceiling in 0.2 m cells, walls in 0.2 m cells with four window
/// openings in the wall y = +4 (each a 1.6 x 1.4 m hole with a frame).
fn shell() -> Vec<Part> {
    let mut floor = Part::new("floor", 0.55);
    floor.grid(
        v(-HALF_X, -HALF_Y, 0.0),
        v(HALF_X, -HALF_Y, 0.0),
        v(-HALF_X, HALF_Y, 0.0),
        50,
        40,
    );
    let mut ceiling = Part::new("ceiling", 0.85);
    ceiling.grid(
        v(-HALF_X, -HALF_Y, HEIGHT),
        v(HALF_X, -HALF_Y, HEIGHT),
        v(-HALF_X, HALF_Y, HEIGHT),
        50,
        40,
    );
    let mut walls = Part::new("walls", 0.75);
    let cells_z = 16;
    walls.grid(
        v(-HALF_X, -HALF_Y, 0.0),
        v(HALF_X, -HALF_Y, 0.0),
        v(-HALF_X, -HALF_Y, HEIGHT),
        50,
        cells_z,
    );
    walls.grid(
        v(-HALF_X, -HALF_Y, 0.0),
        v(-HALF_X, HALF_Y, 0.0),
        v(-HALF_X, -HALF_Y, HEIGHT),
        40,
        cells_z,
    );
    walls.grid(
        v(HALF_X, -HALF_Y, 0.0),
        v(HALF_X, HALF_Y, 0.0),
        v(HALF_X, -HALF_Y, HEIGHT),
        40,
        cells_z,
    );
    let mut frames = Part::new("window-frames", 0.4);
    let window = |i: u32, j: u32| {
        let x = -HALF_X + 0.2 * i as f64 + 0.1;
        let z = 0.2 * j as f64 + 0.1;
        (0..4).any(|w| (x - (-3.6 + 2.4 * w as f64)).abs() < 0.8) && (0.8..2.2).contains(&z)
    };
    for i in 0..50 {
        for j in 0..cells_z {
            if !window(i, j) {
                let a = v(-HALF_X + 0.2 * i as f64, HALF_Y, 0.2 * j as f64);
                walls.grid(a, a + DVec3::X * 0.2, a + DVec3::Z * 0.2, 1, 1);
            }
        }
    }
    for w in 0..4 {
        let x = -3.6 + 2.4 * w as f64;
        frames.cuboid(v(x - 0.85, HALF_Y - 0.1, 0.75), v(x + 0.85, HALF_Y, 0.8));
        frames.cuboid(v(x - 0.85, HALF_Y - 0.1, 2.2), v(x + 0.85, HALF_Y, 2.25));
        frames.cuboid(v(x - 0.03, HALF_Y - 0.06, 0.8), v(x + 0.03, HALF_Y, 2.2));
        frames.cuboid(v(x - 0.85, HALF_Y - 0.1, 0.8), v(x - 0.8, HALF_Y, 2.2));
        frames.cuboid(v(x + 0.8, HALF_Y - 0.1, 0.8), v(x + 0.85, HALF_Y, 2.2));
    }
    vec![floor, ceiling, walls, frames]
}

/// Four legs of `height` at the corners of `lo`..`hi` (inset by 4 cm), each a cylinder.
fn legs(part: &mut Part, lo: DVec3, hi: DVec3, height: f64, radius: f64) {
    for (x, y) in [(lo.x, lo.y), (hi.x, lo.y), (lo.x, hi.y), (hi.x, hi.y)] {
        let inset = v(
            (x - 0.5 * (lo.x + hi.x)).signum() * -0.04,
            (y - 0.5 * (lo.y + hi.y)).signum() * -0.04,
            0.0,
        );
        part.cylinder(v(x, y, 0.0) + inset, radius, height, 28);
    }
}

/// A pupil's desk (1.2 x 0.6 m at 0.75 m) and its chair behind it (towards +x, facing the
/// blackboard at x = -5), turned by `degrees`.
fn desk_and_chair(desks: &mut Part, chairs: &mut Part, centre: DVec3, degrees: f64) {
    let from = desks.triangles.len();
    desks.cuboid(centre + v(-0.3, -0.6, 0.72), centre + v(0.3, 0.6, 0.76));
    legs(
        desks,
        centre + v(-0.3, -0.6, 0.0),
        centre + v(0.3, 0.6, 0.0),
        0.72,
        0.025,
    );
    desks.transform_from(from, turn(centre, degrees));
    let from = chairs.triangles.len();
    let seat = centre + v(0.6, 0.0, 0.0);
    chairs.cuboid(seat + v(-0.2, -0.2, 0.44), seat + v(0.2, 0.2, 0.47));
    chairs.cuboid(seat + v(0.18, -0.2, 0.47), seat + v(0.21, 0.2, 0.85));
    legs(chairs, seat + v(-0.2, -0.2, 0.0), seat + v(0.2, 0.2, 0.0), 0.44, 0.015);
    chairs.transform_from(from, turn(centre, degrees));
}

/// Everything in the room.
fn furniture() -> Vec<Part> {
    let mut desks = Part::new("desks", 0.5);
    let mut chairs = Part::new("chairs", 0.35);
    for row in 0..5 {
        for col in 0..4 {
            let centre = v(-2.0 + 1.25 * row as f64, -2.1 + 1.4 * col as f64, 0.0);
            desk_and_chair(
                &mut desks,
                &mut chairs,
                centre,
                2.0 * ((row * 4 + col) % 3) as f64 - 2.0,
            );
        }
    }
    let mut teacher = Part::new("teacher-desk", 0.45);
    teacher.cuboid(v(-3.9, -0.9, 0.74), v(-3.1, 0.9, 0.78));
    teacher.cuboid(v(-3.85, -0.85, 0.1), v(-3.75, 0.85, 0.74));
    legs(&mut teacher, v(-3.9, -0.9, 0.0), v(-3.1, 0.9, 0.0), 0.74, 0.03);
    let mut board = Part::new("blackboard", 0.08);
    board.grid(
        v(-HALF_X + 0.03, -2.0, 0.9),
        v(-HALF_X + 0.03, 2.0, 0.9),
        v(-HALF_X + 0.03, -2.0, 2.2),
        40,
        13,
    );
    board.cuboid(v(-HALF_X, -2.1, 0.85), v(-HALF_X + 0.08, 2.1, 0.9));
    board.cuboid(v(-HALF_X, -2.1, 2.2), v(-HALF_X + 0.05, 2.1, 2.25));
    let mut shelves = Part::new("bookshelves", 0.4);
    let mut books = Part::new("books", 0.3);
    for s in 0..2 {
        let x0 = 0.2 + 2.2 * s as f64;
        for k in 0..6 {
            let z = 0.3 * k as f64;
            shelves.cuboid(v(x0, -HALF_Y, z), v(x0 + 2.0, -HALF_Y + 0.35, z + 0.03));
            for b in 0..40 {
                let w = 0.035 + 0.01 * ((b * 7 + k * 3 + s) % 4) as f64;
                let x = x0 + 0.05 * b as f64 + 0.005;
                let h = 0.18 + 0.02 * ((b * 5 + k) % 4) as f64;
                if k < 5 && x + w < x0 + 2.0 {
                    books.cuboid(
                        v(x, -HALF_Y + 0.03, z + 0.03),
                        v(x + w.min(0.045), -HALF_Y + 0.3, z + 0.03 + h),
                    );
                }
            }
        }
        shelves.cuboid(v(x0, -HALF_Y, 0.0), v(x0 + 0.03, -HALF_Y + 0.35, 1.53));
        shelves.cuboid(v(x0 + 1.97, -HALF_Y, 0.0), v(x0 + 2.0, -HALF_Y + 0.35, 1.53));
    }
    let mut lamps = Part::new("lamps", 0.9);
    for (x, y) in LAMPS {
        lamps.cylinder(v(x, y, 2.95), 0.25, 0.25, 48);
        lamps.cylinder(v(x, y, 2.95), 0.26, 0.01, 48);
    }
    let mut mirrors = Part::new("wall-mirrors", 0.2).mirror(0.85);
    mirrors.grid(
        v(HALF_X - 0.02, -1.5, 0.6),
        v(HALF_X - 0.02, 1.5, 0.6),
        v(HALF_X - 0.02, -1.5, 2.4),
        30,
        18,
    );
    mirrors.grid(
        v(-4.6, -HALF_Y + 0.02, 0.8),
        v(-1.0, -HALF_Y + 0.02, 0.8),
        v(-4.6, -HALF_Y + 0.02, 2.3),
        24,
        10,
    );
    let mut ball = Part::new("chrome-ball", 0.3).mirror(0.7);
    ball.sphere(v(-3.5, 0.4, 0.98), 0.2, 50, 96);
    ball.cylinder(v(-3.5, 0.4, 0.78), 0.05, 0.02, 24);
    vec![desks, chairs, teacher, board, shelves, books, lamps, mirrors, ball]
}

/// Where the four ceiling lamps hang; a point light sits 5 cm below each shade.
const LAMPS: [(f64, f64); 4] = [(-2.5, -2.0), (2.5, -2.0), (-2.5, 2.0), (2.5, 2.0)];

/// Triangles of [`classroom`] (the paper's classroom has 51,208): what a structure's memory is
/// estimated from before the scene is generated.
pub const TRIANGLES: usize = 51_224;

/// The classroom, always the same.
pub fn classroom() -> Generated {
    let mut parts = shell();
    parts.extend(furniture());
    let lights = LAMPS
        .iter()
        .map(|&(x, y)| Light::Point {
            position: v(x, y, 2.9),
            power: 4.0 * PI * 12.0,
        })
        .collect();
    let mut g = Generated {
        description: String::new(),
        parts,
        lights,
    };
    g.description = format!("procedural classroom, {} triangles", g.triangle_count());
    g
}

/// Frame `frame` of the fixed walk of `frames` frames: one loop at eye height round an
/// ellipse between the desks and the walls, looking at a point a sixth of a loop ahead on a
/// smaller ellipse at desk height.
pub fn camera_path(frame: u32, frames: u32) -> Camera {
    camera_on_loop(frame as f64 / frames.max(1) as f64)
}

/// Camera `frame` drawn at random from the walk, independently of every other frame, from the
/// seeded stream `seed`: its place on the loop uniform in [0, 1). Independent frames let a median
/// over them take an exact order-statistic interval (a path's consecutive frames are correlated).
pub fn random_camera(seed: u32, frame: u32) -> Camera {
    camera_on_loop(crate::sampling::Stream::new(seed, 0, Some(frame)).unit(0))
}

/// The walk's camera a fraction `t` of the way round the loop.
fn camera_on_loop(t: f64) -> Camera {
    let s = TAU * t;
    let position = v(-4.2 * s.cos(), -3.3 * s.sin(), 1.6);
    let ahead = s + TAU / 6.0;
    let look_at = v(-2.0 * ahead.cos(), -1.5 * ahead.sin(), 1.0);
    Camera {
        position,
        look_at,
        up: DVec3::Z,
        projection: Projection::Perspective { fov_y_deg: 65.0 },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_classroom_is_deterministic_and_about_the_papers_size() {
        let a = classroom();
        let n = a.triangle_count();
        assert_eq!(a.triangles().positions, classroom().triangles().positions);
        assert!((n as f64 / 51_208.0 - 1.0).abs() < 0.01, "{n} triangles");
        assert_eq!(n, TRIANGLES);
        assert_eq!(a.lights.len(), 4);
        assert!(a.parts.iter().filter(|p| p.mirror > 0.0).count() >= 2);
        for t in a.triangles().positions {
            for c in t {
                assert!(
                    c.x.abs() <= HALF_X + 1e-9 && c.y.abs() <= HALF_Y + 1e-9 && (-1e-9..=HEIGHT + 1e-9).contains(&c.z),
                    "{c}"
                );
            }
        }
        for f in [0, 105, 210, 315] {
            let c = camera_path(f, 420);
            assert!(c.position.x.abs() < HALF_X - 0.5 && c.position.y.abs() < HALF_Y - 0.5);
        }
    }
}
