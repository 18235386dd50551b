//! The viewer's camera: an orbit about the point the scene's camera looks at, around the
//! camera's up direction (orbit, pan and zoom from the mouse), and the sub-pixel jitter of
//! progressive supersampling.

use glam::DVec3;
use sdfc_compiler::Camera;

/// Radians of orbit per pixel dragged.
const ORBIT_PER_PIXEL: f64 = 0.008;
/// The highest and lowest elevation above the plane perpendicular to up (the camera must not
/// look along its up direction).
const PITCH_LIMIT: f64 = 85.0 * std::f64::consts::PI / 180.0;
/// Distance factor per wheel line.
const ZOOM_PER_LINE: f64 = 0.9;

/// A camera orbiting `target` at `distance`, at `yaw` about the camera's `up` and `pitch`
/// above the plane perpendicular to it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Orbit {
    /// The point looked at.
    pub target: [f64; 3],
    /// Distance from the eye to the target.
    pub distance: f64,
    /// Angle about +y, radians.
    pub yaw: f64,
    /// Elevation, radians.
    pub pitch: f64,
    /// Vertical field of view, radians.
    pub fov: f64,
    /// The camera's up direction (the orbit's axis).
    pub up: [f64; 3],
}

/// The orbit's frame: (a, b, n) with n the unit up and a, b perpendicular to it; for up +y,
/// a = +x and b = +z.
fn frame(up: [f64; 3]) -> (DVec3, DVec3, DVec3) {
    let n = DVec3::from(up).normalize_or_zero();
    let mut b = DVec3::Z - n * n.z;
    if b.length() < 1e-6 {
        b = DVec3::X - n * n.x;
    }
    let b = b.normalize_or_zero();
    (n.cross(b), b, n)
}

impl Orbit {
    /// The orbit that reproduces `camera` (its pitch clamped to the limit).
    pub fn from_camera(camera: &Camera) -> Orbit {
        let d = DVec3::from(camera.position) - DVec3::from(camera.look_at);
        let distance = d.length().max(1e-9);
        let up = if DVec3::from(camera.up).length() > 0.0 {
            camera.up
        } else {
            [0.0, 1.0, 0.0]
        };
        let (a, b, n) = frame(up);
        Orbit {
            target: camera.look_at,
            distance,
            yaw: d.dot(a).atan2(d.dot(b)),
            pitch: (d.dot(n) / distance)
                .clamp(-1.0, 1.0)
                .asin()
                .clamp(-PITCH_LIMIT, PITCH_LIMIT),
            fov: camera.fov,
            up,
        }
    }

    /// The scene camera of this orbit.
    pub fn camera(&self) -> Camera {
        let (sy, cy) = self.yaw.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        let (a, b, n) = frame(self.up);
        let offset = a * (cp * sy) + n * sp + b * (cp * cy);
        Camera {
            position: (DVec3::from(self.target) + offset * self.distance).into(),
            look_at: self.target,
            up: self.up,
            fov: self.fov,
        }
    }

    /// Orbits by a mouse drag of (`dx`, `dy`) pixels: the scene turns with the mouse.
    pub fn orbit(&mut self, dx: f64, dy: f64) {
        self.yaw -= dx * ORBIT_PER_PIXEL;
        self.pitch = (self.pitch + dy * ORBIT_PER_PIXEL).clamp(-PITCH_LIMIT, PITCH_LIMIT);
    }

    /// Pans by a mouse drag of (`dx`, `dy`) pixels in an image `height` pixels high: the
    /// point under the mouse at the target's depth follows it.
    pub fn pan(&mut self, dx: f64, dy: f64, height: u32) {
        let (_, u, v) = self.camera().basis();
        let per_pixel = 2.0 * self.distance * (self.fov * 0.5).tan() / height.max(1) as f64;
        let shift = DVec3::from(u) * (-dx * per_pixel) + DVec3::from(v) * (dy * per_pixel);
        self.target = (DVec3::from(self.target) + shift).into();
    }

    /// Zooms by `lines` wheel lines (positive: closer).
    pub fn zoom(&mut self, lines: f64) {
        self.distance = (self.distance * ZOOM_PER_LINE.powf(lines)).clamp(1e-4, 1e6);
    }
}

/// `camera` turned so that the centre of each pixel of a `width`×`height` image moves by
/// (`dx`, `dy`) pixels (right and down): a sub-pixel sample offset for progressive
/// supersampling, exact at the image centre and off by far less than a pixel elsewhere for
/// the offsets used (under half a pixel).
pub fn jittered(camera: &Camera, dx: f64, dy: f64, width: u32, height: u32) -> Camera {
    if dx == 0.0 && dy == 0.0 {
        return camera.clone();
    }
    let (w, u, v) = camera.basis();
    let tan = (camera.fov * 0.5).tan();
    let aspect = width.max(1) as f64 / height.max(1) as f64;
    let bx = 2.0 * dx / width.max(1) as f64;
    let by = -2.0 * dy / height.max(1) as f64;
    let (w, u, v) = (DVec3::from(w), DVec3::from(u), DVec3::from(v));
    let dir = w + (u * (bx * tan * aspect) + v * (by * tan));
    let (eye, target) = (DVec3::from(camera.position), DVec3::from(camera.look_at));
    let distance = (target - eye).length();
    Camera {
        position: camera.position,
        look_at: (eye + dir.normalize_or_zero() * distance).into(),
        up: camera.up,
        fov: camera.fov,
    }
}

/// The offset from the pixel centre, in pixels, of sample `k` of the `n`×`n` stratified grid
/// (the grid the renderers use for `aa: n`).
pub fn sample_offset(k: u32, n: u32) -> (f64, f64) {
    let n = n.max(1);
    let k = k % (n * n);
    let at = |i: u32| (i as f64 + 0.5) / n as f64 - 0.5;
    (at(k % n), at(k / n))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: [f64; 3], b: [f64; 3]) -> bool {
        (0..3).all(|i| (a[i] - b[i]).abs() < 1e-9)
    }

    #[test]
    fn an_orbit_reproduces_the_camera() {
        for up in [[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.3, 1.0, 0.1]] {
            let c = Camera {
                position: [1.0, 2.0, -6.0],
                look_at: [0.0, 0.5, 0.0],
                up,
                fov: 1.0,
            };
            let back = Orbit::from_camera(&c).camera();
            assert!(close(back.position, c.position) && close(back.look_at, c.look_at));
        }
    }

    #[test]
    fn zoom_moves_closer_and_pan_keeps_the_distance() {
        let mut o = Orbit::from_camera(&Camera::default());
        let d = o.distance;
        o.zoom(1.0);
        assert!(o.distance < d);
        let d = o.distance;
        o.pan(10.0, -5.0, 100);
        assert!((o.distance - d).abs() < 1e-12);
        o.orbit(1e4, 1e4);
        assert!(o.pitch <= PITCH_LIMIT);
    }

    #[test]
    fn samples_cover_the_grid() {
        assert_eq!(sample_offset(0, 1), (0.0, 0.0));
        assert_eq!(sample_offset(0, 2), (-0.25, -0.25));
        assert_eq!(sample_offset(3, 2), (0.25, 0.25));
        let c = Camera::default();
        assert_eq!(jittered(&c, 0.0, 0.0, 64, 48), c);
    }
}
