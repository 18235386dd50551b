//! The render settings of a scene (`render { }`), its rendering method among them.

use super::V3;

/// Render settings (docs/rendering.md); `sdfc render --set key=value` overrides them.
#[derive(Debug, Clone, PartialEq)]
pub struct Settings {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Supersampling grid edge (n×n samples per pixel).
    pub aa: u32,
    /// Sphere-tracing step budget per ray.
    pub max_steps: u32,
    /// Pixel-cone hit tolerance: hit when |d| < epsilon · t (unless `footprint`).
    pub epsilon: f64,
    /// Whether ε follows the pixel footprint instead of `epsilon`: ε is then the angular
    /// radius of a pixel, tan(fov/2)/height (see [`Settings::hit_epsilon`]). The checker sets
    /// it where the file gives no `epsilon` and the field has no proven distance bound
    /// (docs/accuracy.md, "Fields without a bound"); `--set epsilon` clears it.
    pub footprint: bool,
    /// Secondary-ray depth limit.
    pub max_depth: u32,
    /// Rays stop beyond this distance.
    pub max_dist: f64,
    /// Over-relaxation factor ω in [1, 2).
    pub relaxation: f64,
    /// Colour of rays that hit nothing.
    pub background: V3,
    /// How rays find surfaces (see [`Method`]).
    pub method: Method,
    /// How far from a surface ambient occlusion looks, R (0: none; docs/rendering.md, "The
    /// look").
    pub occlusion: f64,
    /// The distance D over which fog leaves e^(−t/D) of a surface's light (0: none).
    pub fog: f64,
    /// The fog's colour; `None`: the background.
    pub fog_color: Option<V3>,
    /// The distance G of the glow of a camera ray's marching steps: each evaluation of its
    /// march adds `glow_color·e^(−d/G)` (0: none; docs/rendering.md, "The look").
    pub glow: f64,
    /// The colour each marching step of a camera ray adds at a distance 0 from a surface.
    pub glow_color: V3,
    /// Exposure in stops: the pixel's colour is multiplied by 2^exposure.
    pub exposure: f64,
    /// The tone curve after the exposure.
    pub tonemap: crate::scene::Tonemap,
    /// Where `tonemap` was not given, why the tone curve is the default it is: what of the
    /// newer look the scene uses (`filmic`), or [`crate::scene::look::OLDER_LOOK`] (`none`;
    /// [`crate::scene::look::newer_look`]); `None` where it was given.
    pub tonemap_why: Option<&'static str>,
    /// Whether pictures are path traced (`method: "path"`; docs/rendering.md, "Path
    /// tracing"): `samples` paths a pixel of up to `bounces` bounces, intersected as
    /// `method` says (`auto` for `method: "path"`).
    pub path: bool,
    /// The path tracer's samples (paths) per pixel.
    pub samples: u32,
    /// The path tracer's bounces after the camera ray's hit.
    pub bounces: u32,
    /// The number of the path tracer's first sample in its random stream (not a language
    /// field: `sdfc view` renders sample `k` of a resting camera as frame `k`, with one
    /// sample each, so that its frames add up to the picture of `samples` samples).
    pub first_sample: u32,
}

/// The intersection method of a render (docs/rendering.md, "Marching" and "Analytic ray tracing").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Method {
    /// Analytic ray tracing when the scene allows it, sphere tracing otherwise.
    #[default]
    Auto,
    /// Analytic ray tracing; an error for a scene that does not allow it.
    Trace,
    /// Sphere tracing, whatever the scene.
    March,
}

impl Method {
    /// The names of the methods, as the `method` setting spells them.
    pub const NAMES: &'static [&'static str] = &["auto", "trace", "march"];

    /// The method of a name in [`Method::NAMES`].
    pub fn from_name(name: &str) -> Option<Method> {
        match name {
            "auto" => Some(Method::Auto),
            "trace" => Some(Method::Trace),
            "march" => Some(Method::March),
            _ => None,
        }
    }

    /// The method's name.
    pub const fn name(self) -> &'static str {
        match self {
            Method::Auto => "auto",
            Method::Trace => "trace",
            Method::March => "march",
        }
    }
}

impl Settings {
    /// Whether camera rays glow with their marching steps (`glow` > 0, not path traced:
    /// docs/rendering.md, "The look").
    pub fn glows(&self) -> bool {
        self.glow > 0.0 && !self.path
    }

    /// The ε of the hit test for a camera of field of view `fov` (radians): `epsilon`, or
    /// where `footprint`, the angular radius of one pixel, tan(fov/2)/height: the surface as a
    /// cone one pixel wide sees it.
    pub fn hit_epsilon(&self, fov: f64) -> f64 {
        if self.footprint {
            (fov * 0.5).tan() / self.height.max(1) as f64
        } else {
            self.epsilon
        }
    }

    /// The fog's colour: `fog_color`, or where it is not given, the background.
    pub fn fog_colour(&self) -> V3 {
        self.fog_color.unwrap_or(self.background)
    }

    /// The settings of a scene without a `render` block, and the default of each field of one
    /// (`check/builtins.rs` reads them here).
    pub const DEFAULT: Settings = Settings {
        width: 640,
        height: 480,
        aa: 1,
        max_steps: 512,
        epsilon: 1e-5,
        footprint: false,
        max_depth: 5,
        max_dist: 100.0,
        relaxation: 1.4,
        background: [0.05, 0.06, 0.08],
        method: Method::Auto,
        occlusion: 0.0,
        fog: 0.0,
        fog_color: None,
        glow: 0.0,
        glow_color: [0.02, 0.02, 0.02],
        exposure: 0.0,
        tonemap: crate::scene::Tonemap::None,
        tonemap_why: None,
        path: false,
        samples: 16,
        bounces: 4,
        first_sample: 0,
    };

    /// The names the `method` setting accepts: [`Method::NAMES`] and `"path"`.
    pub const METHODS: &'static [&'static str] = &["auto", "trace", "march", "path"];

    /// Sets the `method` setting by its name: a [`Method`] (the Whitted renderer), or
    /// `"path"`, the path tracer intersecting as `auto` does. `false` for an unknown name.
    pub fn set_method(&mut self, name: &str) -> bool {
        if name == "path" {
            self.method = Method::Auto;
            self.path = true;
            return true;
        }
        match Method::from_name(name) {
            Some(m) => {
                self.method = m;
                self.path = false;
                true
            }
            None => false,
        }
    }

    /// The `method` setting's name: `"path"` for the path tracer, else [`Method::name`].
    pub fn method_name(&self) -> &'static str {
        if self.path {
            "path"
        } else {
            self.method.name()
        }
    }
}

impl Default for Settings {
    fn default() -> Self {
        Settings::DEFAULT
    }
}
