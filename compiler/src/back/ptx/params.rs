//! The kernel's parameters as data: one `.param .u64` global address per uniform or storage
//! buffer of the module, in (group, binding) order, with the binding each one is, what the
//! buffer must hold (naga's layout of its type) and whether the kernel writes it. The writer
//! names the `.entry`'s parameters from this list and returns it ([`super::Ptx::params`]), so
//! that a launcher checks what it passes against it before its `unsafe` launch
//! ([`check_arguments`]).

use naga::proc::Layouter;
use naga::{AddressSpace, ArraySize, GlobalVariable, Handle, Module, StorageAccess, TypeInner};

/// One parameter of the kernel: the address of one buffer.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Param {
    /// Its name in the PTX (`main_param_0`).
    pub name: String,
    /// Its PTX type (`u64`: a global address) and size in bytes.
    pub ty: &'static str,
    pub size: u32,
    /// The buffer's binding.
    pub group: u32,
    pub binding: u32,
    /// The buffer's variable in the module (`params`, `scene_data`).
    pub var: String,
    /// Its address space.
    pub space: Space,
    /// The fewest bytes the buffer may hold: the size of its type, or of one element of a
    /// runtime-sized array.
    pub min_bytes: u64,
    /// For a runtime-sized array, its stride: the buffer holds whole elements.
    pub stride: Option<u64>,
}

/// A buffer's address space, as the kernel declares it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Space {
    Uniform,
    /// A storage buffer, `read_write` when `writable`.
    Storage {
        writable: bool,
    },
}

impl std::fmt::Display for Space {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Space::Uniform => "uniform",
            Space::Storage { writable: true } => "storage, read_write",
            Space::Storage { writable: false } => "storage, read",
        })
    }
}

/// What a launcher passes as one parameter: the address of a device buffer of `bytes`
/// bytes, given for binding (`group`, `binding`) in `space`, as an argument of `size` bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Argument {
    pub group: u32,
    pub binding: u32,
    pub space: Space,
    pub bytes: u64,
    pub size: u32,
}

/// The parameters of entry point `entry` of `module`, one for each of `buffers`.
pub(super) fn params(
    module: &Module,
    buffers: &[Handle<GlobalVariable>],
    entry: &str,
) -> Result<Vec<Param>, super::Error> {
    let mut layouter = Layouter::default();
    layouter
        .update(module.to_ctx())
        .map_err(|e| super::Error::Invalid(format!("laying out the module's types: {e}")))?;
    Ok(buffers
        .iter()
        .enumerate()
        .map(|(i, &h)| {
            let g = &module.global_variables[h];
            let (group, binding) = g.binding.as_ref().map_or((0, 0), |b| (b.group, b.binding));
            let space = match g.space {
                AddressSpace::Storage { access } => Space::Storage {
                    writable: access.contains(StorageAccess::STORE),
                },
                _ => Space::Uniform,
            };
            let (min_bytes, stride) = match &module.types[g.ty].inner {
                TypeInner::Array {
                    size: ArraySize::Dynamic,
                    stride,
                    ..
                } => (u64::from(*stride), Some(u64::from(*stride))),
                _ => (u64::from(layouter[g.ty].size), None),
            };
            Param {
                name: format!("{entry}_param_{i}"),
                ty: "u64",
                size: 8,
                group,
                binding,
                var: g.name.clone().unwrap_or_else(|| "?".into()),
                space,
                min_bytes,
                stride,
            }
        })
        .collect())
}

/// How a launch's arguments differ from the kernel's parameters.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum Mismatch {
    /// Not one argument for each parameter.
    #[error("the kernel takes {} buffers ({}), the launch passes {passed}", declared.len(), declared.join(", "))]
    Count {
        /// The parameters' bindings and variables, `@binding(0) params`.
        declared: Vec<String>,
        passed: usize,
    },
    /// One parameter (`what` describes it) and how its argument differs.
    #[error("{what} {fault}")]
    Argument { what: String, fault: Fault },
}

/// How one argument differs from its parameter.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum Fault {
    #[error("is passed the buffer of @group({group}) @binding({binding})")]
    Binding { group: u32, binding: u32 },
    #[error("is passed a {0} buffer")]
    Space(Space),
    #[error("is a .{ty} of {size} bytes, passed an argument of {passed} bytes")]
    Size {
        ty: &'static str,
        size: u32,
        passed: u32,
    },
    #[error("needs at least {least} bytes, passed {passed}")]
    Short { least: u64, passed: u64 },
    #[error("holds elements of {stride} bytes, passed {passed} bytes")]
    Stride { stride: u64, passed: u64 },
}

/// What differs when `args` are not what `params` declare: as many, each for the
/// parameter's binding and address space, an argument of the parameter's size, a buffer at
/// least as large as its type (whole elements of a runtime-sized array).
pub fn check_arguments(params: &[Param], args: &[Argument]) -> Result<(), Mismatch> {
    if params.len() != args.len() {
        return Err(Mismatch::Count {
            declared: params
                .iter()
                .map(|p| format!("@binding({}) {}", p.binding, p.var))
                .collect(),
            passed: args.len(),
        });
    }
    for (p, a) in params.iter().zip(args) {
        let fault = if (a.group, a.binding) != (p.group, p.binding) {
            Fault::Binding {
                group: a.group,
                binding: a.binding,
            }
        } else if a.space != p.space {
            Fault::Space(a.space)
        } else if a.size != p.size {
            Fault::Size {
                ty: p.ty,
                size: p.size,
                passed: a.size,
            }
        } else if a.bytes < p.min_bytes {
            Fault::Short {
                least: p.min_bytes,
                passed: a.bytes,
            }
        } else if let Some(stride) = p.stride.filter(|&s| a.bytes % s != 0) {
            Fault::Stride {
                stride,
                passed: a.bytes,
            }
        } else {
            continue;
        };
        let what = format!(
            "parameter {} (@group({}) @binding({}) var<{}> {})",
            p.name, p.group, p.binding, p.space, p.var
        );
        return Err(Mismatch::Argument { what, fault });
    }
    Ok(())
}
