//! Everything a tile needs, prepared once per render in the evaluation type: settings,
//! camera, materials and lights. (The two tapes, distance only and distance and material,
//! are prepared once per scene: [`super::Tapes`].)

use super::analytic::Tracer;
use super::camera::Pinhole;
use super::vec::V3;
use sdfc_compiler::{
    analytic::Traceable, Colour, ColourProgram, Colours, Float, Light, Material, Pattern, Scene,
    Tonemap,
};

/// One colour of a material: a constant, or the colour field of this number
/// ([`Context::colours`]).
#[derive(Debug, Clone, Copy)]
pub(super) enum Tint<T> {
    Const(V3<T>),
    Field(usize),
}

/// The colour of a material at a point.
#[derive(Debug, Clone, Copy)]
pub(super) enum Paint<T> {
    Solid(Tint<T>),
    /// `shift`: [`Scene::checker_shift`].
    Checker {
        a: Tint<T>,
        b: Tint<T>,
        inv_size: T,
        shift: V3<T>,
    },
    /// A checker of the two materials of these ids (`Pattern::Materials`): a hit on it takes
    /// one of them, or their blend (`shade::checkered`).
    Materials {
        a: u32,
        b: u32,
        inv_size: T,
        shift: V3<T>,
    },
}

/// A material in the evaluation type: Phong, or physically based where `pbr` is given.
#[derive(Debug, Clone, Copy)]
pub(super) struct Mat<T> {
    pub paint: Paint<T>,
    pub ambient: T,
    pub diffuse: T,
    pub specular: T,
    pub shininess: T,
    pub reflect: T,
    pub transparency: T,
    pub ior: T,
    /// Schlick's Fresnel term on the reflected and refracted rays.
    pub fresnel: bool,
    /// Whether a hit on it spawns a reflected ray ([`Material::reflects`]).
    pub reflects: bool,
    /// The reflectance at normal incidence of a dielectric of its `ior`.
    pub f0: T,
    pub pbr: Option<PbrMat<T>>,
}

impl<T: Float> Mat<T> {
    /// The blend of two materials of one model with the weight `w` of `other` (docs/rendering.md,
    /// "The checker's footprint"): every number `x·(1 − w) + y·w`, of colour `colour`; Fresnel
    /// and reflections where either has them.
    pub fn blend(&self, other: &Mat<T>, w: T, colour: V3<T>) -> Mat<T> {
        let mix = |x: T, y: T| x * (T::one() - w) + y * w;
        Mat {
            paint: Paint::Solid(Tint::Const(colour)),
            ambient: mix(self.ambient, other.ambient),
            diffuse: mix(self.diffuse, other.diffuse),
            specular: mix(self.specular, other.specular),
            shininess: mix(self.shininess, other.shininess),
            reflect: mix(self.reflect, other.reflect),
            transparency: mix(self.transparency, other.transparency),
            ior: mix(self.ior, other.ior),
            fresnel: self.fresnel || other.fresnel,
            reflects: self.reflects || other.reflects,
            f0: mix(self.f0, other.f0),
            pbr: match (self.pbr, other.pbr) {
                (Some(p), Some(q)) => Some(PbrMat {
                    roughness: mix(p.roughness, q.roughness),
                    alpha: mix(p.alpha, q.alpha),
                    metallic: mix(p.metallic, q.metallic),
                    emission: p.emission * (T::one() - w) + q.emission * w,
                    mirror: mix(p.mirror, q.mirror),
                }),
                // The checker refuses two models.
                _ => other.pbr,
            },
        }
    }
}

/// The parameters of a `pbr` material in the evaluation type (`sdfc_compiler::pbr`).
#[derive(Debug, Clone, Copy)]
pub(super) struct PbrMat<T> {
    pub roughness: T,
    /// The GGX width α.
    pub alpha: T,
    pub metallic: T,
    pub emission: V3<T>,
    /// The weight g of the environment's specular reflection a reflected ray carries.
    pub mirror: T,
}

/// A light in the evaluation type; `color` is colour × intensity (I_l); `sharpness` is
/// the shadows' k (0: hard), or −1 for a light without shadows.
#[derive(Debug, Clone, Copy)]
pub(super) enum Lamp<T> {
    Point {
        position: V3<T>,
        color: V3<T>,
        radius: T,
        sharpness: T,
    },
    Directional {
        to_light: V3<T>,
        color: V3<T>,
        sharpness: T,
        /// The cosine of half its penumbra angle: the path tracer samples it as a disc of
        /// that angular diameter (a sun's is its `angle`; 1 for none).
        cos_disc: T,
    },
}

/// A sky light in the evaluation type, times its intensity: its irradiance coefficients
/// (`look::sky_irradiance`) and its radiance.
#[derive(Debug, Clone, Copy)]
pub(super) struct Sky<T> {
    pub irradiance: [V3<T>; 3],
    pub zenith: V3<T>,
    pub horizon: V3<T>,
    pub ground: V3<T>,
    /// Whether the occlusion scales its light.
    pub occluded: bool,
    /// Whether rays that hit nothing show it.
    pub background: bool,
}

/// Render-wide constants.
#[derive(Debug)]
pub(super) struct Context<T: Float> {
    pub camera: Pinhole<T>,
    pub epsilon: T,
    pub max_dist: T,
    pub max_steps: u32,
    pub max_depth: u32,
    pub relaxation: T,
    /// 1 / L, the step scale.
    pub inv_lipschitz: T,
    pub background: V3<T>,
    pub materials: Vec<Mat<T>>,
    pub lamps: Vec<Lamp<T>>,
    pub skies: Vec<Sky<T>>,
    /// Whether rays that hit nothing show the skies that are the background.
    pub sky_background: bool,
    /// Whether any material is transparent (shadow rays then look up materials).
    pub transparent: bool,
    /// The most rays one hit spawns (0, 1 or 2: a reflection and a refraction).
    pub branching: usize,
    /// `--debug-nan`: pixels whose rays met a NaN are painted [`super::NAN_COLOUR`].
    pub debug_nan: bool,
    /// The primitives, when the scene is ray traced analytically instead of sphere traced.
    pub analytic: Option<Tracer<T>>,
    /// The materials' colour fields (`lower::Colours::programs`).
    pub colours: Vec<ColourProgram>,
    /// The occlusion radius R (0: none).
    pub occlusion: T,
    /// 1/D for fog over a distance D (0: none).
    pub inv_fog: T,
    /// 1/G for a glow of the camera rays' marching steps over a distance G (0: none).
    pub inv_glow: T,
    /// The glow's colour.
    pub glow: V3<T>,
    /// The fog's colour, where `fog_color` is given (else the background seen along the ray:
    /// [`Context::fog_colour`]).
    pub fog: Option<V3<T>>,
    /// Whether the pixels are graded (an exposure or a tone curve): [`super::look::grade`].
    pub graded: bool,
    /// 2^exposure.
    pub exposure: T,
    pub tonemap: Tonemap,
    /// A sample's pitch at unit distance: 2·tan(fov/2)/(height·aa), the width of its
    /// footprint on a surface facing it at distance 1 (the filtered checker's; the path
    /// tracer's samples spread over the whole pixel: aa counts as 1).
    pub pitch: T,
    /// Whether the render is path traced (`super::path`), with `samples` paths a pixel of
    /// up to `bounces` bounces.
    pub path: bool,
    pub samples: u32,
    pub bounces: u32,
    /// The number of the first sample in the random stream (`Settings::first_sample`).
    pub first_sample: u32,
    /// The image's width (the path tracer's pixel numbers are `y·width + x`).
    pub width: u32,
}

impl<T: Float> Context<T> {
    /// The context of a render of `scene`, traced analytically when `traceable` and its
    /// `method` setting say so.
    pub fn new(
        scene: &Scene,
        traceable: &Traceable,
        colours: &[ColourProgram],
        lipschitz: f64,
        debug_nan: bool,
    ) -> Self {
        let s = &scene.settings;
        let numbers = Colours::numbers(scene);
        let mut materials: Vec<Mat<T>> = scene
            .materials
            .iter()
            .zip(&numbers)
            .map(|(m, fields)| mat(scene, m, *fields))
            .collect();
        if materials.is_empty() {
            materials.push(mat(scene, &Material::default_material(), [None; 2]));
        }
        // The path tracer's shadow rays are stopped by every surface (light through glass
        // arrives along the paths that refract), so they look up no material.
        let transparent = !s.path && materials.iter().any(|m| m.transparency > T::zero());
        let aa = if s.path { 1 } else { s.aa.max(1) };
        Context {
            camera: Pinhole::new(&scene.camera, s),
            epsilon: T::from_f64(scene.epsilon()),
            max_dist: T::from_f64(s.max_dist),
            max_steps: s.max_steps.max(1),
            max_depth: s.max_depth,
            relaxation: T::from_f64(s.relaxation.max(1.0)),
            inv_lipschitz: T::from_f64(1.0 / lipschitz.max(1.0)),
            background: V3::from_f64(s.background),
            materials,
            lamps: scene.lights.iter().filter_map(lamp).collect(),
            skies: scene.lights.iter().filter_map(sky).collect(),
            sky_background: scene.lights.iter().any(|l| {
                matches!(
                    l,
                    Light::Sky {
                        background: true,
                        ..
                    }
                )
            }),
            transparent,
            branching: branching(scene),
            debug_nan,
            analytic: traceable.traced(s.method).map(Tracer::new),
            colours: colours.to_vec(),
            occlusion: T::from_f64(s.occlusion),
            inv_fog: T::from_f64(if s.fog > 0.0 { 1.0 / s.fog } else { 0.0 }),
            inv_glow: T::from_f64(if s.glows() { 1.0 / s.glow } else { 0.0 }),
            glow: V3::from_f64(s.glow_color),
            fog: s.fog_color.map(V3::from_f64),
            graded: s.exposure != 0.0 || s.tonemap != Tonemap::None,
            exposure: T::from_f64(s.exposure.exp2()),
            tonemap: s.tonemap,
            pitch: T::from_f64(2.0) * T::from_f64((scene.camera.fov * 0.5).tan())
                / (T::from_f64(s.height.max(1) as f64) * T::from_f64(aa as f64)),
            path: s.path,
            samples: s.samples.max(1),
            bounces: s.bounces,
            first_sample: s.first_sample,
            width: s.width,
        }
    }

    /// The material of an id (unknown ids get material 0).
    pub fn material(&self, id: u32) -> &Mat<T> {
        self.materials
            .get(id as usize)
            .unwrap_or(&self.materials[0])
    }

    /// The normal step at a hit: h = max(L·ε·t, 64·machine ε·(1 + |p|∞)), where t is the
    /// path length; a hit may lie up to L·ε·t from the surface, and the floor keeps the
    /// differences above the rounding noise of `T`.
    pub fn normal_step(&self, tt: T, p: V3<T>) -> T {
        let floor = T::from_f64(64.0) * T::EPSILON * (T::one() + p.max_abs());
        (self.epsilon * tt / self.inv_lipschitz).max(floor)
    }

    /// The hit tolerance at a point: the pixel cone's `cone` (ε·t), but never below a few
    /// units in the last place of the point's coordinates, where the field cannot resolve
    /// anything finer (far from the origin).
    #[inline(always)]
    pub fn tolerance(&self, cone: T, x: T, y: T, z: T) -> T {
        let m = x.abs().max(y.abs()).max(z.abs());
        cone.max(T::from_f64(8.0) * T::EPSILON * m)
    }
}

/// The most rays one hit spawns: a reflection where the material reflects
/// ([`Material::reflects`]) and a refraction (or, on
/// total internal reflection, a reflection) where `transparency` > 0; an exit from a solid
/// spawns one, and no hit spawns any at `max_depth` 0.
pub(super) fn branching(scene: &Scene) -> usize {
    if scene.settings.max_depth == 0 {
        return 0;
    }
    scene
        .materials
        .iter()
        .map(|m| (m.reflects() as usize) + (m.transparency > 0.0) as usize)
        .max()
        .unwrap_or(0)
}

fn mat<T: Float>(scene: &Scene, m: &Material, fields: [Option<usize>; 2]) -> Mat<T> {
    let f = T::from_f64;
    let tint = |c: &Colour, slot: usize| match (c, fields[slot]) {
        (Colour::Const(c), _) => Tint::Const(V3::from_f64(*c)),
        (Colour::Field(_), Some(k)) => Tint::Field(k),
        (Colour::Field(_), None) => Tint::Const(V3::zero()),
    };
    let paint = match &m.pattern {
        Pattern::Solid(c) => Paint::Solid(tint(c, 0)),
        Pattern::Checker { a, b, size } => Paint::Checker {
            a: tint(a, 0),
            b: tint(b, 1),
            inv_size: f(1.0 / size),
            shift: V3::from_f64(scene.checker_shift(*size)),
        },
        Pattern::Materials { a, b, size } => Paint::Materials {
            a: a.0,
            b: b.0,
            inv_size: f(1.0 / size),
            shift: V3::from_f64(scene.checker_shift(*size)),
        },
    };
    Mat {
        paint,
        ambient: f(m.ambient),
        diffuse: f(m.diffuse),
        specular: f(m.specular),
        shininess: f(m.shininess),
        reflect: f(m.reflect),
        transparency: f(m.transparency),
        ior: f(m.ior.max(1e-6)),
        fresnel: m.fresnel,
        reflects: m.reflects(),
        f0: f(sdfc_compiler::pbr::f0(m.ior)),
        pbr: m.pbr.map(|p| PbrMat {
            roughness: f(p.roughness),
            alpha: f(p.alpha()),
            metallic: f(p.metallic),
            emission: V3::from_f64(p.emission),
            mirror: f(p.mirror()),
        }),
    }
}

/// The shadows' sharpness k of a light, −1 without shadows.
fn sharpness<T: Float>(l: &Light) -> T {
    T::from_f64(if l.shadows() { l.sharpness() } else { -1.0 })
}

fn sky<T: Float>(l: &Light) -> Option<Sky<T>> {
    let Light::Sky {
        zenith,
        horizon,
        ground,
        intensity,
        shadows,
        background,
    } = l
    else {
        return None;
    };
    let scaled = |c: [f64; 3]| V3::from_f64(c) * T::from_f64(*intensity);
    let c = sdfc_compiler::look::sky_irradiance(*zenith, *horizon, *ground);
    Some(Sky {
        irradiance: c.map(scaled),
        zenith: scaled(*zenith),
        horizon: scaled(*horizon),
        ground: scaled(*ground),
        occluded: *shadows,
        background: *background,
    })
}

fn lamp<T: Float>(l: &Light) -> Option<Lamp<T>> {
    Some(match l {
        Light::Point {
            position,
            color,
            intensity,
            radius,
            ..
        } => Lamp::Point {
            position: V3::from_f64(*position),
            color: V3::from_f64(*color) * T::from_f64(*intensity),
            radius: T::from_f64(*radius),
            sharpness: sharpness(l),
        },
        Light::Directional {
            direction,
            color,
            intensity,
            penumbra,
            ..
        } => Lamp::Directional {
            to_light: -V3::<T>::from_f64(*direction).normalize(),
            color: V3::from_f64(*color) * T::from_f64(*intensity),
            sharpness: sharpness(l),
            cos_disc: T::from_f64((penumbra * 0.5).cos()),
        },
        Light::Sky { .. } => return None,
    })
}

impl<T: Float> Sky<T> {
    /// Its radiance along `d`: `ground` below the horizon, else `horizon + (zenith −
    /// horizon)·d.y`.
    pub fn radiance(&self, d: V3<T>) -> V3<T> {
        if d.y >= T::zero() {
            self.horizon + (self.zenith - self.horizon) * d.y
        } else {
            self.ground
        }
    }

    /// Its irradiance over π on a surface whose normal's height is `y`:
    /// `c₀ + c₁·y + c₂·(3y² − 1)` (docs/rendering.md, "Sky light").
    pub fn irradiance_at(&self, y: T) -> V3<T> {
        let [c0, c1, c2] = self.irradiance;
        c0 + c1 * y + c2 * (T::from_f64(3.0) * y * y - T::one())
    }
}

impl<T: Float> Context<T> {
    /// The fog's colour along `d`: `fog_color`, or the background seen along `d`.
    pub fn fog_colour(&self, d: V3<T>) -> V3<T> {
        self.fog.unwrap_or_else(|| self.background(d))
    }

    /// The radiance of every sky along `d` (the path tracer's light from the skies, whether
    /// or not they are the background).
    pub fn sky_radiance(&self, d: V3<T>) -> V3<T> {
        self.skies
            .iter()
            .fold(V3::zero(), |sum, s| sum + s.radiance(d))
    }

    /// What a ray along `d` that hits nothing sees: the skies that are the background, or
    /// the background.
    pub fn background(&self, d: V3<T>) -> V3<T> {
        if !self.sky_background {
            return self.background;
        }
        self.skies
            .iter()
            .filter(|s| s.background)
            .fold(V3::zero(), |sum, s| sum + s.radiance(d))
    }
}
