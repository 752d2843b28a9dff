//! A pinhole camera: one primary ray through the centre of each pixel.

use super::scene::Ray;
use glam::DVec3;

/// A pinhole camera at `eye` looking at `target`, `+z` up, with a vertical field of
/// view and an image of `width x height` pixels (row 0 at the top).
#[derive(Clone, Copy, Debug)]
pub struct Camera {
    eye: DVec3,
    forward: DVec3,
    right: DVec3,
    up: DVec3,
    /// `tan(fov / 2)`.
    tan_half: f64,
    width: u32,
    height: u32,
}

impl Camera {
    /// The camera; `fov_deg` is the vertical field of view in degrees (in
    /// `(0, 180)`), `target != eye` and the view not vertical.
    pub fn new(eye: DVec3, target: DVec3, fov_deg: f64, width: u32, height: u32) -> Self {
        let forward = (target - eye).normalize();
        let right = forward.cross(DVec3::Z).normalize();
        let up = right.cross(forward);
        Self {
            eye,
            forward,
            right,
            up,
            tan_half: (0.5 * fov_deg.to_radians()).tan(),
            width,
            height,
        }
    }

    /// The evaluation's view of [`super::scene::Scene::spheres_on_ground`]: from
    /// `(0, -10, 7)` towards `(0, 0, 1.2)`, 45° vertical field of view, high
    /// enough to see the back row (the metals) over the front row.
    pub fn evaluation(width: u32, height: u32) -> Self {
        Self::new(
            DVec3::new(0.0, -10.0, 7.0),
            DVec3::new(0.0, 0.0, 1.2),
            45.0,
            width,
            height,
        )
    }

    /// Image width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Image height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Row-major index of pixel `(x, y)`, `y width + x`: its place in an image and
    /// the stream of its random numbers.
    pub fn pixel_index(&self, x: u32, y: u32) -> u64 {
        y as u64 * self.width as u64 + x as u64
    }

    /// The ray through the centre of pixel `(x, y)` (`y = 0` the top row).
    pub fn ray(&self, x: u32, y: u32) -> Ray {
        let aspect = self.width as f64 / self.height as f64;
        let sx = (2.0 * (x as f64 + 0.5) / self.width as f64 - 1.0) * self.tan_half * aspect;
        let sy = (1.0 - 2.0 * (y as f64 + 0.5) / self.height as f64) * self.tan_half;
        Ray {
            origin: self.eye,
            direction: (self.forward + sx * self.right + sy * self.up).normalize(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centre_ray_looks_at_the_target_and_corners_span_the_field_of_view() {
        let eye = DVec3::new(1.0, -5.0, 2.0);
        let target = DVec3::new(1.0, 0.0, 2.0);
        // Odd sizes: the middle pixel's centre is the image centre.
        let cam = Camera::new(eye, target, 90.0, 41, 21);
        let mid = cam.ray(20, 10);
        assert!((mid.direction - DVec3::Y).length() < 1e-12);
        // The top edge of a 90° view is at 45° above the axis; the top row's centre
        // is half a pixel below it.
        let top = cam.ray(20, 0).direction;
        let expect = (1.0 - 1.0 / 21.0f64).atan();
        assert!((top.z.atan2(top.y) - expect).abs() < 1e-12);
        // x grows to the right: +x for a camera looking along +y.
        assert!(cam.ray(40, 10).direction.x > 0.0);
    }
}
