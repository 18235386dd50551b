//! A kernel's contract: the features it was specialised for (every `//#if` of the template,
//! on or off), the render settings that decided them, and what it reads at each render: the
//! scene uniform `Params` (binding 0) as naga laid it out, member by member. A render checks
//! its scene against the contract ([`Contract::check`]) and writes the uniform by member name
//! at the offsets naga reports ([`UniformWriter`]), so that the template's `Params` and the
//! bytes the launchers upload cannot drift apart: a member the writer names and the kernel
//! lacks, a member of another type, or a member of the kernel's that nothing writes is an
//! error, never a silently shifted field.

use crate::scene::{Method, Scene, Settings};
use naga::{AddressSpace, Handle, Module, ScalarKind, Type, TypeInner};
use std::fmt;

/// What of the render settings a kernel is specialised for: the method (analytic tracing
/// or marching: `ANALYTIC`), whether over-relaxation is on (`RELAX`) and `max_depth` (the ray
/// stack's size, and `SECONDARY`). The values of the other settings (ε, `max_steps`, ω
/// itself, the image size) are uniforms, read at every render.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Specialisation {
    /// The `method` setting.
    pub method: Method,
    /// Whether ω > 1.
    pub relax: bool,
    /// The `max_depth` setting.
    pub max_depth: u32,
    /// Whether it path traces (`method: "path"`).
    pub path: bool,
}

impl Specialisation {
    /// The specialisation a kernel for `settings` has. Every setting is named here: those
    /// not kept are read from the uniform at each render ([`super::uniforms`]), so a new
    /// setting must be placed on one side or the other.
    pub fn of(settings: &Settings) -> Specialisation {
        let Settings {
            // Read at every render (`Params`: view, march, background, counts).
            width: _,
            height: _,
            aa: _,
            max_steps: _,
            epsilon: _,
            footprint: _,
            max_dist: _,
            background: _,
            // Read at every render (`look`, `fog`); whether each is on is a feature.
            occlusion: _,
            fog: _,
            fog_color: _,
            // Read at every render (`glow`); whether it is on is a feature (`GLOW`).
            glow: _,
            glow_color: _,
            exposure: _,
            tonemap: _,
            tonemap_why: _,
            // Its samples, bounces and first sample are read at every render (`depth.y`,
            // `depth.z`, `depth.w`);
            // whether it path traces is specialised (the feature `PATH`).
            path,
            samples: _,
            bounces: _,
            first_sample: _,
            // Specialised (and read: ω in `march.z`, max_depth in `depth.x`).
            relaxation,
            max_depth,
            method,
        } = settings;
        Specialisation {
            method: *method,
            path: *path,
            relax: *relaxation > 1.0,
            max_depth: *max_depth,
        }
    }

    /// In words, for errors.
    pub fn describe(&self) -> String {
        format!(
            "method {}{}, {}, max_depth {}",
            self.method.name(),
            if self.path { " (path traced)" } else { "" },
            if self.relax {
                "over-relaxation"
            } else {
                "no over-relaxation (ω = 1)"
            },
            self.max_depth
        )
    }
}

/// What a kernel was specialised for and what it reads: [`super::Kernel::contract`], also
/// held by a CUDA module translated from the kernel.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Contract {
    /// The render settings that decided its features: a render with other settings of
    /// these needs another kernel.
    pub specialisation: Specialisation,
    /// Every feature of the template by name, on or off: those of the scene and its settings
    /// (`ANALYTIC`, `POINT`, `DIRECTIONAL`, `SOFT`, `CHECKER`, `TRANSPARENT`, `REFRACTION`,
    /// `SECONDARY`, `MATERIALS`, `RELAX`, `COLOUR_FIELDS`, `OCCLUSION`, `SKY`, `FOG`, `GRADE`), then the kernel's own (`DEBUG_NAN`, `PARAMS`,
    /// `MEDIA`, `SCENE_DATA`, `INTERPRETED`).
    pub features: Vec<(&'static str, bool)>,
    /// The scene uniform (binding 0) as naga laid it out.
    pub uniform: Uniform,
}

/// The features that follow from the scene and its settings alone (the first ones of
/// [`Contract::features`]): those a render checks.
pub(super) const SCENE_FEATURES: usize = 19;

/// A scene that a kernel cannot render, or a uniform that does not fit its layout: what
/// differs, in words.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Mismatch(pub String);

impl fmt::Display for Mismatch {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for Mismatch {}

impl Contract {
    /// Whether feature `name` is on.
    pub fn has(&self, name: &str) -> bool {
        self.features.iter().any(|&(n, on)| n == name && on)
    }

    /// `Err` when `scene` (traced analytically when `traced`) needs a kernel specialised
    /// otherwise: other settings of those kept ([`Specialisation`]), or a feature of the
    /// scene's on where the kernel has it off or the other way round (a light with a
    /// penumbra where the kernel has hard shadows only, say). The message names each
    /// difference.
    pub fn check(&self, scene: &Scene, traced: bool) -> Result<(), Mismatch> {
        let wanted = Specialisation::of(&scene.settings);
        let mut differences = Vec::new();
        if wanted != self.specialisation {
            differences.push(format!(
                "it was specialised for {}, the settings ask for {}",
                self.specialisation.describe(),
                wanted.describe()
            ));
        }
        let have = &self.features[..SCENE_FEATURES.min(self.features.len())];
        for (name, on) in super::features(scene, traced) {
            if let Some(&(_, had)) = have.iter().find(|(n, _)| *n == name) {
                if had != on {
                    differences.push(format!(
                        "{name} is {} in the kernel and {} for this scene",
                        if had { "on" } else { "off" },
                        if on { "on" } else { "off" }
                    ));
                }
            }
        }
        if differences.is_empty() {
            Ok(())
        } else {
            Err(Mismatch(differences.join("; ")))
        }
    }
}

/// The layout of a struct the kernel reads, from naga: its name, size and members.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Uniform {
    /// The struct's name in the kernel (`Params`).
    pub name: String,
    /// Its size in bytes.
    pub size: u32,
    /// Its members, at naga's offsets.
    pub members: Vec<Field>,
}

/// A member of a struct: name, offset from the struct's start, shape.
#[derive(Debug, Clone, PartialEq)]
pub struct Field {
    pub name: String,
    pub offset: u32,
    pub shape: Shape,
}

/// What a member holds.
#[derive(Debug, Clone, PartialEq)]
pub enum Shape {
    /// A scalar (`n` = 1) or vector of `n` 32-bit components, floats or unsigned integers.
    Leaf { float: bool, n: u32 },
    /// A fixed-size array.
    Array {
        length: u32,
        stride: u32,
        element: Box<Shape>,
    },
    /// A struct.
    Struct(Vec<Field>),
    /// A type the uniform writer does not write (named), which the writer refuses.
    Other(String),
}

impl Uniform {
    /// The layout of the uniform at group 0, binding 0 of `module`, as naga laid it out
    /// (the members' `offset`s, the arrays' `stride`s, the struct's `span`). `None` when
    /// the module has no such uniform struct (a `--part map` module).
    pub fn of(module: &Module) -> Option<Uniform> {
        let (_, global) = module.global_variables.iter().find(|(_, g)| {
            g.space == AddressSpace::Uniform
                && g.binding
                    .as_ref()
                    .is_some_and(|b| b.group == 0 && b.binding == 0)
        })?;
        match &module.types[global.ty].inner {
            TypeInner::Struct { members, span } => Some(Uniform {
                name: module.types[global.ty]
                    .name
                    .clone()
                    .unwrap_or_else(|| "?".into()),
                size: *span,
                members: fields(module, members),
            }),
            _ => None,
        }
    }

    /// A writer of this layout's bytes, all zero to begin with.
    pub fn writer(&self) -> UniformWriter<'_> {
        UniformWriter {
            layout: self,
            bytes: vec![0; self.size as usize],
            written: vec![false; self.size as usize],
        }
    }
}

fn fields(module: &Module, members: &[naga::StructMember]) -> Vec<Field> {
    members
        .iter()
        .map(|m| Field {
            name: m.name.clone().unwrap_or_default(),
            offset: m.offset,
            shape: shape(module, m.ty),
        })
        .collect()
}

fn shape(module: &Module, ty: Handle<Type>) -> Shape {
    let leaf = |s: naga::Scalar, n: u32| match (s.kind, s.width) {
        (ScalarKind::Float, 4) => Shape::Leaf { float: true, n },
        (ScalarKind::Uint, 4) => Shape::Leaf { float: false, n },
        _ => Shape::Other(format!("{s:?}")),
    };
    match &module.types[ty].inner {
        TypeInner::Scalar(s) => leaf(*s, 1),
        TypeInner::Vector { size, scalar } => leaf(*scalar, *size as u32),
        TypeInner::Array {
            base,
            size: naga::ArraySize::Constant(length),
            stride,
        } => Shape::Array {
            length: length.get(),
            stride: *stride,
            element: Box::new(shape(module, *base)),
        },
        TypeInner::Struct { members, .. } => Shape::Struct(fields(module, members)),
        other => Shape::Other(format!("{other:?}")),
    }
}

/// Writes a uniform's bytes by member path (`"eye"`, `"points[1].color"`) at naga's offsets;
/// [`UniformWriter::finish`] refuses bytes where a member was left unwritten.
#[derive(Debug)]
pub struct UniformWriter<'a> {
    layout: &'a Uniform,
    bytes: Vec<u8>,
    written: Vec<bool>,
}

impl UniformWriter<'_> {
    /// Writes `values` (rounded to f32) into the float member at `path`.
    pub fn floats(&mut self, path: &str, values: &[f64]) -> Result<(), Mismatch> {
        let words: Vec<u32> = values.iter().map(|&x| (x as f32).to_bits()).collect();
        self.put(path, true, &words)
    }

    /// Writes `values` into the unsigned integer member at `path`.
    pub fn uints(&mut self, path: &str, values: &[u32]) -> Result<(), Mismatch> {
        self.put(path, false, values)
    }

    fn put(&mut self, path: &str, float: bool, words: &[u32]) -> Result<(), Mismatch> {
        let name = &self.layout.name;
        let (offset, shape) = resolve(&self.layout.members, path).map_err(|e| {
            Mismatch(format!(
                "the kernel's uniform `{name}` has no member `{path}` ({e})"
            ))
        })?;
        let kind = |f: bool| if f { "f32" } else { "u32" };
        match shape {
            Shape::Leaf { float: f, n } if *f == float && *n as usize == words.len() => {}
            Shape::Leaf { float: f, n } => {
                return Err(Mismatch(format!(
                    "the member `{path}` of the kernel's uniform `{name}` holds {n} {}, written as {} {}",
                    kind(*f),
                    words.len(),
                    kind(float)
                )))
            }
            _ => {
                return Err(Mismatch(format!(
                    "the member `{path}` of the kernel's uniform `{name}` is not a scalar or vector"
                )))
            }
        }
        for (k, w) in words.iter().enumerate() {
            let at = offset as usize + 4 * k;
            self.bytes[at..at + 4].copy_from_slice(&w.to_le_bytes());
            self.written[at..at + 4].fill(true);
        }
        Ok(())
    }

    /// The bytes as written so far, whatever was left unwritten (for tests that find offsets).
    #[cfg(test)]
    pub(super) fn finish_unchecked(self) -> Vec<u8> {
        self.bytes
    }

    /// The bytes, or `Err` naming the first member of the layout that nothing wrote.
    pub fn finish(self) -> Result<Vec<u8>, Mismatch> {
        let mut missing = None;
        leaves(&self.layout.members, 0, "", &mut |path, offset| {
            if missing.is_none() && !self.written[offset as usize] {
                missing = Some(path.to_string());
            }
        });
        match missing {
            Some(path) => Err(Mismatch(format!(
                "the member `{path}` of the kernel's uniform `{}` is written by nothing: \
                 the kernel was written for another scene, or the uniform writer lags the template",
                self.layout.name
            ))),
            None => Ok(self.bytes),
        }
    }
}

/// The offset and shape of the member at `path` among `members`.
fn resolve<'a>(members: &'a [Field], path: &str) -> Result<(u32, &'a Shape), Unresolved> {
    let (head, rest) = match path.split_once('.') {
        Some((h, r)) => (h, Some(r)),
        None => (path, None),
    };
    let (name, index) = match head.split_once('[') {
        Some((n, i)) => {
            let i = i
                .strip_suffix(']')
                .and_then(|i| i.parse::<u32>().ok())
                .ok_or_else(|| Unresolved::NotIndex(head.into()))?;
            (n, Some(i))
        }
        None => (head, None),
    };
    let field = members
        .iter()
        .find(|f| f.name == name)
        .ok_or_else(|| Unresolved::NoMember(name.into()))?;
    let (mut offset, mut shape) = (field.offset, &field.shape);
    if let Some(i) = index {
        match shape {
            Shape::Array {
                length,
                stride,
                element,
            } if i < *length => {
                offset += i * stride;
                shape = element;
            }
            Shape::Array { length, .. } => {
                return Err(Unresolved::Past {
                    name: name.into(),
                    length: *length,
                    index: i,
                })
            }
            _ => return Err(Unresolved::NotArray(name.into())),
        }
    }
    match (rest, shape) {
        (None, _) => Ok((offset, shape)),
        (Some(rest), Shape::Struct(inner)) => resolve(inner, rest).map(|(o, s)| (offset + o, s)),
        (Some(_), _) => Err(Unresolved::NotStruct(head.into())),
    }
}

/// Why a member's path names nothing in a layout.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
enum Unresolved {
    #[error("`{0}` is not an index")]
    NotIndex(String),
    #[error("no `{0}`")]
    NoMember(String),
    #[error("`{name}` holds {length}, not an element {index}")]
    Past {
        name: String,
        length: u32,
        index: u32,
    },
    #[error("`{0}` is not an array")]
    NotArray(String),
    #[error("`{0}` is not a struct")]
    NotStruct(String),
}

/// Calls `f` with the path and offset of every scalar or vector under `members`.
fn leaves(members: &[Field], base: u32, prefix: &str, f: &mut dyn FnMut(&str, u32)) {
    for m in members {
        let path = format!("{prefix}{}", m.name);
        visit(&m.shape, base + m.offset, &path, f);
    }
}

fn visit(shape: &Shape, offset: u32, path: &str, f: &mut dyn FnMut(&str, u32)) {
    match shape {
        Shape::Leaf { .. } | Shape::Other(_) => f(path, offset),
        Shape::Array {
            length,
            stride,
            element,
        } => {
            for i in 0..*length {
                visit(element, offset + i * stride, &format!("{path}[{i}]"), f);
            }
        }
        Shape::Struct(inner) => leaves(inner, offset, &format!("{path}."), f),
    }
}
