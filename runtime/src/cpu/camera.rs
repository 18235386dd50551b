//! The pinhole camera of docs/rendering.md, "Camera", and the supersampling grid.

use super::vec::V3;
use sdfc_compiler::{Camera, Float, Settings};

/// A camera prepared for generating rays.
#[derive(Debug, Clone, Copy)]
pub struct Pinhole<T> {
    origin: V3<T>,
    w: V3<T>,
    u: V3<T>,
    v: V3<T>,
    /// tan(fov/2)·aspect and tan(fov/2).
    scale: (T, T),
    size: (T, T),
    aa: u32,
}

impl<T: Float> Pinhole<T> {
    /// The camera for an image of the settings' size, with the basis of [`Camera::basis`]
    /// (computed in f64, as for the GPU kernel).
    pub fn new(camera: &Camera, settings: &Settings) -> Self {
        let origin = V3::from_f64(camera.position);
        let (w, u, v) = camera.basis();
        let (w, u, v) = (V3::from_f64(w), V3::from_f64(u), V3::from_f64(v));
        let tan = T::from_f64((camera.fov * 0.5).tan());
        let (width, height) = (settings.width.max(1) as f64, settings.height.max(1) as f64);
        let aspect = T::from_f64(width / height);
        let size = (T::from_f64(width), T::from_f64(height));
        Pinhole {
            origin,
            w,
            u,
            v,
            scale: (tan * aspect, tan),
            size,
            aa: settings.aa.max(1),
        }
    }

    /// The eye position.
    pub fn origin(&self) -> V3<T> {
        self.origin
    }

    /// Samples per pixel (n×n).
    pub fn samples_per_pixel(&self) -> u32 {
        self.aa * self.aa
    }

    /// The direction of sample `s` (row-major in the n×n grid) of pixel (x, y): the sample
    /// sits at a = ((x + (i+0.5)/n) / W, (y + (j+0.5)/n) / H), b = (2a.x - 1, 1 - 2a.y),
    /// D = normalize(w + b.x·tan(fov/2)·aspect·u + b.y·tan(fov/2)·v).
    pub fn direction(&self, x: u32, y: u32, s: u32) -> V3<T> {
        let n = T::from_f64(self.aa as f64);
        let half = T::from_f64(0.5);
        let (i, j) = (
            T::from_f64((s % self.aa) as f64),
            T::from_f64((s / self.aa) as f64),
        );
        let ax = (T::from_f64(x as f64) + (i + half) / n) / self.size.0;
        let ay = (T::from_f64(y as f64) + (j + half) / n) / self.size.1;
        let two = T::from_f64(2.0);
        let bx = two * ax - T::one();
        let by = T::one() - two * ay;
        (self.w + self.u * (bx * self.scale.0) + self.v * (by * self.scale.1)).normalize()
    }

    /// The direction through the point `(x + jx, y + jy)` of the image, `jx`, `jy` in [0, 1)
    /// (the path tracer's jittered samples): `direction`'s formula with `a = ((x + jx)/W,
    /// (y + jy)/H)`.
    pub fn jittered(&self, x: u32, y: u32, jx: T, jy: T) -> V3<T> {
        let ax = (T::from_f64(x as f64) + jx) / self.size.0;
        let ay = (T::from_f64(y as f64) + jy) / self.size.1;
        let two = T::from_f64(2.0);
        let bx = two * ax - T::one();
        let by = T::one() - two * ay;
        (self.w + self.u * (bx * self.scale.0) + self.v * (by * self.scale.1)).normalize()
    }
}
