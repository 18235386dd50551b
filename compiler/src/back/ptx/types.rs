//! Types as the PTX writer sees them: the scalars it supports, the shape of a value,
//! how many registers a value takes (its leaves, in declaration order) and where each
//! leaf lives in memory (the offsets and strides naga's WGSL layout put in the IR).

use super::emit::{Class, Leaves, Op};
use super::Error;
use naga::proc::TypeResolution;
use naga::{ArraySize, Handle, Module, ScalarKind, StructMember, Type, TypeInner};

/// The largest value (in scalar leaves) the writer keeps in registers.
const MAX_LEAVES: u32 = 1 << 16;

/// A supported scalar type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Sc {
    F32,
    I32,
    U32,
    Bool,
}

impl Sc {
    /// The supported scalar for naga's `s`, or an error naming it.
    pub fn of(s: naga::Scalar) -> Result<Sc, Error> {
        match (s.kind, s.width) {
            (ScalarKind::Float, 4) => Ok(Sc::F32),
            (ScalarKind::Sint, 4) => Ok(Sc::I32),
            (ScalarKind::Uint, 4) => Ok(Sc::U32),
            (ScalarKind::Bool, _) => Ok(Sc::Bool),
            (kind, width) => Err(Error::Unsupported(format!(
                "the scalar type {kind:?} of {width} bytes"
            ))),
        }
    }

    /// The register class that holds it.
    pub fn class(self) -> Class {
        match self {
            Sc::F32 => Class::F32,
            Sc::I32 | Sc::U32 => Class::B32,
            Sc::Bool => Class::Pred,
        }
    }

    /// The PTX type of arithmetic on it.
    pub fn ptx(self) -> &'static str {
        match self {
            Sc::F32 => "f32",
            Sc::I32 => "s32",
            Sc::U32 => "u32",
            Sc::Bool => "pred",
        }
    }

    /// The PTX type of a load or store of it (booleans are bytes in memory).
    pub fn mem(self) -> &'static str {
        match self {
            Sc::F32 => "f32",
            Sc::I32 | Sc::U32 => "u32",
            Sc::Bool => "u8",
        }
    }

    /// Its size in memory, in bytes.
    pub fn bytes(self) -> u32 {
        if self == Sc::Bool {
            1
        } else {
            4
        }
    }

    /// Its zero.
    pub fn zero(self) -> Op {
        match self {
            Sc::F32 => Op::F32(0),
            Sc::I32 => Op::I32(0),
            Sc::U32 => Op::U32(0),
            Sc::Bool => Op::Bool(false),
        }
    }
}

/// A value type: one from the module's arena, or a scalar, vector or (f32) matrix that
/// naga resolved without one.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Ty {
    H(Handle<Type>),
    S(Sc),
    V(u32, Sc),
    M { cols: u32, rows: u32 },
}

/// What a type is made of.
#[derive(Debug, Clone, Copy)]
pub(super) enum Shape<'a> {
    Scalar(Sc),
    Vector(u32, Sc),
    /// Columns of `rows` f32s.
    Matrix {
        cols: u32,
        rows: u32,
    },
    Struct(Handle<Type>, &'a [StructMember]),
    /// `len` is `None` for a runtime-sized array.
    Array {
        base: Handle<Type>,
        len: Option<u32>,
        stride: u32,
    },
}

/// An expression's type: a value, or a pointer to a value.
#[derive(Debug, Clone, Copy)]
pub(super) enum Resolved {
    Value(Ty),
    Pointer(Ty),
}

/// A run of leaves loaded or stored by one instruction (`n` is 1, 2 or 4).
#[derive(Debug, Clone, Copy)]
pub(super) struct Chunk {
    pub offset: u32,
    pub sc: Sc,
    pub n: u32,
}

/// Facts about the module's types, computed once in arena order.
#[derive(Debug)]
pub(super) struct Types<'a> {
    pub module: &'a Module,
    /// Leaves per type handle; `None` where the type cannot be a register value.
    leaves: Vec<Option<u32>>,
    /// For each struct, the index of the first leaf of each member.
    firsts: Vec<Vec<u32>>,
}

impl<'a> Types<'a> {
    pub fn new(module: &'a Module) -> Self {
        let mut t = Types {
            module,
            leaves: Vec::with_capacity(module.types.len()),
            firsts: Vec::new(),
        };
        for (_, ty) in module.types.iter() {
            let (n, firsts) = t.count(&ty.inner);
            t.leaves.push(n);
            t.firsts.push(firsts);
        }
        t
    }

    fn count(&self, inner: &TypeInner) -> (Option<u32>, Vec<u32>) {
        let known = |h: Handle<Type>| self.leaves.get(h.index()).copied().flatten();
        match *inner {
            TypeInner::Scalar(s) => (Sc::of(s).ok().map(|_| 1), Vec::new()),
            TypeInner::Vector { size, scalar } => {
                (Sc::of(scalar).ok().map(|_| size as u32), Vec::new())
            }
            TypeInner::Matrix {
                columns,
                rows,
                scalar,
            } if Sc::of(scalar) == Ok(Sc::F32) => (Some(columns as u32 * rows as u32), Vec::new()),
            TypeInner::Struct { ref members, .. } => {
                let mut firsts = Vec::with_capacity(members.len());
                let mut total = Some(0u32);
                for m in members {
                    firsts.push(total.unwrap_or(0));
                    total = match (total, known(m.ty)) {
                        (Some(t), Some(n)) => t.checked_add(n).filter(|&s| s <= MAX_LEAVES),
                        _ => None,
                    };
                }
                (total, firsts)
            }
            TypeInner::Array {
                base,
                size: ArraySize::Constant(n),
                ..
            } => {
                let total = known(base)
                    .and_then(|b| b.checked_mul(n.get()))
                    .filter(|&s| s <= MAX_LEAVES);
                (total, Vec::new())
            }
            _ => (None, Vec::new()),
        }
    }

    /// The name of a type, for messages.
    pub fn name(&self, ty: Ty) -> String {
        match ty {
            Ty::H(h) => match &self.module.types[h] {
                Type { name: Some(n), .. } => n.clone(),
                t => format!("{:?}", t.inner),
            },
            other => format!("{other:?}"),
        }
    }

    /// What `ty` is made of, or an error naming a type the writer does not support.
    pub fn shape(&self, ty: Ty) -> Result<Shape<'a>, Error> {
        let h = match ty {
            Ty::S(s) => return Ok(Shape::Scalar(s)),
            Ty::V(n, s) => return Ok(Shape::Vector(n, s)),
            Ty::M { cols, rows } => return Ok(Shape::Matrix { cols, rows }),
            Ty::H(h) => h,
        };
        let module = self.module;
        match module.types[h].inner {
            TypeInner::Scalar(s) => Ok(Shape::Scalar(Sc::of(s)?)),
            TypeInner::Vector { size, scalar } => Ok(Shape::Vector(size as u32, Sc::of(scalar)?)),
            TypeInner::Matrix {
                columns,
                rows,
                scalar,
            } => match Sc::of(scalar)? {
                Sc::F32 => Ok(Shape::Matrix {
                    cols: columns as u32,
                    rows: rows as u32,
                }),
                _ => Err(Error::Unsupported(
                    "matrices of other scalars than f32".into(),
                )),
            },
            TypeInner::Struct { ref members, .. } => Ok(Shape::Struct(h, members)),
            TypeInner::Array { base, size, stride } => {
                let len = match size {
                    ArraySize::Constant(n) => Some(n.get()),
                    ArraySize::Dynamic => None,
                    ArraySize::Pending(_) => {
                        return Err(Error::Unsupported(
                            "arrays sized by a pipeline override".into(),
                        ))
                    }
                };
                Ok(Shape::Array { base, len, stride })
            }
            ref other => Err(Error::Unsupported(format!("the type {}", type_kind(other)))),
        }
    }

    /// How many scalar registers a value of `ty` takes.
    pub fn leaves(&self, ty: Ty) -> Result<u32, Error> {
        match ty {
            Ty::S(_) => Ok(1),
            Ty::V(n, _) => Ok(n),
            Ty::M { cols, rows } => Ok(cols * rows),
            Ty::H(h) => match self.leaves.get(h.index()).copied().flatten() {
                Some(n) => Ok(n),
                None => {
                    self.shape(ty)?;
                    Err(Error::Unsupported(format!(
                        "the type `{}` as a value",
                        self.name(ty)
                    )))
                }
            },
        }
    }

    /// The first leaf of member `i` of struct `h`.
    pub fn member_first(&self, h: Handle<Type>, i: usize) -> u32 {
        self.firsts
            .get(h.index())
            .and_then(|f| f.get(i))
            .copied()
            .unwrap_or(0)
    }

    /// The scalar of each leaf of `ty`, in order.
    pub fn scalars(&self, ty: Ty, out: &mut Vec<Sc>) -> Result<(), Error> {
        match self.shape(ty)? {
            Shape::Scalar(s) => out.push(s),
            Shape::Vector(n, s) => out.extend((0..n).map(|_| s)),
            Shape::Matrix { cols, rows } => out.extend((0..cols * rows).map(|_| Sc::F32)),
            Shape::Struct(_, members) => {
                for m in members {
                    self.scalars(Ty::H(m.ty), out)?;
                }
            }
            Shape::Array {
                base, len: Some(n), ..
            } => {
                self.leaves(ty)?;
                for _ in 0..n {
                    self.scalars(Ty::H(base), out)?;
                }
            }
            Shape::Array { len: None, .. } => {
                return Err(Error::Unsupported(
                    "a runtime-sized array as a value".into(),
                ))
            }
        }
        Ok(())
    }

    /// The zero of `ty`, leaf by leaf.
    pub fn zeros(&self, ty: Ty) -> Result<Leaves, Error> {
        let mut scs = Vec::new();
        self.scalars(ty, &mut scs)?;
        Ok(scs.into_iter().map(Sc::zero).collect())
    }

    /// Where each leaf of `ty`, stored at byte `offset`, lives: in leaf order, grouped
    /// into vector loads where the WGSL layout guarantees their alignment.
    pub fn chunks(&self, ty: Ty, offset: u32, out: &mut Vec<Chunk>) -> Result<(), Error> {
        match self.shape(ty)? {
            Shape::Scalar(sc) => out.push(Chunk { offset, sc, n: 1 }),
            Shape::Vector(n, sc) => vector_chunks(n, sc, offset, out),
            Shape::Matrix { cols, rows } => {
                let stride = if rows == 2 { 8 } else { 16 };
                for c in 0..cols {
                    vector_chunks(rows, Sc::F32, offset + c * stride, out);
                }
            }
            Shape::Struct(_, members) => {
                for m in members {
                    self.chunks(Ty::H(m.ty), offset + m.offset, out)?;
                }
            }
            Shape::Array {
                base,
                len: Some(n),
                stride,
            } => {
                self.leaves(ty)?;
                for i in 0..n {
                    self.chunks(Ty::H(base), offset + i * stride, out)?;
                }
            }
            Shape::Array { len: None, .. } => {
                return Err(Error::Unsupported(
                    "a runtime-sized array as a value".into(),
                ))
            }
        }
        Ok(())
    }

    /// The size in bytes of a value of `ty` in memory.
    pub fn size(&self, ty: Ty) -> u32 {
        match ty {
            Ty::H(h) => self.module.types[h].inner.size(self.module.to_ctx()),
            Ty::S(s) => s.bytes(),
            Ty::V(n, s) => n * s.bytes(),
            Ty::M { cols, rows } => cols * if rows == 2 { 8 } else { 16 },
        }
    }

    /// An expression's type as naga's validator resolved it.
    pub fn resolve(&self, r: &TypeResolution) -> Result<Resolved, Error> {
        let inner = match *r {
            TypeResolution::Handle(h) => match self.module.types[h].inner {
                TypeInner::Pointer { base, .. } => return Ok(Resolved::Pointer(Ty::H(base))),
                _ => return Ok(Resolved::Value(Ty::H(h))),
            },
            TypeResolution::Value(ref inner) => inner,
        };
        match *inner {
            TypeInner::Scalar(s) => Ok(Resolved::Value(Ty::S(Sc::of(s)?))),
            TypeInner::Vector { size, scalar } => {
                Ok(Resolved::Value(Ty::V(size as u32, Sc::of(scalar)?)))
            }
            TypeInner::Matrix {
                columns,
                rows,
                scalar,
            } if Sc::of(scalar)? == Sc::F32 => Ok(Resolved::Value(Ty::M {
                cols: columns as u32,
                rows: rows as u32,
            })),
            TypeInner::Pointer { base, .. } => Ok(Resolved::Pointer(Ty::H(base))),
            TypeInner::ValuePointer {
                size: None, scalar, ..
            } => Ok(Resolved::Pointer(Ty::S(Sc::of(scalar)?))),
            TypeInner::ValuePointer {
                size: Some(n),
                scalar,
                ..
            } => Ok(Resolved::Pointer(Ty::V(n as u32, Sc::of(scalar)?))),
            ref other => Err(Error::Unsupported(format!("the type {}", type_kind(other)))),
        }
    }

    /// The scalar and width (1 for scalars) of a scalar or vector type.
    pub fn scalar_vector(&self, ty: Ty) -> Result<(Sc, u32), Error> {
        match self.shape(ty)? {
            Shape::Scalar(s) => Ok((s, 1)),
            Shape::Vector(n, s) => Ok((s, n)),
            _ => Err(Error::Invalid(format!(
                "expected a scalar or vector, found `{}`",
                self.name(ty)
            ))),
        }
    }
}

fn vector_chunks(n: u32, sc: Sc, offset: u32, out: &mut Vec<Chunk>) {
    match (n, sc) {
        (_, Sc::Bool) => out.extend((0..n).map(|i| Chunk {
            offset: offset + i,
            sc,
            n: 1,
        })),
        (2 | 4, _) => out.push(Chunk { offset, sc, n }),
        (3, _) => {
            out.push(Chunk { offset, sc, n: 2 });
            out.push(Chunk {
                offset: offset + 8,
                sc,
                n: 1,
            });
        }
        _ => out.extend((0..n).map(|i| Chunk {
            offset: offset + 4 * i,
            sc,
            n: 1,
        })),
    }
}

/// A short name for a kind of type, for messages.
pub(super) fn type_kind(inner: &TypeInner) -> &'static str {
    match inner {
        TypeInner::Scalar(_) => "scalar",
        TypeInner::Vector { .. } => "vector",
        TypeInner::Matrix { .. } => "matrix",
        TypeInner::CooperativeMatrix { .. } => "cooperative matrix",
        TypeInner::Atomic(_) => "atomic",
        TypeInner::Pointer { .. } | TypeInner::ValuePointer { .. } => "pointer",
        TypeInner::Array { .. } => "array",
        TypeInner::Struct { .. } => "struct",
        TypeInner::Image { .. } => "texture",
        TypeInner::Sampler { .. } => "sampler",
        TypeInner::AccelerationStructure { .. } => "acceleration structure",
        TypeInner::RayQuery { .. } => "ray query",
        TypeInner::BindingArray { .. } => "binding array",
    }
}
