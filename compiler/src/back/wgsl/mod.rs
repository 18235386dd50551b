//! The WGSL back end: the distance program written as `fn map` and `fn sdf`, joined to the
//! renderer kernel (`kernel.wgsl`) specialised to the scene, then parsed and validated by
//! naga. Also the bytes of the scene uniform the kernel reads.
//!
//! Entry: [`write`]. The kernel's bindings (group 0): 0 the scene uniform ([`uniforms`]),
//! 1 the tile (x0, y0, width, height as a uniform `vec4<u32>`), 2 the image (`vec4<f32>`
//! linear colour per pixel), 3 the statistics ([`STATS_WORDS`] `u32` per pixel), and, only in
//! the kernel of an analytically traced scene of more than [`MAX_UNROLLED`] primitives or of a
//! marched scene whose root union has more than [`MAX_INSTANCES`] instances, 4 the read-only
//! `scene_data` (`array<vec4<f32>>`, [`Kernel::data`]; layouts in buffer.rs and march.rs),
//! and 5 the finished pixels (`u32` per pixel: the colour clamped and sRGB-encoded to RGBA8,
//! [`srgb`], alpha 255, red in the low byte), which a host that has no use for the linear
//! colours reads back instead (a quarter of the bytes) and a viewer can draw from.

mod analytic;
mod buffer;
mod contract;
mod glyphs;
pub mod interp;
pub mod layout;
mod literal;
mod map;
mod march;
mod mesh;
pub mod part;
pub mod reduce;
mod refused;
pub mod srgb;
mod template;
mod uniform;

pub use analytic::MAX_UNROLLED;
pub use contract::{Contract, Field, Mismatch, Shape, Specialisation, Uniform, UniformWriter};
pub(crate) use literal::float;
pub use map::{write_map, write_sdf};
pub use refused::Refused;
pub use uniform::uniforms;

use crate::lower::Lowered;
use crate::scene::{Colour, Light, Pattern, Scene};
use std::collections::HashMap;
use std::fmt;

/// The kernel's entry point.
pub const ENTRY_POINT: &str = "main";
/// The workgroup is `WORKGROUP × WORKGROUP` invocations: a warp of 32 is a block of 8×4
/// pixels, and a small workgroup leaves its multiprocessor as soon as its own rays end.
/// Workgroups of 768–1 024 invocations would hold the Vulkan driver to 64–80 registers a
/// thread, which helps a kernel short of registers (temple) but makes the others wait in
/// the tails of workgroups for their slowest warp (measured).
pub const WORKGROUP: u32 = 8;
/// Statistics words per pixel: steps, hits, misses, budget misses, overshoots, NaNs,
/// secondary rays, shadow rays.
pub const STATS_WORDS: u32 = 9;

/// The kernel template: the renderer (kernel.wgsl) and its shading (shading.wgsl), one
/// module (WGSL declarations may come in any order).
const TEMPLATE: &str = concat!(
    include_str!("kernel.wgsl"),
    include_str!("shading.wgsl"),
    include_str!("path.wgsl")
);

/// The most instances (`lower::Lowered::instances`) of a marched scene's root union written as code: beyond,
/// they are read from `scene_data` and walked nearest first (march.rs). The code grows with
/// the scene, and so does the driver's compile (the CUDA JIT of a marched kernel of 10 000
/// spheres takes minutes); the walk's kernel is the same size for any number. The code is
/// faster at a hundred instances, the walk as fast or faster from a few hundred, and its
/// pipeline is created in milliseconds where the code's takes seconds: 256 lies between.
pub const MAX_INSTANCES: usize = 256;

/// A generated, validated kernel.
#[derive(Debug, Clone)]
pub struct Kernel {
    /// The WGSL text.
    pub source: String,
    /// naga's IR of it (input of the PTX and other shader back ends).
    pub module: naga::Module,
    /// naga's validation info.
    pub info: naga::valid::ModuleInfo,
    /// What it was specialised for (every feature, on or off, and the settings that
    /// decided them) and the layout of the uniform it reads, from `module`.
    pub contract: Contract,
    /// The bytes of binding 4, `scene_data`, when the kernel declares it (the `SCENE_DATA`
    /// feature): the primitives and hierarchy of a large analytically traced scene, or the
    /// instances and their hierarchy of a large marched one.
    pub data: Option<Vec<u8>>,
}

impl Kernel {
    /// Whether the kernel interprets its distance programs from `scene_data` (interp.rs).
    pub fn interpreted(&self) -> bool {
        self.contract.has("INTERPRETED")
    }
}

/// A generated kernel that naga rejected: always a compiler bug, reported with the generated
/// line and, where the line comes from the distance program, the scene node's span.
#[derive(Debug, Clone, PartialEq)]
pub struct Error {
    /// naga's message.
    pub message: String,
    /// The generated line, 1-based, and its text.
    pub line: Option<(usize, String)>,
    /// The span of the scene node the line was generated from.
    pub node_span: Option<crate::Span>,
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(
            f,
            "internal compiler error: the generated WGSL is invalid: {}",
            self.message
        )?;
        if let Some((n, text)) = &self.line {
            write!(f, "\n  at generated line {n}: {}", text.trim())?;
        }
        Ok(())
    }
}

impl std::error::Error for Error {}

impl Error {
    /// A kernel refused before it is written: the reason, with no line.
    fn refused(reason: impl fmt::Display) -> Error {
        Error {
            message: reason.to_string(),
            line: None,
            node_span: None,
        }
    }
}

/// What the scene uses, deciding which parts of the kernel are emitted; `traced` when it is
/// ray traced analytically.
pub(crate) fn features(scene: &Scene, traced: bool) -> Vec<(&'static str, bool)> {
    let mats = &scene.materials;
    // The path tracer's shadow rays are hard (it samples a light's disc instead), so its
    // kernel leaves the penumbra search out.
    let soft = !scene.settings.path
        && scene
            .lights
            .iter()
            .any(|l| l.penumbra() > 0.0 && l.shadows());
    let points = scene
        .lights
        .iter()
        .any(|l| matches!(l, Light::Point { .. }));
    let dirs = scene
        .lights
        .iter()
        .any(|l| matches!(l, Light::Directional { .. }));
    let refraction = mats.iter().any(|m| m.transparency > 0.0);
    // The path tracer continues every path (and refracts with the secondary rays' code).
    let path = scene.settings.path;
    let secondary = path
        || (scene.settings.max_depth > 0
            && mats.iter().any(|m| m.reflects() || m.transparency > 0.0));
    vec![
        ("ANALYTIC", traced),
        ("POINT", points),
        ("DIRECTIONAL", dirs),
        ("SOFT", soft),
        (
            "CHECKER",
            mats.iter().any(|m| {
                matches!(
                    m.pattern,
                    Pattern::Checker { .. } | Pattern::Materials { .. }
                )
            }),
        ),
        // A checker of two materials resolves a hit's material (`checkered`).
        (
            "MATERIAL_CHECKER",
            mats.iter()
                .any(|m| matches!(m.pattern, Pattern::Materials { .. })),
        ),
        // Shadow rays pass through transparent solids even when no refracted ray is traced
        // (`max_depth: 0`), as on the CPU; the path tracer's are stopped by every surface.
        ("TRANSPARENT", refraction && !path),
        ("REFRACTION", refraction && secondary),
        ("SECONDARY", secondary),
        ("MATERIALS", mats.len() > 1),
        ("RELAX", !traced && scene.settings.relaxation > 1.0),
        (
            "COLOUR_FIELDS",
            mats.iter().any(|m| {
                m.pattern
                    .colours()
                    .iter()
                    .any(|c| matches!(c, Colour::Field(_)))
            }),
        ),
        // The look (docs/rendering.md): occlusion samples the field, so a traced scene has none.
        ("OCCLUSION", !traced && scene.settings.occlusion > 0.0),
        (
            "SKY",
            scene.lights.iter().any(|l| matches!(l, Light::Sky { .. })),
        ),
        ("FOG", scene.settings.fog > 0.0),
        // A glow of the camera rays' marching steps (a marched scene's, never the path
        // tracer's).
        ("GLOW", scene.settings.glows()),
        // Schlick's Fresnel term on a material's rays (`fresnel: true`, or `pbr`), and the
        // physically based material (docs/rendering.md, "Physically based materials").
        ("FRESNEL", mats.iter().any(|m| m.fresnel)),
        ("PBR", mats.iter().any(|m| m.pbr.is_some())),
        (
            "GRADE",
            scene.settings.exposure != 0.0 || scene.settings.tonemap != crate::scene::Tonemap::None,
        ),
    ]
}

/// The number of the scene's lights of a kind: `kind` 0 point, 1 directional (suns too),
/// 2 sky.
fn count(scene: &Scene, kind: u32) -> usize {
    scene
        .lights
        .iter()
        .filter(|l| {
            kind == match l {
                Light::Point { .. } => 0,
                Light::Directional { .. } => 1,
                Light::Sky { .. } => 2,
            }
        })
        .count()
}

/// Choices of a kernel that do not come from the scene.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Options {
    /// Paint the pixels whose rays met a NaN magenta (`sdfc render --debug-nan`): the
    /// `DEBUG_NAN` feature. Off, the kernel is the same as without the option.
    pub debug_nan: bool,
    /// The most primitives of an analytically traced scene whose intersections are unrolled
    /// into the kernel; a larger scene is read from `scene_data` ([`MAX_UNROLLED`] unless a
    /// test or a measurement compares the two ways).
    pub max_unrolled: usize,
    /// The most instances of a marched scene's root union written as code; more are read
    /// from `scene_data` ([`MAX_INSTANCES`] unless a test compares the two ways).
    pub max_instances: usize,
    /// The constants of a marched scene's distance program read from `scene_data` instead
    /// of written as literals (the `PARAMS` feature; docs/animation.md): the kernel's text
    /// then depends on the program with its constants erased, so the frames of an animation
    /// that differ only in numbers share one kernel and differ in [`Kernel::data`]. Only the
    /// program written as code takes them: a marched scene whose instances are read from
    /// `scene_data` and the media of glass keep their literals; an analytically traced scene
    /// with parameters (`param`) walks its primitives in `scene_data`, whatever their count.
    pub parameters: bool,
    /// Which kernel a marched scene gets: its distance program written as code (the
    /// specialised kernel), or interpreted from `scene_data` (interp.rs), or the one of the two
    /// [`choose`] expects to be ready and render sooner.
    pub kernel: KernelChoice,
    /// Instructions the interpreted kernel runs an iteration of its loop: [`interp::UNROLL`]
    /// for a GPU, [`interp::UNROLL_SOFTWARE`] for a software adapter, whose loops share a
    /// budget of iterations.
    pub interp_unroll: usize,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            debug_nan: false,
            max_unrolled: MAX_UNROLLED,
            max_instances: MAX_INSTANCES,
            parameters: false,
            kernel: KernelChoice::Specialised,
            interp_unroll: interp::UNROLL,
        }
    }
}

/// The kernel asked for (`--kernel`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum KernelChoice {
    /// The interpreted kernel where the program written as code has at least
    /// [`interp::AUTO_INTERPRET`] live instructions and fits the interpreter, else the
    /// specialised one.
    #[default]
    Auto,
    /// The distance program written as code.
    Specialised,
    /// The distance program interpreted from `scene_data`: a kernel whose text does not
    /// depend on the program (marched scenes only).
    Interpreted,
}

/// The kernel a scene gets.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum KernelKind {
    /// The distance program written as code (or an analytically traced scene's kernel).
    Specialised,
    /// The distance program interpreted from `scene_data`.
    Interpreted,
}

/// The kernel `options.kernel` gives `scene`, lowered as `lowered`, or why it cannot render
/// it: the interpreted kernel asked for and unable to, or meshes over the `scene_data` limit.
pub fn choose(scene: &Scene, lowered: &Lowered, options: &Options) -> Result<KernelKind, Refused> {
    let primitives = lowered.traceable.traced(scene.settings.method);
    let traced = primitives.is_some();
    // The meshes' triangles are read from `scene_data`: a traced scene's own meshes
    // (analytic.rs), else those the programs name, by either kernel.
    let bytes = match primitives {
        Some(t) => mesh::data_len(t.meshes.iter().map(|m| &*m.0)),
        None => mesh::data_len(mesh_programs(scene, lowered).flat_map(|p| p.meshes())),
    };
    mesh::fits(scene, bytes)?;
    match options.kernel {
        KernelChoice::Specialised => Ok(KernelKind::Specialised),
        KernelChoice::Interpreted if traced => Err(Refused::InterpretedTraced),
        KernelChoice::Interpreted => interpreted(scene, lowered).map(|_| KernelKind::Interpreted),
        KernelChoice::Auto if traced => Ok(KernelKind::Specialised),
        KernelChoice::Auto => {
            let big = code_size(scene, lowered, options) >= interp::AUTO_INTERPRET;
            Ok(if big && interpreted(scene, lowered).is_ok() {
                KernelKind::Interpreted
            } else {
                KernelKind::Specialised
            })
        }
    }
}

/// The live instructions of a marched scene's distance program that its specialised kernel
/// writes as code: the whole program's, or, where its instances are read from `scene_data`,
/// those of the rest.
pub fn code_size(scene: &Scene, lowered: &Lowered, options: &Options) -> usize {
    let live = |p: &crate::program::Program| {
        let (live, _) = p.live(&[p.distance(), p.material()]);
        live.iter().filter(|&&l| l).count()
    };
    let whole = live(&lowered.program);
    if whole < interp::AUTO_INTERPRET {
        return whole;
    }
    match split(scene, lowered, options) {
        Some((s, _)) => live(&s.rest),
        None => whole,
    }
}

/// The media programs a marched scene's kernel needs: glass that may overlap solids, with
/// refracted rays traced.
fn media_of<'a>(scene: &Scene, lowered: &'a Lowered) -> Option<&'a crate::lower::Media> {
    let refraction = features(scene, false)
        .iter()
        .any(|&(n, on)| n == "REFRACTION" && on);
    lowered.media.as_ref().filter(|_| refraction)
}

/// The `scene_data` of the meshes a marched scene's [`mesh_programs`] name, if any (mesh.rs).
fn meshes_of(scene: &Scene, lowered: &Lowered) -> Option<Vec<u8>> {
    let programs = mesh_programs(scene, lowered);
    if !programs.clone().any(mesh::uses_meshes) {
        return None;
    }
    Some(mesh::data(programs))
}

/// The programs whose meshes a marched scene's kernel reads: the scene's and its media's.
fn mesh_programs<'a>(
    scene: &Scene,
    lowered: &'a Lowered,
) -> impl Iterator<Item = &'a crate::program::Program> + Clone {
    let media = media_of(scene, lowered);
    std::iter::once(&lowered.program)
        .chain(media.map(|m| &m.medium))
        .chain(media.map(|m| &m.solid))
}

/// The `scene_data` of the interpreted kernel for a marched scene, or why it cannot hold its
/// programs.
fn interpreted(scene: &Scene, lowered: &Lowered) -> Result<Vec<u8>, Refused> {
    use crate::limits::Limit;
    let media = media_of(scene, lowered);
    let programs = interp::Programs {
        main: &lowered.program,
        media: media.map(|m| (&m.medium, &m.solid)),
        colours: &lowered.colours.programs,
    };
    let file = scene.limits.count(Limit::Registers);
    let mib = scene.limits.get(Limit::SceneData);
    interp::encode(&programs, file, mib).map_err(|unfit| {
        let raise = match unfit {
            interp::Unfit::Registers(needed, _) => {
                Some(scene.limits.raise_to(Limit::Registers, needed as u64))
            }
            interp::Unfit::Bytes(bytes, _) => Some(
                scene
                    .limits
                    .raise_to(Limit::SceneData, bytes.div_ceil(1 << 20) as u64),
            ),
            interp::Unfit::Words(_) => None,
        };
        Refused::Interpreted { unfit, raise }
    })
}

/// Writes and validates the kernel for `scene`, lowered as `lowered`.
pub fn write(scene: &Scene, lowered: &Lowered) -> Result<Kernel, Error> {
    write_with(scene, lowered, &Options::default())
}

/// [`write`] with the given options.
pub fn write_with(scene: &Scene, lowered: &Lowered, options: &Options) -> Result<Kernel, Error> {
    write_from(TEMPLATE, scene, lowered, options)
}

/// [`write_with`] from the template `template` (a test changes it).
fn write_from(
    template: &str,
    scene: &Scene,
    lowered: &Lowered,
    options: &Options,
) -> Result<Kernel, Error> {
    let text = write_template(template, scene, lowered, options)?;
    let (module, info) = validate(&text.source, scene)?;
    let uniform = Uniform::of(&module).ok_or_else(|| Error {
        message: "the kernel has no scene uniform at binding 0".into(),
        line: None,
        node_span: None,
    })?;
    Ok(Kernel {
        source: text.source,
        module,
        info,
        contract: Contract {
            specialisation: Specialisation::of(&scene.settings),
            features: text.features,
            uniform,
        },
        data: text.data,
    })
}

/// A kernel's text and data before naga parses and validates it: what a caller holding a
/// kernel compares to decide whether it can keep it ([`Options::parameters`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Text {
    /// The WGSL text.
    pub source: String,
    /// Every feature of the template, on or off, by name ([`Contract::features`]).
    pub features: Vec<(&'static str, bool)>,
    /// The bytes of `scene_data`, when it has them.
    pub data: Option<Vec<u8>>,
}

/// The text of the kernel [`write_with`] writes, not validated.
pub fn write_text(scene: &Scene, lowered: &Lowered, options: &Options) -> Result<Text, Error> {
    write_template(TEMPLATE, scene, lowered, options)
}

/// [`write_text`] from the template `template` (a test changes it).
fn write_template(
    template: &str,
    scene: &Scene,
    lowered: &Lowered,
    options: &Options,
) -> Result<Text, Error> {
    let traced = lowered.traceable.traced(scene.settings.method);
    let mut features = features(scene, traced.is_some());
    debug_assert_eq!(features.len(), contract::SCENE_FEATURES);
    let mut on: HashMap<&str, bool> = features.iter().copied().collect();
    let mut values: HashMap<&str, String> = HashMap::new();
    let code = match traced {
        // An analytically traced scene needs no distance field.
        Some(traced) => analytic_map(scene, traced, options)?,
        None if choose(scene, lowered, options).map_err(Error::refused)?
            == KernelKind::Interpreted =>
        {
            interpreted_map(scene, lowered, options)?
        }
        None => marched_map(scene, lowered, options, on["REFRACTION"]),
    };
    values.insert("MAP", code.text);
    if let Some(text) = code.analytic {
        values.insert("ANALYTIC", text);
    }
    if on["COLOUR_FIELDS"] {
        let colours = &lowered.colours.programs;
        let text = if code.interprets {
            interp::write_colours()
        } else {
            map::write_colours(colours, "")
        };
        values.insert("COLOURS", text);
    }
    // The kernel's own features, after the scene's; the header lists them only when on, so
    // that the kernels without them do not change.
    features.extend([
        ("DEBUG_NAN", options.debug_nan),
        ("PARAMS", code.params),
        ("MEDIA", code.media),
        ("SCENE_DATA", code.data.is_some()),
        ("INTERPRETED", code.interprets),
        ("PATH", scene.settings.path),
    ]);
    on.extend(features[contract::SCENE_FEATURES..].iter().copied());
    values.insert("HEADER", header(&features));
    insert_constants(&mut values, scene);
    let source = template::expand(template, &on, &values).map_err(|e| Error {
        message: format!("kernel template: {e}"),
        line: None,
        node_span: None,
    })?;
    Ok(Text {
        source,
        features,
        data: code.data,
    })
}

/// The scene's distance code of a kernel (its `MAP`), with the bytes of its `scene_data` and
/// the kernel's features it decides.
struct MapText {
    text: String,
    /// The closed-form trace of an analytically traced scene (`ANALYTIC`).
    analytic: Option<String>,
    data: Option<Vec<u8>>,
    /// Whether the program reads its constants from `scene_data` (`PARAMS`).
    params: bool,
    /// Whether rays inside glass march the scene's media (`MEDIA`).
    media: bool,
    /// Whether the distance programs are interpreted (`INTERPRETED`).
    interprets: bool,
}

/// The `MAP` of an analytically traced scene: no distance field, the primitives traced in
/// closed form (from `scene_data` past the unrolled ones, or all of them for a scene whose
/// parameters the kernel reads).
fn analytic_map(
    scene: &Scene,
    traced: &crate::scene::analytic::Traced,
    options: &Options,
) -> Result<MapText, Error> {
    let clear = |m| scene.material(m).transparency > 0.0;
    // A scene with parameters, asked for a kernel whose text does not depend on its
    // numbers (the viewer's panel), walks its primitives in `scene_data`: a changed
    // size or place is new data for the same kernel, not a new kernel.
    let unrolled = match options.parameters && !scene.params.is_empty() {
        true => 0,
        false => options.max_unrolled,
    };
    let (text, bytes) = analytic::write(traced, &clear, unrolled);
    // A mesh's triangles, read from `scene_data` as a marched scene's are.
    if let Some(bytes) = bytes.as_ref().filter(|_| !traced.meshes.is_empty()) {
        mesh::fits(scene, bytes.len() as u64).map_err(Error::refused)?;
    }
    Ok(MapText {
        text: String::new(),
        analytic: Some(text),
        data: bytes,
        params: false,
        media: false,
        interprets: false,
    })
}

/// The `MAP` of a scene whose distance programs the kernel interprets from `scene_data`: the
/// text depends only on the features and the register file's size.
fn interpreted_map(scene: &Scene, lowered: &Lowered, options: &Options) -> Result<MapText, Error> {
    let bytes = interpreted(scene, lowered).map_err(Error::refused)?;
    let media = media_of(scene, lowered).is_some();
    let file = scene.limits.count(crate::limits::Limit::Registers);
    let m = media_of(scene, lowered);
    let calls = interp::Programs {
        main: &lowered.program,
        media: m.map(|m| (&m.medium, &m.solid)),
        colours: &lowered.colours.programs,
    }
    .calls();
    Ok(MapText {
        text: interp::write(file, media, options.interp_unroll, calls),
        analytic: None,
        data: Some(bytes),
        params: false,
        media,
        interprets: true,
    })
}

/// The `MAP` of a marched scene: its program as code (with the meshes' walk, or its
/// instances or constants in `scene_data`: [`marched`]), then, with `refraction`, the
/// media's programs, then the text's outlines.
fn marched_map(scene: &Scene, lowered: &Lowered, options: &Options, refraction: bool) -> MapText {
    let meshes = meshes_of(scene, lowered);
    let (mut text, bytes, params) = match meshes {
        // The program as code, its constants as literals, the meshes' walk after it.
        Some(data) => (
            format!(
                "{}\n{}\n{}",
                write_map(&lowered.program),
                write_sdf(&lowered.program),
                mesh::write()
            ),
            Some(data),
            false,
        ),
        None => marched(scene, lowered, options),
    };
    // Rays inside glass that may overlap a solid march the scene's media.
    let m = lowered.media.as_ref().filter(|_| refraction);
    if let Some(m) = m {
        text.push('\n');
        text.push_str(&map::write_sdf_named(&m.medium, "sdf_medium"));
        text.push('\n');
        text.push_str(&map::write_map_named(&m.solid, "map_solid"));
        text.push('\n');
        text.push_str(&map::write_sdf_named(&m.solid, "sdf_solid"));
    }
    // Text: its outlines after the rest of scene_data.
    let mut bytes = bytes;
    let mut programs = vec![&lowered.program];
    if let Some(m) = m {
        programs.extend([&m.medium, &m.solid]);
    }
    let glyphs = glyphs::append(&programs, &mut bytes);
    if !glyphs.is_empty() {
        text.push('\n');
        text.push_str(&glyphs);
    }
    MapText {
        text,
        analytic: None,
        data: bytes,
        params,
        media: m.is_some(),
        interprets: false,
    }
}

/// The kernel's first lines: what generated it, and its features (the scene's, on or off,
/// then the kernel's own that are on).
fn header(features: &[(&str, bool)]) -> String {
    let used: Vec<String> = features
        .iter()
        .enumerate()
        .filter(|&(k, &(_, on))| k < contract::SCENE_FEATURES || on)
        .map(|(_, (n, on))| format!("{}{n}", if *on { "+" } else { "-" }))
        .collect();
    format!(
        "// Generated by sdfc: the renderer kernel of docs/rendering.md specialised for one scene.\n// Features: {}.",
        used.join(" ")
    )
}

/// The template's numbers: the scene's counts, and the constants of the look, the
/// physically based materials and the path tracer's sampling, as WGSL literals.
fn insert_constants(values: &mut HashMap<&str, String>, scene: &Scene) {
    values.insert("POINTS", count(scene, 0).to_string());
    values.insert("DIRS", count(scene, 1).to_string());
    values.insert("SKIES", count(scene, 2).to_string());
    values.insert("MATERIALS", scene.materials.len().max(1).to_string());
    values.insert("STACK", (scene.settings.max_depth + 2).to_string());
    values.insert("PENUMBRA_BRACKET", float(Light::PENUMBRA_BRACKET));
    values.insert("PENUMBRA_PROBES", format!("{}u", Light::PENUMBRA_PROBES));
    values.insert("WORKGROUP", WORKGROUP.to_string());
    {
        use crate::scene::look;
        values.insert("FOOTPRINT_MIN", float(look::FOOTPRINT_MIN));
        values.insert("FOOTPRINT_COS", float(look::FOOTPRINT_COS));
        values.insert("OCCLUSION_SAMPLES", format!("{}u", look::OCCLUSION_SAMPLES));
        values.insert("OCCLUSION_STRENGTH", float(look::OCCLUSION_STRENGTH));
        for (k, c) in ["FILMIC_A", "FILMIC_B", "FILMIC_C", "FILMIC_D", "FILMIC_E"]
            .into_iter()
            .zip(look::FILMIC)
        {
            values.insert(k, float(c));
        }
    }
    {
        use crate::scene::pbr;
        let v4 = |c: [f64; 4]| c.map(float).join(", ");
        values.insert("NV_MIN", float(pbr::NV_MIN));
        values.insert("ENV_C0", v4(pbr::ENV_C0));
        values.insert("ENV_C1", v4(pbr::ENV_C1));
        values.insert("ENV_EXP", float(pbr::ENV_EXP));
        values.insert("PI", float(std::f64::consts::PI));
    }
    {
        use crate::scene::sampling::{self, dim};
        values.insert("INV_PI", float(std::f64::consts::FRAC_1_PI));
        values.insert("UNIT", float(sampling::UNIT));
        values.insert("ROULETTE_DEPTH", format!("{}u", sampling::ROULETTE_DEPTH));
        values.insert("ROULETTE_MAX", float(sampling::ROULETTE_MAX));
        values.insert("DIM_LOBE", format!("{}u", dim::LOBE));
        values.insert("DIM_DIRECTION", format!("{}u", dim::DIRECTION[0]));
        values.insert("DIM_SKY", format!("{}u", dim::SKY[0]));
        values.insert("DIM_ROULETTE", format!("{}u", dim::ROULETTE));
        values.insert("DIM_LAMPS", format!("{}u", dim::LAMPS));
    }
    values.insert("ENTRY", ENTRY_POINT.to_string());
}

/// `fn map` and `fn sdf` of a marched scene: the program as code, or, when its root union has
/// more than `max_instances` instances, the rest of it as code and the instances as
/// `scene_data` (march.rs), unless their materials or their bytes do not fit. The program as
/// code reads its constants from `scene_data` with [`Options::parameters`] (then the last
/// value is true).
fn marched(scene: &Scene, lowered: &Lowered, options: &Options) -> (String, Option<Vec<u8>>, bool) {
    let program = &lowered.program;
    match split(scene, lowered, options) {
        Some((s, data)) => {
            let text = format!(
                "{}\n{}\n{}",
                map::write_map_named(&s.rest, "rest_map"),
                map::write_sdf_named(&s.rest, "rest_sdf"),
                march::write(&s.instances, data.stack)
            );
            (text, Some(data.bytes), false)
        }
        None if options.parameters => {
            let params = map::Params::default();
            let text = format!(
                "{}\n{}",
                map::write_map_with(program, "map", Some(&params)),
                map::write_sdf_with(program, "sdf", Some(&params))
            );
            (text, Some(params.bytes()), true)
        }
        None => (
            format!("{}\n{}", write_map(program), write_sdf(program)),
            None,
            false,
        ),
    }
}

/// The distance program cut into the rest and the instances read from `scene_data`, with
/// their bytes, where the root union has more than `max_instances` instances and they fit
/// ([`marched`]).
fn split(
    scene: &Scene,
    lowered: &Lowered,
    options: &Options,
) -> Option<(crate::lower::Split, march::Data)> {
    lowered
        .instances(options.max_instances)
        .filter(|s| march::fits(&s.instances))
        .map(|s| {
            let data = march::data(&s.instances);
            (s, data)
        })
        // The `scene_data` limit, in MiB: by default what wgpu's default limits let a
        // storage buffer bind; a scene with more keeps its instances as code.
        .filter(|(_, data)| {
            let mib = scene.limits.get(crate::limits::Limit::SceneData);
            data.bytes.len() as u64 <= mib.saturating_mul(1 << 20)
        })
}

/// Parses and validates WGSL with naga.
fn validate(source: &str, scene: &Scene) -> Result<(naga::Module, naga::valid::ModuleInfo), Error> {
    let located = |message: String, span: Option<naga::Span>| {
        let line = span
            .map(|s| s.location(source).line_number as usize)
            .filter(|&n| n > 0);
        let line = line.map(|n| (n, source.lines().nth(n - 1).unwrap_or("").to_string()));
        let node_span = line
            .as_ref()
            .and_then(|(n, _)| node_of_line(source, *n, scene));
        Error {
            message,
            line,
            node_span,
        }
    };
    let module = naga::front::wgsl::parse_str(source)
        .map_err(|e| located(e.emit_to_string(source), e.labels().next().map(|(s, _)| s)))?;
    let info = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::empty(),
    )
    .validate(&module)
    .map_err(|e| located(e.emit_to_string(source), e.spans().next().map(|(s, _)| *s)))?;
    Ok((module, info))
}

/// The scene node whose comment (`// node N ...`) precedes generated line `n`.
fn node_of_line(source: &str, n: usize, scene: &Scene) -> Option<crate::Span> {
    let comment = source
        .lines()
        .take(n)
        .collect::<Vec<_>>()
        .into_iter()
        .rev()
        .find_map(|l| l.trim().strip_prefix("// node "))?;
    let id: u32 = comment.split_whitespace().next()?.parse().ok()?;
    (id < scene.graph.len() as u32).then(|| scene.graph.span(crate::scene::NodeId(id)))
}

#[cfg(test)]
mod tests;
