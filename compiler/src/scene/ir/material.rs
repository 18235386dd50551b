//! Materials: their colours (constant or a field), patterns and surface parameters.

use super::{MaterialId, V3};

/// One colour of a material: a constant, or a colour field (`field { … }` whose body is a
/// vec3 of the point `p`, docs/language.md "Colour fields"), evaluated at the hit point in
/// the scene's coordinates (the world's, before [`Scene::origin`] moved them).
#[derive(Debug, Clone, PartialEq)]
pub enum Colour {
    /// The same colour everywhere.
    Const(V3),
    /// Red, green and blue as the three values of a field's expression; components below 0
    /// are taken as 0.
    Field(crate::scene::field::FieldFn),
}

impl Colour {
    /// The constant colour, or `None` for a field.
    pub fn constant(&self) -> Option<V3> {
        match self {
            Colour::Const(c) => Some(*c),
            Colour::Field(_) => None,
        }
    }
}

impl From<V3> for Colour {
    fn from(c: V3) -> Colour {
        Colour::Const(c)
    }
}

/// The colour of a material at a point.
#[derive(Debug, Clone, PartialEq)]
pub enum Pattern {
    /// One colour (or colour field).
    Solid(Colour),
    /// A 3D checkerboard of two colours (or colour fields) with cubes of edge `size`.
    Checker { a: Colour, b: Colour, size: f64 },
    /// A 3D checkerboard of two materials (`checker { a: gold, b: rubber }`), in cubes of edge
    /// `size` laid out as [`Pattern::Checker`]'s: each cell shades as its material, blended
    /// over a sample's footprint (docs/rendering.md, "The checker's footprint"). The two are
    /// opaque, of one model (both Phong or both `pbr`), and neither is such a checker itself
    /// (the checker refuses the others); the material holding this pattern has no other use.
    Materials {
        a: MaterialId,
        b: MaterialId,
        size: f64,
    },
}

impl Pattern {
    /// The pattern's colours: one, or the checker's two.
    pub fn colours(&self) -> Vec<&Colour> {
        match self {
            Pattern::Solid(c) => vec![c],
            Pattern::Checker { a, b, .. } => vec![a, b],
            // Its cells' colours are its materials'.
            Pattern::Materials { .. } => Vec::new(),
        }
    }
}

/// A material (docs/rendering.md, "At a hit"): Phong, or physically based where `pbr` is
/// given (its Phong fields then hold the nearest Phong material, for the material tables of
/// `--part map` and the Shadertoy page).
#[derive(Debug, Clone, PartialEq)]
pub struct Material {
    /// The name it was declared with.
    pub name: String,
    /// Colour or pattern.
    pub pattern: Pattern,
    /// k_a
    pub ambient: f64,
    /// k_d
    pub diffuse: f64,
    /// k_s
    pub specular: f64,
    /// α
    pub shininess: f64,
    /// Weight of the reflected ray, in [0, 1].
    pub reflect: f64,
    /// Weight of the transmitted ray, in [0, 1]; reflect + transparency ≤ 1.
    pub transparency: f64,
    /// Index of refraction, ≥ 1.
    pub ior: f64,
    /// Schlick's Fresnel term on the reflected and refracted rays (`fresnel: true`; always
    /// on for `pbr`).
    pub fresnel: bool,
    /// The physically based model's parameters (`pbr { … }`), or `None` for Phong.
    pub pbr: Option<crate::scene::Pbr>,
    /// The maps from the world to the coordinates its colour fields are evaluated in, the
    /// outermost first (`scene/frame.rs`): none for a material applied in the world's.
    pub frame: Vec<crate::scene::frame::Frame>,
}

impl Material {
    // The default of each field of a material (`phong`'s and `checker`'s, check/builtins.rs
    // reads them here), and the default material's.
    /// The default colour.
    pub const COLOR: V3 = [0.8, 0.8, 0.8];
    /// The default k_a.
    pub const AMBIENT: f64 = 0.1;
    /// The default k_d.
    pub const DIFFUSE: f64 = 0.9;
    /// The default k_s.
    pub const SPECULAR: f64 = 0.3;
    /// The default α.
    pub const SHININESS: f64 = 32.0;
    /// The default weight of the reflected ray.
    pub const REFLECT: f64 = 0.0;
    /// The default weight of the transmitted ray.
    pub const TRANSPARENCY: f64 = 0.0;
    /// The default index of refraction.
    pub const IOR: f64 = 1.5;

    /// Whether a hit on it may spawn a reflected ray: `reflect` > 0, a `pbr` material
    /// that is not fully rough (its mirror weight `(1 − roughness)²` > 0), or a Phong
    /// material with Fresnel (which reflects at grazing incidence).
    pub fn reflects(&self) -> bool {
        match self.pbr {
            Some(p) => p.mirror() > 0.0,
            None => self.reflect > 0.0 || self.fresnel,
        }
    }

    /// The material of shapes that were not painted.
    pub fn default_material() -> Self {
        Material {
            name: "default".into(),
            pattern: Pattern::Solid(Colour::Const(Material::COLOR)),
            ambient: Material::AMBIENT,
            diffuse: Material::DIFFUSE,
            specular: Material::SPECULAR,
            shininess: Material::SHININESS,
            reflect: Material::REFLECT,
            transparency: Material::TRANSPARENCY,
            ior: Material::IOR,
            fresnel: false,
            pbr: None,
            frame: Vec::new(),
        }
    }
}
