//! Resource limits: every bound that keeps a compilation or a render finite, with its
//! default, the name `--limit NAME=VALUE` sets it by, and what it bounds.
//!
//! The checker reads the compilation limits from the [`Limits`] it is given
//! (`check::check_with`); the render limits are checked by the checker (the `render` block)
//! and by the runtime (`--set`, the program size, the render's memory). A diagnostic or error
//! for an exceeded limit names the flag that raises it ([`Limits::raise`]), or the parameter,
//! for a caller that spells its options as the Python package does ([`Spelling`]).

use std::fmt;

/// One resource limit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Limit {
    /// Levels of expression nesting evaluated.
    Nesting,
    /// Evaluation steps (expressions and loop iterations) of one compilation.
    Fuel,
    /// Depth of nested calls of user functions.
    CallDepth,
    /// Shape nodes a scene may build.
    Nodes,
    /// Objects a `scene` block may add, and iterations of one loop.
    Objects,
    /// Files one compilation may import, in all.
    Files,
    /// Width and height of an image, in pixels.
    Edge,
    /// Supersampling: samples per pixel edge.
    Aa,
    /// The render setting `max_steps`.
    MaxSteps,
    /// The render setting `max_depth`.
    MaxDepth,
    /// The path tracer's samples per pixel (the render setting `samples`).
    Samples,
    /// The path tracer's bounces (the render setting `bounces`).
    Bounces,
    /// Operations of the distance program after lowering.
    Program,
    /// Memory a render may allocate, in MiB.
    Memory,
    /// Shape nodes of the scene counted as a tree: a shared sub-shape once per use, as the
    /// passes that walk the scene (method choice, simplification, lowering) visit it.
    Expansion,
    /// Primitives `method: "auto"` traces analytically (more are sphere traced).
    Traced,
    /// Bytes of a marched scene's instance data in one GPU buffer, in MiB (more keep their
    /// instances as code).
    SceneData,
    /// Values of one `sdfc pareto --sweep`.
    SweepValues,
    /// Settings `sdfc pareto` measures: the product of its sweeps' value counts.
    SweepPoints,
    /// Frames of one animated sequence (`render { fps, duration }`, `sdfc render --frames`).
    Frames,
    /// Cells `sdfc mesh` evaluates: the octree's cells at every level (or the dense grid's).
    Cells,
    /// Registers of the interpreted GPU kernel's file (programs that need more take the
    /// specialised kernel).
    Registers,
    /// Triangles of the meshes one scene reads (`mesh(path)`), in all.
    Triangles,
    /// Bytes of one file read (a scene, an import, a mesh, a font), in MiB.
    FileSize,
    /// Worker threads `--threads` may start.
    Threads,
    /// Characters of the text one scene lays out (`text`), in all.
    TextChars,
    /// Balls and cylinders one `hull(shapes…)` takes.
    HullShapes,
}

/// What a limit is: its name, default, accepted values and a one-line description.
struct Spec {
    /// The limit the row is of.
    limit: Limit,
    name: &'static str,
    default: u64,
    /// The largest value `--limit` accepts (beyond it the implementation's own bounds, such
    /// as 32-bit pixel indices, would break).
    ceiling: u64,
    what: &'static str,
}

/// Every limit's [`Spec`], in the order of [`Limit::ALL`] (checked when compiled, below).
const SPECS: [Spec; 27] = [
    Spec {
        limit: Limit::Nesting,
        name: "nesting",
        default: 1_000,
        ceiling: 100_000,
        what: "levels of expression nesting",
    },
    Spec {
        limit: Limit::Fuel,
        name: "fuel",
        default: 50_000_000,
        ceiling: 1 << 50,
        what: "evaluation steps (expressions and loop iterations) of one compilation",
    },
    Spec {
        limit: Limit::CallDepth,
        name: "call_depth",
        default: 256,
        ceiling: 1_000_000,
        what: "depth of nested calls of functions",
    },
    Spec {
        limit: Limit::Nodes,
        name: "nodes",
        default: 1_000_000,
        ceiling: u32::MAX as u64 - 1,
        what: "shape nodes a scene builds",
    },
    Spec {
        limit: Limit::Objects,
        name: "objects",
        default: 100_000,
        ceiling: u32::MAX as u64 - 1,
        what: "objects in a scene, and iterations of one loop",
    },
    Spec {
        limit: Limit::Files,
        name: "files",
        default: 256,
        ceiling: 1_000_000,
        what: "files imported by one compilation",
    },
    Spec {
        limit: Limit::Edge,
        name: "edge",
        default: 16_384,
        ceiling: 65_535,
        what: "width and height of an image, in pixels",
    },
    Spec {
        limit: Limit::Aa,
        name: "aa",
        default: 16,
        ceiling: 256,
        what: "supersampling (samples per pixel edge)",
    },
    Spec {
        limit: Limit::MaxSteps,
        name: "max_steps",
        default: 1_000_000,
        ceiling: u32::MAX as u64 - 1,
        what: "the render setting max_steps",
    },
    Spec {
        limit: Limit::MaxDepth,
        name: "max_depth",
        default: 64,
        ceiling: 1_000,
        what: "the render setting max_depth",
    },
    // A sample is one path a pixel: 65 536 of them at 1920×1080 are 1.4·10¹¹ paths,
    // hours on any device; the ceiling keeps sample indices within the random
    // stream's 32 bits.
    Spec {
        limit: Limit::Samples,
        name: "samples",
        default: 65_536,
        ceiling: 1 << 31,
        what: "the path tracer's samples per pixel (render setting samples)",
    },
    Spec {
        limit: Limit::Bounces,
        name: "bounces",
        default: 64,
        ceiling: 1_000,
        what: "the path tracer's bounces (render setting bounces)",
    },
    Spec {
        limit: Limit::Program,
        name: "program",
        default: 4_000_000,
        ceiling: u32::MAX as u64 - 1,
        what: "operations of the distance program after lowering",
    },
    Spec {
        limit: Limit::Memory,
        name: "memory",
        default: 4_096,
        ceiling: 1 << 30,
        what: "memory a render may allocate, in MiB (host and device together)",
    },
    // 4 000 000 holds 2¹⁹ spheres built by sharing, two translated copies per level
    // (2²¹ − 3 nodes as a tree, checked in about a second);
    // every example is far below it (the largest, examples/scaling/compound_10000.sdf,
    // expands to 120 003).
    Spec {
        limit: Limit::Expansion,
        name: "expansion",
        default: 4_000_000,
        ceiling: 1 << 40,
        what: "shape nodes counted as a tree (a shared shape once per use)",
    },
    // Rays visit the primitives through a bounding-volume hierarchy, in O(log n) per
    // ray, so tracing beats sphere tracing at any size. The default
    // keeps the GPU buffer of a large traced scene (at most 112 bytes a primitive:
    // 80 for a rotated one, 32 for a group, of which there are fewer than primitives)
    // under the 128 MiB that wgpu's default limits let a storage buffer bind; the
    // default `objects` limit stays below it. `method: "trace"` has no limit.
    Spec {
        limit: Limit::Traced,
        name: "traced",
        default: 1_000_000,
        ceiling: u32::MAX as u64 - 1,
        what: "primitives method \"auto\" traces analytically (beyond, it sphere traces)",
    },
    // What wgpu's default limits let a storage buffer bind (128 MiB: over a million
    // instances, ten times the default `objects` limit).
    Spec {
        limit: Limit::SceneData,
        name: "scene_data",
        default: 128,
        ceiling: 4_095,
        what: "MiB of a marched scene's instances in one GPU buffer (beyond, they are code)",
    },
    Spec {
        limit: Limit::SweepValues,
        name: "sweep_values",
        default: 1_000,
        ceiling: 1_000_000,
        what: "values of one sdfc pareto --sweep",
    },
    Spec {
        limit: Limit::SweepPoints,
        name: "sweep_points",
        default: 1_000,
        ceiling: 1_000_000,
        what: "settings sdfc pareto measures (the product of its sweeps' values)",
    },
    // An hour at 30 frames per second is 108 000 frames: ten hours fit.
    Spec {
        limit: Limit::Frames,
        name: "frames",
        default: 1_000_000,
        ceiling: 1 << 40,
        what: "frames of one animated sequence",
    },
    // A dense grid of 512³ cells is 134 million; the octree of a scene at that
    // resolution evaluates a few percent of it.
    Spec {
        limit: Limit::Cells,
        name: "cells",
        default: 50_000_000,
        ceiling: 1 << 40,
        what: "cells sdfc mesh evaluates (octree cells and candidates, or the dense grid)",
    },
    // The interpreted kernel's file is an array of this many f32 per GPU thread
    // (compiler/src/back/wgsl/interp.rs), in the GPU's local memory: its size is part
    // of the kernel's text, so every scene that fits shares one kernel. The examples
    // need 5 (seed1) to 40 (lattice), examples/scaling/compound_1000.sdf 54 (linear
    // scan over the program's liveness); 64 holds them all in 256 bytes a thread. A
    // register's number is 13 bits of an instruction word.
    Spec {
        limit: Limit::Registers,
        name: "registers",
        default: 64,
        ceiling: 8_190,
        what: "registers of the interpreted GPU kernel (programs that need more cannot use it)",
    },
    // A triangle takes 144 bytes of the GPU's `scene_data` (its corners and
    // pseudo-normals) and its hierarchy some 16 more: 800 000 fit the 128 MiB that wgpu's
    // default limits let a storage buffer bind, and load in about a second.
    Spec {
        limit: Limit::Triangles,
        name: "triangles",
        default: 800_000,
        ceiling: 1 << 28,
        what: "triangles of the meshes one scene reads",
    },
    // Files are read whole: a mesh of the default `triangles` limit is about 40 MB as
    // binary STL and several times that as text; a scene is far smaller.
    Spec {
        limit: Limit::FileSize,
        name: "file_size",
        default: 256,
        ceiling: 1 << 20,
        what: "MiB of one file read (a scene, an import, a mesh, a font)",
    },
    // Each worker is a thread of the operating system with its own stack and, on the
    // CPU renderer, its evaluators' slots: far more workers than cores only costs
    // (`--threads 100000` started threads until the system refused them). 1 024 is
    // beyond any machine the project meets; the ceiling is where Linux's default
    // limit of threads a process may start lies.
    Spec {
        limit: Limit::Threads,
        name: "threads",
        default: 1_024,
        ceiling: 32_768,
        what: "worker threads --threads may start",
    },
    // A glyph of DejaVu Sans holds some 30 lines and curves, about 2 KB as they are
    // laid out and lowered, and every point walks the glyphs near it: 10 000
    // characters (a few pages, far beyond any plaque or label) check in a tenth of a
    // second within some 40 MB. `text` of a million characters took 1.9 GB.
    Spec {
        limit: Limit::TextChars,
        name: "text_chars",
        default: 10_000,
        ceiling: 1 << 32,
        what: "characters of the text one scene lays out (text), in all",
    },
    // Each point tries about 8n normals against all n balls: 64 balls are some
    // 30 000 operations a point, and finding the planes tangent to three takes n⁴.
    Spec {
        limit: Limit::HullShapes,
        name: "hull_shapes",
        default: 64,
        ceiling: 4_096,
        what: "balls and cylinders one hull(shapes...) takes",
    },
];

// Each limit's row stands at its place in the enum: [`Limit::spec`] reads it by position.
const _: () = {
    let mut i = 0;
    while i < SPECS.len() {
        assert!(
            SPECS[i].limit as usize == i,
            "SPECS is in declaration order"
        );
        i += 1;
    }
};

impl Limit {
    /// Every limit, in the order they are listed.
    pub const ALL: [Limit; 27] = [
        Limit::Nesting,
        Limit::Fuel,
        Limit::CallDepth,
        Limit::Nodes,
        Limit::Objects,
        Limit::Files,
        Limit::Edge,
        Limit::Aa,
        Limit::MaxSteps,
        Limit::MaxDepth,
        Limit::Samples,
        Limit::Bounces,
        Limit::Program,
        Limit::Memory,
        Limit::Expansion,
        Limit::Traced,
        Limit::SceneData,
        Limit::SweepValues,
        Limit::SweepPoints,
        Limit::Frames,
        Limit::Cells,
        Limit::Registers,
        Limit::Triangles,
        Limit::FileSize,
        Limit::Threads,
        Limit::TextChars,
        Limit::HullShapes,
    ];

    /// The limit's row of [`SPECS`].
    fn spec(self) -> &'static Spec {
        &SPECS[self as usize]
    }

    /// The name `--limit NAME=VALUE` uses.
    pub fn name(self) -> &'static str {
        self.spec().name
    }

    /// What the limit bounds, in a few words.
    pub fn describe(self) -> &'static str {
        self.spec().what
    }

    /// The default value.
    pub fn default_value(self) -> u64 {
        self.spec().default
    }

    /// The largest value the limit may be raised to.
    pub fn ceiling(self) -> u64 {
        self.spec().ceiling
    }

    /// The limit of a name, as `--limit` writes it.
    pub fn named(name: &str) -> Option<Limit> {
        Limit::ALL.into_iter().find(|l| l.name() == name)
    }
}

impl fmt::Display for Limit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// How a caller names its options in messages: as the command line's flags (`--limit
/// memory=8192`, `--bounds`) or as the keyword parameters of the Python package's `Scene`
/// (`limits={"memory": 8192}`, `bounds`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub enum Spelling {
    /// Command-line flags.
    #[default]
    Flags,
    /// Keyword parameters.
    Parameters,
}

impl Spelling {
    /// The option `name` (`bounds`, `resolution`, `voxel`) as the caller writes it.
    pub fn option(self, name: &str) -> String {
        match self {
            Spelling::Flags => format!("--{name}"),
            Spelling::Parameters => name.to_string(),
        }
    }

    /// `limit` set to `value`, as the caller writes it: `--limit fuel=100000000`, or
    /// `limits={"fuel": 100000000}`.
    pub fn limit(self, limit: Limit, value: u64) -> String {
        match self {
            Spelling::Flags => format!("--limit {}={value}", limit.name()),
            Spelling::Parameters => format!("limits={{\"{}\": {value}}}", limit.name()),
        }
    }
}

/// A limit's setting (`--limit NAME=VALUE`, Python's `limits=`) that cannot be applied.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum LimitError {
    /// Not of the form `NAME=VALUE`.
    #[error("--limit expects NAME=VALUE, like fuel=100000000, not `{0}`; {names}", names = Limits::names())]
    NotASetting(String),
    /// No limit has this name.
    #[error("unknown limit `{0}`; {names}", names = Limits::names())]
    Unknown(String),
    /// The value is not a whole number within the limit's range.
    #[error("the limit {} must be a whole number from 1 to {}, not `{value}`", limit.name(), limit.ceiling())]
    NotANumber { limit: Limit, value: String },
    /// The value is outside the limit's range.
    #[error("the limit {} must be a whole number from 1 to {}, not {value}", limit.name(), limit.ceiling())]
    OutOfRange { limit: Limit, value: u64 },
}

/// The value of every limit for one run, and how its messages name the option that raises
/// one ([`Spelling`]); and the values given from outside for the scene's parameters
/// (`--param name=value`), which a run is checked with beside its limits, and those offered
/// (the viewer's panel), taken only where the scene accepts them.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Limits {
    values: [u64; 27],
    spelling: Spelling,
    params: Vec<(String, String)>,
    offered: Vec<(String, String)>,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            values: Limit::ALL.map(Limit::default_value),
            spelling: Spelling::Flags,
            params: Vec::new(),
            offered: Vec::new(),
        }
    }
}

impl Limits {
    /// These limits, their messages naming options as `spelling` writes them.
    pub fn spelled(self, spelling: Spelling) -> Limits {
        Limits { spelling, ..self }
    }

    /// Gives the parameter `name` the value written `value` (the last given counts).
    pub fn set_param(&mut self, name: &str, value: &str) {
        self.params.push((name.to_string(), value.to_string()));
    }

    /// The values given for parameters, as written, in the order given.
    pub fn params(&self) -> &[(String, String)] {
        &self.params
    }

    /// Offers the parameter `name` the value written `value` (the last offered counts): the
    /// scene is checked with it, over a value given with [`Limits::set_param`], where it
    /// declares `name` and accepts the value; elsewhere it is passed over in silence (the
    /// viewer's panel keeps what the user set across edits of the file that may rename a
    /// parameter or narrow its range).
    pub fn offer_param(&mut self, name: &str, value: &str) {
        self.offered.push((name.to_string(), value.to_string()));
    }

    /// The values offered for parameters, as written, in the order offered.
    pub fn offered(&self) -> &[(String, String)] {
        &self.offered
    }

    /// How the messages of these limits name the option that raises one.
    pub fn spelling(&self) -> Spelling {
        self.spelling
    }

    /// The value of `limit`.
    pub fn get(&self, limit: Limit) -> u64 {
        self.values[limit as usize]
    }

    /// The value of `limit` as a `usize` (saturating on 32-bit targets).
    pub fn count(&self, limit: Limit) -> usize {
        usize::try_from(self.get(limit)).unwrap_or(usize::MAX)
    }

    /// Sets `limit` to `value`, which must be from 1 to the limit's ceiling.
    pub fn set(&mut self, limit: Limit, value: u64) -> Result<(), LimitError> {
        if !(1..=limit.ceiling()).contains(&value) {
            return Err(LimitError::OutOfRange { limit, value });
        }
        self.values[limit as usize] = value;
        Ok(())
    }

    /// Parses one `NAME=VALUE` of `--limit` (underscores may group digits). The error names
    /// the valid limits.
    pub fn parse(setting: &str) -> Result<(Limit, u64), LimitError> {
        let (name, value) = setting
            .split_once('=')
            .ok_or_else(|| LimitError::NotASetting(setting.to_string()))?;
        let (name, value) = (name.trim(), value.trim());
        let limit = Limit::named(name).ok_or_else(|| LimitError::Unknown(name.to_string()))?;
        let bad = || LimitError::NotANumber {
            limit,
            value: value.to_string(),
        };
        let parsed = value.replace('_', "").parse::<u64>().map_err(|_| bad())?;
        if !(1..=limit.ceiling()).contains(&parsed) {
            return Err(bad());
        }
        Ok((limit, parsed))
    }

    /// Applies one `NAME=VALUE` of `--limit`.
    pub fn apply(&mut self, setting: &str) -> Result<(), LimitError> {
        let (limit, value) = Self::parse(setting)?;
        self.set(limit, value)
    }

    /// `the limits are nesting, fuel, …`, for usage errors.
    pub fn names() -> String {
        let names: Vec<&str> = Limit::ALL.iter().map(|l| l.name()).collect();
        format!("the limits are {}", names.join(", "))
    }

    /// A heading and one line per limit: name, default and what it bounds (for `--help`).
    pub fn table() -> String {
        let row =
            |name: &str, default: &str, what: &str| format!("{name:<12} {default:>10}  {what}");
        let rows = Limit::ALL
            .iter()
            .map(|l| row(l.name(), &l.default_value().to_string(), l.describe()));
        std::iter::once(row("NAME", "DEFAULT", "BOUNDS"))
            .chain(rows)
            .collect::<Vec<_>>()
            .join("\n")
    }

    /// How to raise `limit` past its current value: ``raise it with `--limit fuel=100000000` ``
    /// (twice the current value, within the ceiling), spelled as [`Limits::spelling`].
    pub fn raise(&self, limit: Limit) -> String {
        let doubled = self.get(limit).saturating_mul(2);
        self.raise_to(limit, doubled.min(limit.ceiling().max(self.get(limit) + 1)))
    }

    /// How to raise `limit` to at least `needed`, or that it cannot be raised so far.
    pub fn raise_to(&self, limit: Limit, needed: u64) -> String {
        let ceiling = limit.ceiling();
        let spell = |value| self.spelling.limit(limit, value);
        if needed > ceiling {
            return format!("it cannot be raised above {ceiling} (`{}`)", spell(ceiling));
        }
        format!("raise it with `{}`", spell(needed.max(1)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique_and_defaults_within_ceilings() {
        for (i, a) in Limit::ALL.iter().enumerate() {
            assert_eq!(*a as usize, i, "ALL is in declaration order");
            assert!(a.default_value() >= 1 && a.default_value() <= a.ceiling());
            for b in &Limit::ALL[i + 1..] {
                assert_ne!(a.name(), b.name());
            }
        }
    }

    #[test]
    fn settings_parse_and_errors_list_the_names() {
        let mut l = Limits::default();
        l.apply("fuel=100_000").expect("valid");
        assert_eq!(l.get(Limit::Fuel), 100_000);
        let unknown = l.apply("speed=3").expect_err("unknown");
        assert_eq!(unknown, LimitError::Unknown("speed".into()));
        let text = unknown.to_string();
        assert!(text.contains("unknown limit `speed`") && text.contains("max_steps"));
        for bad in ["aa=0", "aa=257", "aa=x"] {
            let e = l.apply(bad).expect_err(bad);
            assert!(
                matches!(
                    e,
                    LimitError::NotANumber {
                        limit: Limit::Aa,
                        ..
                    }
                ),
                "{e}"
            );
        }
        assert_eq!(
            l.clone().set(Limit::Aa, 0),
            Err(LimitError::OutOfRange {
                limit: Limit::Aa,
                value: 0
            })
        );
        let no_equals = l.apply("aa").expect_err("no =");
        assert!(
            no_equals.to_string().contains("the limits are"),
            "{no_equals}"
        );
        assert_eq!(l.raise(Limit::Fuel), "raise it with `--limit fuel=200000`");
        assert_eq!(l.raise(Limit::Aa), "raise it with `--limit aa=32`");
    }

    #[test]
    fn limits_spelled_as_parameters_name_the_parameter() {
        let l = Limits::default().spelled(Spelling::Parameters);
        assert_eq!(
            l.raise_to(Limit::Memory, 9000),
            "raise it with `limits={\"memory\": 9000}`"
        );
        assert_eq!(
            l.raise_to(Limit::Aa, 1000),
            "it cannot be raised above 256 (`limits={\"aa\": 256}`)"
        );
        assert_eq!(Spelling::Parameters.option("voxel"), "voxel");
        assert_eq!(Spelling::Flags.option("voxel"), "--voxel");
    }
}
