//! Cameras: perspective for pictures, orthographic top-down for measuring the receiver plane.

use glam::DVec3;

/// How a camera maps pixels to rays.
#[derive(Clone, Debug, PartialEq)]
pub enum Projection {
    /// Pinhole camera with a vertical field of view in degrees.
    Perspective {
        /// Vertical field of view, degrees.
        fov_y_deg: f64,
    },
    /// Parallel rays; `width` metres span the image horizontally. Seen from straight above, each
    /// pixel of the receiver plane is a point at a known position, which makes radial profiles exact.
    Orthographic {
        /// Horizontal extent of the image in metres.
        width: f64,
    },
}

/// A camera in world space (metres, z up by convention of the shipped scenes).
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    /// Eye position (perspective) or centre of the image plane (orthographic).
    pub position: DVec3,
    /// Point the camera looks at.
    pub look_at: DVec3,
    /// Approximate up direction.
    pub up: DVec3,
    /// Projection model.
    pub projection: Projection,
}

/// A camera ray; `direction` is unit length.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Origin.
    pub origin: DVec3,
    /// Unit direction.
    pub direction: DVec3,
}

/// The camera's orthonormal frame: right, up, forward.
#[derive(Clone, Copy, Debug)]
pub struct Basis {
    /// +x of the image.
    pub right: DVec3,
    /// +y of the image (rows grow downwards).
    pub up: DVec3,
    /// Viewing direction.
    pub forward: DVec3,
}

impl Camera {
    /// The camera's frame; `None` when `up` is parallel to the viewing direction.
    pub fn frame(&self) -> Option<Basis> {
        let forward = (self.look_at - self.position).try_normalize()?;
        let right = forward.cross(self.up).try_normalize()?;
        Some(Basis {
            right,
            up: right.cross(forward),
            forward,
        })
    }

    /// Half extents of the image plane at unit distance (perspective) or in metres (orthographic).
    fn half_extents(&self, width: u32, height: u32) -> (f64, f64) {
        let aspect = width as f64 / height as f64;
        match self.projection {
            Projection::Perspective { fov_y_deg } => {
                let hy = (fov_y_deg.to_radians() * 0.5).tan();
                (hy * aspect, hy)
            }
            Projection::Orthographic { width: w } => (0.5 * w, 0.5 * w / aspect),
        }
    }

    /// The ray through the centre of pixel (x, y) of a `width` x `height` image; row 0 is the top.
    pub fn ray(&self, x: u32, y: u32, width: u32, height: u32) -> Ray {
        self.ray_at(x as f64 + 0.5, y as f64 + 0.5, width, height)
    }

    /// The ray through image position (x, y) in pixels from the top-left corner (a pixel's
    /// centre is at +0.5 in both): for references averaged over a pixel's square.
    pub fn ray_at(&self, x: f64, y: f64, width: u32, height: u32) -> Ray {
        let f = self.frame().expect("validated camera has a frame");
        let (hx, hy) = self.half_extents(width, height);
        let sx = (2.0 * x / width as f64 - 1.0) * hx;
        let sy = (1.0 - 2.0 * y / height as f64) * hy;
        match self.projection {
            Projection::Perspective { .. } => Ray {
                origin: self.position,
                direction: (f.forward + sx * f.right + sy * f.up).normalize(),
            },
            Projection::Orthographic { .. } => Ray {
                origin: self.position + sx * f.right + sy * f.up,
                direction: f.forward,
            },
        }
    }

    /// Parameters the GPU needs to generate the same rays: frame, half extents, kind.
    pub fn gpu_terms(&self, width: u32, height: u32) -> (Basis, (f64, f64), bool) {
        let f = self.frame().expect("validated camera has a frame");
        (
            f,
            self.half_extents(width, height),
            matches!(self.projection, Projection::Orthographic { .. }),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orthographic_pixels_tile_the_view() {
        let c = Camera {
            position: DVec3::new(1.0, 2.0, 5.0),
            look_at: DVec3::new(1.0, 2.0, 0.0),
            up: DVec3::Y,
            projection: Projection::Orthographic { width: 4.0 },
        };
        let r = c.ray(0, 0, 4, 2);
        assert_eq!(r.direction, DVec3::NEG_Z);
        // Pixel (0, 0) centre: half a pixel (0.5 m) in from the top-left corner (-2, +1).
        assert!((r.origin - DVec3::new(1.0 - 1.5, 2.0 + 0.5, 5.0)).length() < 1e-12);
    }

    #[test]
    fn perspective_centre_ray_looks_at_target() {
        let c = Camera {
            position: DVec3::ZERO,
            look_at: DVec3::new(0.0, 3.0, 0.0),
            up: DVec3::Z,
            projection: Projection::Perspective { fov_y_deg: 60.0 },
        };
        let r = c.ray(1, 1, 3, 3);
        assert!((r.direction - DVec3::Y).length() < 1e-12);
    }

    #[test]
    fn degenerate_up_has_no_frame() {
        let c = Camera {
            position: DVec3::ZERO,
            look_at: DVec3::NEG_Z,
            up: DVec3::Z,
            projection: Projection::Perspective { fov_y_deg: 60.0 },
        };
        assert!(c.frame().is_none());
    }
}
