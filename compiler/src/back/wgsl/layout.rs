//! The interface of a validated kernel as JSON (`sdfc compile --emit layout`,
//! docs/embedding.md): its entry point, workgroup size and bindings, and the layout of every
//! binding's type (member names, offsets, sizes, array strides) as naga laid the module out,
//! so that a program of the user's own fills `Params` and dispatches the kernel without sdfc.

use super::Kernel;
use naga::{proc::Layouter, Handle, Module, Type, TypeInner};
use serde_json::{json, Value};

/// Why a kernel's interface cannot be described (a mistake of the compiler's).
#[derive(Debug, thiserror::Error)]
pub enum LayoutError {
    #[error("internal compiler error: laying out the kernel: {0}")]
    Layout(#[from] naga::proc::LayoutError),
    #[error("internal compiler error: the kernel has no entry point")]
    NoEntryPoint,
}

/// The kernel's interface: `entry_point`, `workgroup_size`, and `bindings`, each with its
/// group, binding, name, address space, access and type layout.
pub fn interface(kernel: &Kernel) -> Result<Value, LayoutError> {
    let module = &kernel.module;
    let mut layouter = Layouter::default();
    layouter.update(module.to_ctx())?;
    let entry = module
        .entry_points
        .iter()
        .find(|e| e.name == super::ENTRY_POINT)
        .ok_or(LayoutError::NoEntryPoint)?;
    let mut bindings: Vec<(u32, u32, Value)> = module
        .global_variables
        .iter()
        .filter_map(|(_, g)| {
            let b = g.binding.as_ref()?;
            let (space, access) = match g.space {
                naga::AddressSpace::Uniform => ("uniform", "read"),
                naga::AddressSpace::Storage { access } => (
                    "storage",
                    if access.contains(naga::StorageAccess::STORE) {
                        "read_write"
                    } else {
                        "read"
                    },
                ),
                _ => ("other", "read"),
            };
            Some((
                b.group,
                b.binding,
                json!({
                    "group": b.group,
                    "binding": b.binding,
                    "name": g.name,
                    "space": space,
                    "access": access,
                    "type": describe(module, &layouter, g.ty),
                }),
            ))
        })
        .collect();
    bindings.sort_by_key(|b| (b.0, b.1));
    Ok(json!({
        "entry_point": entry.name,
        "workgroup_size": entry.workgroup_size,
        "bindings": bindings.into_iter().map(|b| b.2).collect::<Vec<_>>(),
    }))
}

/// A type's name and layout: a scalar or vector by its WGSL name, an array with its element,
/// length (absent when sized at run time) and stride, a struct with its members' offsets.
fn describe(module: &Module, layouter: &Layouter, ty: Handle<Type>) -> Value {
    let size = layouter[ty].size;
    match &module.types[ty].inner {
        TypeInner::Scalar(s) => json!({"name": scalar(*s), "size": size}),
        TypeInner::Vector { size: n, scalar: s } => {
            json!({"name": format!("vec{}<{}>", *n as u8, scalar(*s)), "size": size})
        }
        TypeInner::Array {
            base,
            size: n,
            stride,
        } => {
            let length = match n {
                naga::ArraySize::Constant(k) => Some(k.get()),
                _ => None,
            };
            json!({
                "name": "array",
                "length": length,
                "stride": stride,
                "size": length.map(|_| size),
                "element": describe(module, layouter, *base),
            })
        }
        TypeInner::Struct { members, span } => json!({
            "name": module.types[ty].name,
            "size": span,
            "members": members
                .iter()
                .map(|m| json!({
                    "name": m.name,
                    "offset": m.offset,
                    "type": describe(module, layouter, m.ty),
                }))
                .collect::<Vec<_>>(),
        }),
        other => json!({"name": format!("{other:?}"), "size": size}),
    }
}

fn scalar(s: naga::Scalar) -> String {
    let kind = match s.kind {
        naga::ScalarKind::Float => "f",
        naga::ScalarKind::Uint => "u",
        naga::ScalarKind::Sint => "i",
        naga::ScalarKind::Bool => return "bool".into(),
        _ => return format!("{s:?}"),
    };
    format!("{kind}{}", s.width as u32 * 8)
}
