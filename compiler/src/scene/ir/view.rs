//! The lights (their penumbrae and shadows) and the camera (its basis).

use super::V3;
use glam::DVec3;

/// A light source.
#[derive(Debug, Clone, PartialEq)]
pub enum Light {
    /// A point light whose contribution falls to zero at `radius`.
    Point {
        position: V3,
        color: V3,
        intensity: f64,
        radius: f64,
        /// The angle of the penumbra in radians (0 gives hard shadows); see [`Light::sharpness`].
        penumbra: f64,
        /// Whether it casts shadows (`shadows: false`: no shadow rays).
        shadows: bool,
    },
    /// A light from a direction (the direction light travels in), with no attenuation.
    Directional {
        direction: V3,
        color: V3,
        intensity: f64,
        /// The angle of the penumbra in radians (0 gives hard shadows); see [`Light::sharpness`].
        /// A `sun`'s is its angular size, `angle`.
        penumbra: f64,
        /// Whether it casts shadows (`shadows: false`: no shadow rays).
        shadows: bool,
    },
    /// Light from the whole sky (docs/rendering.md, "Sky light"): radiance `zenith` straight
    /// up, `horizon` at the horizon, linear in the height of the direction between them,
    /// `ground` below the horizon, each times `intensity`.
    Sky {
        zenith: V3,
        horizon: V3,
        ground: V3,
        intensity: f64,
        /// Whether the ambient occlusion (the `occlusion` render setting) scales its light.
        shadows: bool,
        /// Whether rays that hit nothing show it instead of the `background` colour.
        background: bool,
    },
}

impl Light {
    /// The penumbra angle in radians; 0 means hard shadows.
    pub fn penumbra(&self) -> f64 {
        match self {
            Light::Point { penumbra, .. } | Light::Directional { penumbra, .. } => *penumbra,
            Light::Sky { .. } => 0.0,
        }
    }

    /// Whether it casts shadows (a sky's are its occlusion).
    pub fn shadows(&self) -> bool {
        match self {
            Light::Point { shadows, .. }
            | Light::Directional { shadows, .. }
            | Light::Sky { shadows, .. } => *shadows,
        }
    }

    /// The sharpness k of the soft-shadow estimate `min(k·d/t)` (docs/rendering.md,
    /// "Shadows"): a point whose ray to the light passes an occluder at angular distance
    /// `atan(d/t)` of at least the penumbra angle θ is fully lit, so k = 1/tan θ; 0 (hard
    /// shadows) for θ = 0.
    pub fn sharpness(&self) -> f64 {
        sharpness(self.penumbra())
    }

    /// A soft shadow ray's search around a least `k·d/t` (docs/rendering.md, "Shadows") ends
    /// once its bracket is narrower than this fraction of the penumbra cone's width there.
    pub const PENUMBRA_BRACKET: f64 = 0.02;
    /// The most evaluations one such search takes.
    pub const PENUMBRA_PROBES: u32 = 16;
}

/// The soft-shadow sharpness k = 1/tan θ of a penumbra angle θ (0 for θ = 0).
fn sharpness(penumbra: f64) -> f64 {
    if penumbra > 0.0 {
        1.0 / penumbra.tan()
    } else {
        0.0
    }
}

/// The penumbra angle θ = atan(1/k) of a soft-shadow sharpness k (0 for k = 0): the inverse
/// of [`sharpness`], for files written with the old `softness` field.
pub fn penumbra_of_sharpness(k: f64) -> f64 {
    if k > 0.0 {
        (1.0 / k).atan()
    } else {
        0.0
    }
}

/// A pinhole camera.
#[derive(Debug, Clone, PartialEq)]
pub struct Camera {
    /// Eye position.
    pub position: V3,
    /// The point looked at.
    pub look_at: V3,
    /// The direction that is up in the image (need not be perpendicular to the view).
    pub up: V3,
    /// Vertical field of view in radians.
    pub fov: f64,
}

impl Camera {
    /// The camera's orthonormal basis `(w, u, v)` (docs/rendering.md, "Camera"): `w` the view
    /// direction `normalize(look_at − position)`, `u = normalize(w × up)` (the image's
    /// rightward direction), `v = u × w` (the image's up). Where `up` is parallel to
    /// the view (looking straight down or up with the default up), the coordinate axis least
    /// aligned with the view stands in for it, so every camera has a valid basis. Computed in
    /// f64 once, for every backend.
    pub fn basis(&self) -> (V3, V3, V3) {
        let up = DVec3::from(self.up);
        let w = unit(DVec3::from(self.look_at) - DVec3::from(self.position));
        let mut side = w.cross(up);
        if side.length_squared() < 1e-12 * up.length_squared() {
            // z first: of equally unaligned axes +z wins, so looking straight down the top
            // of the image is +z, as for a camera that approaches the vertical from −z.
            let axis = [2, 0, 1]
                .into_iter()
                .min_by(|&a, &b| w[a].abs().total_cmp(&w[b].abs()))
                .unwrap_or(2);
            side = w.cross(DVec3::AXES[axis]);
        }
        let u = unit(side);
        (w.into(), u.into(), u.cross(w).into())
    }
}

/// `a` scaled to length 1 (zero stays zero).
fn unit(a: DVec3) -> DVec3 {
    let l = a.length();
    if l > 0.0 {
        a / l
    } else {
        a
    }
}

impl Camera {
    /// The field of view of a camera that gives none, in degrees.
    pub const FOV_DEGREES: f64 = 60.0;

    /// The camera of a scene without a `camera` block, and the default of each field of one
    /// (`check/builtins.rs` reads them here).
    pub const DEFAULT: Camera = Camera {
        position: [0.0, 1.0, -5.0],
        look_at: [0.0, 0.0, 0.0],
        up: [0.0, 1.0, 0.0],
        fov: Camera::FOV_DEGREES.to_radians(),
    };
}

impl Default for Camera {
    fn default() -> Self {
        Camera::DEFAULT
    }
}
