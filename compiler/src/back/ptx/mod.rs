//! The PTX back end: a validated naga module of a WGSL compute shader written as PTX
//! text for NVIDIA GPUs, `back::ptx::write(&Module, &ModuleInfo, &Options)`.
//!
//! The kernel's interface: one `.param .u64` global address per uniform or storage
//! buffer of the module, in (group, binding) order, whether or not the entry point
//! uses it. Launch it with the entry point's workgroup size as the block (the header
//! says it; it is not declared with `.reqntid`, which makes ptxas cap the registers and
//! spill) and the dispatch as the grid.
//!
//! How naga's IR maps to PTX:
//! - every value is scalarised: one virtual register (or immediate) per scalar leaf of
//!   a vector, matrix, struct or array, in declaration order;
//! - each expression is evaluated once, at the `Emit` that covers it, into fresh
//!   registers; constants are immediates and cost nothing until used;
//! - variables (function locals and `var<private>`) live in registers, except those an
//!   array or matrix of which is indexed with a run-time index: they live in `.local`
//!   memory with the WGSL layout;
//! - structured control flow becomes labelled branches; loads from uniform buffers at
//!   fixed offsets in an innermost loop are made once before it;
//! - a function is inlined at its calls where it must be (it takes a pointer, or uses a
//!   `var<private>`, which lives in the kernel's registers) or where that duplicates
//!   little code; the others are `.func`s whose parameters are the buffer addresses
//!   they use followed by their arguments' leaves, with one aggregate return value;
//! - run-time indices into fixed-size arrays and vectors are clamped to the last
//!   element (naga's `Restrict` policy); indices into runtime-sized arrays are not;
//! - f32 arithmetic flushes subnormals (`.ftz`), as WGSL allows and NVIDIA's Vulkan
//!   driver does; maths: `math.rs` and `libm.rs`; docs/ptx.md gives each function's error.
//!
//! The output depends only on the module: registers, labels and functions are
//! numbered in the order the IR lists them.

mod analysis;
mod emit;
mod expr;
mod func;
mod isa;
mod libm;
mod math;
mod memory;
mod ops;
mod params;
mod stmt;
mod types;
mod writer;

use naga::valid::ModuleInfo;
use naga::{AddressSpace, Module, ShaderStage};
use std::cell::Cell;
use std::collections::HashSet;
use std::fmt;

pub use params::{check_arguments, Argument, Fault, Mismatch, Param, Space};

/// What to write.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Options {
    /// The target architecture: 70 for `sm_70`, 80, 86, 89, 90 ...
    pub sm: u32,
    /// The name of the compute entry point to write as the kernel.
    pub entry_point: String,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            sm: 70,
            entry_point: "main".into(),
        }
    }
}

/// Why a module could not be written as PTX.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Error {
    /// The module has no entry point of this name.
    NoEntryPoint(String),
    /// The entry point is not a compute shader.
    NotCompute(String),
    /// The target architecture is not one this back end knows a PTX version for.
    Target(u32),
    /// A construct this back end does not translate, named.
    Unsupported(String),
    /// The module breaks a rule naga's validator guarantees (a bug upstream).
    Invalid(String),
}

impl Error {
    /// The error, saying in which WGSL function it arose.
    fn in_function(self, name: &str) -> Self {
        match self {
            Error::Unsupported(m) => Error::Unsupported(format!("{m} (in fn {name})")),
            Error::Invalid(m) => Error::Invalid(format!("{m} (in fn {name})")),
            other => other,
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self {
            Error::NoEntryPoint(n) => write!(f, "the module has no entry point `{n}`"),
            Error::NotCompute(n) => write!(f, "the entry point `{n}` is not a compute shader"),
            Error::Target(sm) => write!(
                f,
                "no PTX target for sm_{sm} (sm_50 to sm_90, sm_100, sm_120)"
            ),
            Error::Unsupported(m) => write!(f, "the PTX back end does not support {m}"),
            Error::Invalid(m) => write!(f, "internal error in the PTX back end: {m}"),
        }
    }
}

impl std::error::Error for Error {}

/// The PTX ISA version for `sm`: the oldest that supports it (so older drivers load it).
fn isa_version(sm: u32) -> Result<&'static str, Error> {
    Ok(match sm {
        50..=80 => "7.0",
        81..=86 => "7.1",
        87 => "7.4",
        88..=90 => "7.8",
        100 | 101 => "8.6",
        103 | 121 => "8.8",
        120 => "8.7",
        _ => return Err(Error::Target(sm)),
    })
}

/// A written PTX module and its kernel's parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct Ptx {
    /// The PTX text.
    pub text: String,
    /// The kernel's parameters, in order: what a launch must pass ([`check_arguments`]).
    pub params: Vec<Param>,
}

/// Writes the entry point `options.entry_point` of `module` (validated, with `info` from
/// naga's validator) as a PTX module for `sm_<options.sm>`, with its parameters.
pub fn write(module: &Module, info: &ModuleInfo, options: &Options) -> Result<Ptx, Error> {
    let name = &options.entry_point;
    let index = module
        .entry_points
        .iter()
        .position(|e| &e.name == name)
        .ok_or_else(|| Error::NoEntryPoint(name.clone()))?;
    let ep = &module.entry_points[index];
    if ep.stage != ShaderStage::Compute {
        return Err(Error::NotCompute(name.clone()));
    }
    if func::ident(name) != *name
        || name.starts_with(|c: char| c.is_ascii_digit())
        || name.starts_with("__")
    {
        return Err(Error::Unsupported(format!(
            "the entry point name `{name}` (not a PTX identifier)"
        )));
    }
    if ep.workgroup_size_overrides.is_some() {
        return Err(Error::Unsupported(
            "a workgroup size set by pipeline overrides".into(),
        ));
    }
    let version = isa_version(options.sm)?;
    let types = types::Types::new(module);
    let an = analysis::Analysis::new(module, info, &types, index)?;
    let buffers = buffers(module);
    let params = params::params(module, &buffers, name)?;
    let cx = writer::Cx {
        module,
        info,
        types,
        an,
        buffers,
        params,
        names: names(module, name),
        trig_reduce: Cell::new(false),
    };
    let mut funcs = String::new();
    for (h, _) in module.functions.iter() {
        if cx.an.reachable[h.index()] && !cx.an.inline[h.index()] {
            let text = func::write_func(&cx, h)?;
            funcs.push_str(&text);
            funcs.push('\n');
        }
    }
    let kernel = func::write_kernel(&cx, ep, index)?;
    let mut out = header(&cx, name, options.sm, version);
    if cx.trig_reduce.get() {
        out.push_str(&libm::trig_reduce_func());
        out.push('\n');
    }
    out.push_str(&funcs);
    out.push_str(&kernel);
    Ok(Ptx {
        text: out,
        params: cx.params,
    })
}

/// The uniform and storage buffers, in (group, binding) order.
fn buffers(module: &Module) -> Vec<naga::Handle<naga::GlobalVariable>> {
    let mut b: Vec<_> = module
        .global_variables
        .iter()
        .filter(|(_, g)| {
            matches!(
                g.space,
                AddressSpace::Uniform | AddressSpace::Storage { .. }
            )
        })
        .filter_map(|(h, g)| g.binding.as_ref().map(|rb| ((rb.group, rb.binding), h)))
        .collect();
    b.sort_by_key(|&(key, h)| (key, h.index()));
    b.into_iter().map(|(_, h)| h).collect()
}

/// A unique PTX name for each function: `fn_<name>`.
fn names(module: &Module, entry: &str) -> Vec<String> {
    let mut seen: HashSet<String> = HashSet::from([entry.to_string(), libm_name()]);
    module
        .functions
        .iter()
        .map(|(h, f)| {
            let base = format!(
                "fn_{}",
                func::ident(f.name.as_deref().unwrap_or("anonymous"))
            );
            let name = if seen.contains(&base) {
                format!("{base}_{}", h.index())
            } else {
                base
            };
            seen.insert(name.clone());
            name
        })
        .collect()
}

fn libm_name() -> String {
    libm::TRIG_REDUCE.to_string()
}

/// The module's header: what it is, how to launch it, the target.
fn header(cx: &writer::Cx, entry: &str, sm: u32, version: &str) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "//\n// Generated by sdfc's PTX back end from the WGSL entry point `{entry}`."
    );
    let _ = writeln!(
        s,
        "// Kernel parameters: the global address of each buffer, in (group, binding) order:"
    );
    for p in &cx.params {
        let _ = writeln!(
            s,
            "//   {}: @group({}) @binding({}) var<{}> {}",
            p.name,
            p.group,
            p.binding,
            p.space,
            emit::ascii(&p.var)
        );
    }
    let _ = writeln!(
        s,
        "//\n\n.version {version}\n.target sm_{sm}\n.address_size 64\n"
    );
    s
}
