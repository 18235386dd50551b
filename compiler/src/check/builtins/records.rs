//! The schemas of the records: material kinds, light kinds, `camera` and `render` (their
//! fields, defaults, ranges and help).

use super::*;

/// The schema of a record: a material kind, a light kind, `camera` or `render`.
#[derive(Debug)]
pub struct Record {
    pub name: &'static str,
    pub fields: &'static [P],
    /// Fields whose value must not depend on the time `t` (E0406): what every frame of a
    /// sequence shares.
    pub timeless: &'static [&'static str],
    /// Fields that take a colour field (`field { … }` of a vec3) as well as a vec3.
    pub painted: &'static [&'static str],
    /// The help of a field's E0400 (its value out of range): how to give a valid one.
    pub help: &'static [(&'static str, &'static str)],
}

const SURFACE: [P; 9] = [
    p("ambient", F, Num(Material::AMBIENT), Unit),
    p("diffuse", F, Num(Material::DIFFUSE), NonNeg),
    p("specular", F, Num(Material::SPECULAR), NonNeg),
    p(
        "shininess",
        F,
        Num(Material::SHININESS),
        Within(1.0, 10000.0),
    ),
    p("reflect", F, Num(Material::REFLECT), Unit),
    p("transparency", F, Num(Material::TRANSPARENCY), Unit),
    p("ior", F, Num(Material::IOR), Within(1.0, 10.0)),
    p("color", V, V3(Material::COLOR), NonNeg),
    // Schlick's Fresnel term on the reflected and refracted rays (docs/rendering.md,
    // "Secondary rays"): off, so that the scenes written before it keep their look.
    p("fresnel", B, Bool(false), Any),
];

const fn concat<const N: usize, const M: usize, const T: usize>(a: [P; N], b: [P; M]) -> [P; T] {
    let mut out = [p("", F, Req, Any); T];
    let mut i = 0;
    while i < N {
        out[i] = a[i];
        i += 1;
    }
    while i < T {
        out[i] = b[i - N];
        i += 1;
    }
    out
}

const CHECKER: [P; 11] = concat(
    [
        SURFACE[0], SURFACE[1], SURFACE[2], SURFACE[3], SURFACE[4], SURFACE[5], SURFACE[6],
        SURFACE[8],
    ],
    [
        p("a", V, V3([0.9, 0.9, 0.9]), NonNeg),
        p("b", V, V3([0.1, 0.1, 0.1]), NonNeg),
        p("size", F, Num(1.0), Pos),
    ],
);

/// `pbr`: the physically based material (docs/rendering.md, "Physically based materials").
const PBR: [P; 6] = [
    p("base_color", V, V3(Material::COLOR), NonNeg),
    p("roughness", F, Num(Pbr::ROUGHNESS), Unit),
    p("metallic", F, Num(Pbr::METALLIC), Unit),
    p("emission", V, V3([0.0; 3]), NonNeg),
    p("transmission", F, Num(Pbr::TRANSMISSION), Unit),
    SURFACE[6],
];

/// Material kinds.
pub static MATERIALS: &[Record] = &[
    Record {
        name: "phong",
        timeless: &[],
        painted: &["color"],
        help: &[],
        fields: &SURFACE,
    },
    Record {
        name: "checker",
        timeless: &[],
        painted: &["a", "b"],
        help: &[],
        fields: &CHECKER,
    },
    Record {
        name: "pbr",
        timeless: &[],
        painted: &["base_color"],
        help: &[
            ("roughness", "write a roughness from 0 (a mirror) to 1 (fully rough): `roughness: 0.5`"),
            ("metallic", "write a metallic from 0 (plastic, stone, glass) to 1 (a metal): `metallic: 1`"),
            ("transmission", "write a transmission from 0 (opaque) to 1 (clear glass): `transmission: 1`"),
            ("ior", "write an index of refraction from 1 to 10 (air 1, water 1.33, glass 1.5, diamond 2.42): `ior: 1.5`"),
        ],
        fields: &PBR,
    },
];

const LIGHT_COMMON: [P; 5] = [
    p("color", V, V3([1.0, 1.0, 1.0]), NonNeg),
    p("intensity", F, Num(1.0), NonNeg),
    p(
        "penumbra",
        A,
        Deg(0.0),
        Within(0.0, 89.0 * std::f64::consts::PI / 180.0),
    ),
    // The sharpness k = 1/tan(penumbra) of the old files; W0012 says what to write instead.
    p("softness", F, Num(0.0), NonNeg),
    p("shadows", B, Bool(true), Any),
];

const POINT: [P; 7] = concat(
    [p("position", V, Req, Any), p("radius", F, Num(100.0), Pos)],
    LIGHT_COMMON,
);
const DIRECTIONAL: [P; 6] = concat([p("direction", V, Req, NonZero)], LIGHT_COMMON);

/// `light sun`: a directional light whose shadows soften over its angular size.
const SUN: [P; 5] = [
    p("direction", V, Req, NonZero),
    LIGHT_COMMON[0],
    LIGHT_COMMON[1],
    p(
        "angle",
        A,
        Deg(0.53),
        Within(0.0, 89.0 * std::f64::consts::PI / 180.0),
    ),
    LIGHT_COMMON[4],
];

/// `light sky`: light from the whole sky, a gradient or one colour.
const SKY: [P; 7] = [
    p("color", V, V3([1.0, 1.0, 1.0]), NonNeg),
    p("zenith", V, V3(crate::scene::look::SKY_ZENITH), NonNeg),
    p("horizon", V, V3(crate::scene::look::SKY_HORIZON), NonNeg),
    p("ground", V, V3(crate::scene::look::SKY_GROUND), NonNeg),
    LIGHT_COMMON[1],
    LIGHT_COMMON[4],
    p("background", B, Bool(true), Any),
];

/// Light kinds.
pub static LIGHTS: &[Record] = &[
    Record {
        name: "point",
        timeless: &[],
        painted: &[],
        help: &[],
        fields: &POINT,
    },
    Record {
        name: "directional",
        timeless: &[],
        painted: &[],
        help: &[],
        fields: &DIRECTIONAL,
    },
    Record {
        name: "sun",
        timeless: &[],
        painted: &[],
        help: &[],
        fields: &SUN,
    },
    Record {
        name: "sky",
        timeless: &[],
        painted: &[],
        help: &[],
        fields: &SKY,
    },
];

/// `camera { ... }`
pub static CAMERA: Record = Record {
    name: "camera",
    timeless: &[],
    painted: &[],
    help: &[],
    fields: &[
        p("position", V, V3(Camera::DEFAULT.position), Any),
        p("look_at", V, V3(Camera::DEFAULT.look_at), Any),
        p("up", V, V3(Camera::DEFAULT.up), NonZero),
        p(
            "fov",
            A,
            Deg(Camera::FOV_DEGREES),
            Within(
                0.1f64 * std::f64::consts::PI / 180.0,
                179.0 * std::f64::consts::PI / 180.0,
            ),
        ),
    ],
};

/// The defaults of `render`'s fields.
const DEFAULT: Settings = Settings::DEFAULT;

/// An integer setting of default `def`, from `lo` up to the limit `limit`.
const fn limited(name: &'static str, def: i64, lo: f64, limit: Limit) -> P {
    p(name, I, Int(def), Limited(lo, limit))
}

/// `render { ... }`; the same keys are accepted by `sdfc render --set`.
pub static RENDER: Record = Record {
    name: "render",
    // The sequence's frames and their size: an animated PNG or a video has one size.
    timeless: &["width", "height", "fps", "duration"],
    painted: &[],
    help: &[],
    fields: &[
        limited("width", DEFAULT.width as i64, 1.0, Limit::Edge),
        limited("height", DEFAULT.height as i64, 1.0, Limit::Edge),
        limited("aa", DEFAULT.aa as i64, 1.0, Limit::Aa),
        limited("max_steps", DEFAULT.max_steps as i64, 1.0, Limit::MaxSteps),
        p("epsilon", F, Num(DEFAULT.epsilon), Within(1e-9, 0.5)),
        limited("max_depth", DEFAULT.max_depth as i64, 0.0, Limit::MaxDepth),
        p("max_dist", F, Num(DEFAULT.max_dist), Within(1e-6, 1e9)),
        p("relaxation", F, Num(DEFAULT.relaxation), Within(1.0, 1.99)),
        p("background", V, V3(DEFAULT.background), NonNeg),
        p(
            "method",
            Str,
            Text(DEFAULT.method.name()),
            OneOf(Settings::METHODS),
        ),
        limited("samples", DEFAULT.samples as i64, 1.0, Limit::Samples),
        limited("bounces", DEFAULT.bounces as i64, 0.0, Limit::Bounces),
        p("fps", F, Num(30.0), Within(0.01, 1000.0)),
        p("duration", F, Num(0.0), Within(0.0, 1e7)),
        p("occlusion", F, Num(DEFAULT.occlusion), Within(0.0, 1e9)),
        p("fog", F, Num(DEFAULT.fog), Within(0.0, 1e9)),
        p("fog_color", V, V3(DEFAULT.background), NonNeg),
        p("glow", F, Num(DEFAULT.glow), Within(0.0, 1e9)),
        p("glow_color", V, V3(DEFAULT.glow_color), NonNeg),
        p("exposure", F, Num(DEFAULT.exposure), Within(-20.0, 20.0)),
        p(
            "tonemap",
            Str,
            Text(DEFAULT.tonemap.name()),
            OneOf(crate::scene::Tonemap::NAMES),
        ),
    ],
};
