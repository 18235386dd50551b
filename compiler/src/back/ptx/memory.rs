//! Pointers: stepping into members and elements (with run-time indices clamped into
//! fixed-size arrays and vectors), and loading and storing whole values through them,
//! from memory (vector loads where the layout allows) or from register variables.

use super::emit::Leaves;
use super::emit::{ins, Class, Op, Reg};
use super::types::{Chunk, Sc, Shape, Ty};
use super::writer::{Fw, Loc, Ptr, Space};
use super::Error;
use smallvec::smallvec;

impl Fw<'_, '_> {
    /// The pointer to member, element or component `i` of what `p` points to.
    pub fn ptr_index(&mut self, p: &Ptr, i: u32) -> Result<Ptr, Error> {
        let types = &self.cx.types;
        let (ty, bytes, leaves) = match types.shape(p.ty)? {
            Shape::Struct(h, members) => {
                let m = members.get(i as usize).ok_or_else(|| bad_index(i))?;
                (Ty::H(m.ty), m.offset, types.member_first(h, i as usize))
            }
            Shape::Array { base, len, stride } => {
                let i = len.map_or(i, |n| i.min(n - 1));
                let leaves = if matches!(p.loc, Loc::Mem { .. }) {
                    0
                } else {
                    i * types.leaves(Ty::H(base))?
                };
                (Ty::H(base), i * stride, leaves)
            }
            Shape::Vector(n, sc) => {
                let i = i.min(n - 1);
                (Ty::S(sc), i * sc.bytes(), i)
            }
            Shape::Matrix { cols, rows } => {
                let i = i.min(cols - 1);
                (Ty::V(rows, Sc::F32), i * col_stride(rows), i * rows)
            }
            Shape::Scalar(_) => return Err(Error::Invalid("an index into a scalar".into())),
        };
        let loc = match p.loc {
            Loc::Mem {
                space,
                base,
                offset,
            } => Loc::Mem {
                space,
                base,
                offset: offset + bytes,
            },
            Loc::Var { var, first } => Loc::Var {
                var,
                first: first + leaves,
            },
            Loc::VarElem { .. } => {
                return Err(Error::Invalid("an index into a vector component".into()))
            }
        };
        Ok(Ptr { loc, ty })
    }

    /// The pointer to element or component `index` (a run-time value) of what `p`
    /// points to; the index is clamped into fixed-size arrays and vectors.
    pub fn ptr_access(&mut self, p: &Ptr, index: Op) -> Result<Ptr, Error> {
        match index {
            Op::U32(i) => return self.ptr_index(p, i),
            Op::I32(i) => return self.ptr_index(p, u32::try_from(i).unwrap_or(u32::MAX)),
            _ => {}
        }
        let (ty, len, stride) = match self.cx.types.shape(p.ty)? {
            Shape::Array { base, len, stride } => (Ty::H(base), len, stride),
            Shape::Vector(n, sc) => (Ty::S(sc), Some(n), sc.bytes()),
            Shape::Matrix { cols, rows } => (Ty::V(rows, Sc::F32), Some(cols), col_stride(rows)),
            _ => {
                return Err(Error::Invalid(
                    "a run-time index into a scalar or struct".into(),
                ))
            }
        };
        let index = match len {
            Some(n) => self.bin("min.u32", Class::B32, index, Op::U32(n - 1)),
            None => index,
        };
        let loc = match p.loc {
            Loc::Mem {
                space,
                base,
                offset,
            } => {
                let b = self.out.reg(Class::B64);
                ins!(self.out, "mad.wide.u32 {b}, {index}, {stride}, {base};");
                Loc::Mem {
                    space,
                    base: b,
                    offset,
                }
            }
            Loc::Var { var, first } if matches!(ty, Ty::S(_)) => Loc::VarElem {
                var,
                first,
                len: len.unwrap_or(1),
                index,
            },
            _ => {
                return Err(Error::Invalid(
                    "a run-time index into an array held in registers".into(),
                ))
            }
        };
        Ok(Ptr { loc, ty })
    }

    /// The value `p` points to, leaf by leaf, in fresh registers.
    pub fn load(&mut self, p: &Ptr) -> Result<Leaves, Error> {
        match p.loc {
            Loc::Mem {
                space,
                base,
                offset,
            } => self.load_mem(space, base, offset, p.ty),
            Loc::Var { var, first } => {
                let n = self.cx.types.leaves(p.ty)?;
                let src = self.var_slice(var, first, n)?;
                Ok(src.into_iter().map(|o| self.copy(o)).collect())
            }
            Loc::VarElem {
                var,
                first,
                len,
                index,
            } => {
                let src = self.var_slice(var, first, len)?;
                let sc = src.first().map_or(Sc::F32, |&o| sc_of(o));
                Ok(smallvec![self.select_index(sc, &src, index)])
            }
        }
    }

    /// Stores the value `v` where `p` points.
    pub fn store(&mut self, p: &Ptr, v: &[Op]) -> Result<(), Error> {
        match p.loc {
            Loc::Mem {
                space,
                base,
                offset,
            } => self.store_mem(space, base, offset, p.ty, v),
            Loc::Var { var, first } => {
                let dst = self.var_slice(var, first, v.len() as u32)?;
                dst.iter().zip(v).try_for_each(|(&d, &s)| self.mov_to(d, s))
            }
            Loc::VarElem {
                var,
                first,
                len,
                index,
            } => {
                let dst = self.var_slice(var, first, len)?;
                let value = *v
                    .first()
                    .ok_or_else(|| Error::Invalid("an empty store".into()))?;
                for (k, &d) in dst.iter().enumerate() {
                    let hit = self.setp("eq.u32", index, Op::U32(k as u32));
                    let sc = sc_of(d);
                    let new = self.selp(sc, value, d, hit);
                    self.mov_to(d, new)?;
                }
                Ok(())
            }
        }
    }

    fn var_slice(&self, var: usize, first: u32, n: u32) -> Result<Leaves, Error> {
        let regs = self
            .vars
            .get(var)
            .ok_or_else(|| Error::Invalid("an unknown variable".into()))?;
        regs.get(first as usize..(first + n) as usize)
            .map(Leaves::from_slice)
            .ok_or_else(|| Error::Invalid("an access past the end of a variable".into()))
    }

    /// A copy of `o` in a fresh register (a load must not change when the variable does).
    fn copy(&mut self, o: Op) -> Op {
        match o {
            Op::Reg(r) => self.mov(r.class, o),
            imm => imm,
        }
    }

    /// `elems[index]`, by comparisons; an index past the end selects the last element.
    pub fn select_index(&mut self, sc: Sc, elems: &[Op], index: Op) -> Op {
        let Some((&last, rest)) = elems.split_last() else {
            return sc.zero();
        };
        let mut acc = last;
        for (k, &e) in rest.iter().enumerate().rev() {
            let hit = self.setp("eq.u32", index, Op::U32(k as u32));
            acc = self.selp(sc, e, acc, hit);
        }
        acc
    }

    fn load_mem(&mut self, space: Space, base: Reg, offset: u32, ty: Ty) -> Result<Leaves, Error> {
        let mut chunks = Vec::new();
        self.cx.types.chunks(ty, offset, &mut chunks)?;
        let mut out = Leaves::with_capacity(chunks.len());
        for c in chunks {
            self.load_chunk(space, base, c, &mut out);
        }
        Ok(out)
    }

    fn load_chunk(&mut self, space: Space, base: Reg, c: Chunk, out: &mut Leaves) {
        let addr = address(base, c.offset);
        let sp = space.ld();
        if c.sc == Sc::Bool {
            let b = self.out.reg(Class::B16);
            ins!(self.out, "ld.{sp}.u8 {b}, {addr};");
            out.push(self.setp("ne.u16", Op::Reg(b), Op::U32(0)));
            return;
        }
        let regs: Vec<Op> = (0..c.n).map(|_| Op::Reg(self.fresh(c.sc))).collect();
        let mem = c.sc.mem();
        let (v, dst) = vector(&regs);
        ins!(self.out, "ld.{sp}{v}.{mem} {dst}, {addr};");
        out.extend(regs);
    }

    fn store_mem(
        &mut self,
        space: Space,
        base: Reg,
        offset: u32,
        ty: Ty,
        v: &[Op],
    ) -> Result<(), Error> {
        let mut chunks = Vec::new();
        self.cx.types.chunks(ty, offset, &mut chunks)?;
        let mut at = 0usize;
        for c in chunks {
            let vals = v
                .get(at..at + c.n as usize)
                .ok_or_else(|| Error::Invalid("a store of the wrong size".into()))?;
            at += c.n as usize;
            self.store_chunk(space, base, c, vals);
        }
        Ok(())
    }

    fn store_chunk(&mut self, space: Space, base: Reg, c: Chunk, vals: &[Op]) {
        let addr = address(base, c.offset);
        let sp = space.st();
        if c.sc == Sc::Bool {
            let b = match vals[0] {
                Op::Bool(x) => Op::U32(u32::from(x)),
                p => {
                    let d = self.out.reg(Class::B16);
                    ins!(self.out, "selp.u16 {d}, 1, 0, {p};");
                    Op::Reg(d)
                }
            };
            ins!(self.out, "st.{sp}.u8 {addr}, {b};");
            return;
        }
        let mem = c.sc.mem();
        let (v, src) = vector(vals);
        ins!(self.out, "st.{sp}{v}.{mem} {addr}, {src};");
    }
}

/// The width suffix and the operand of a memory access to `ops`: no suffix and the one
/// operand, or `.vN` and the N operands in braces.
fn vector(ops: &[Op]) -> (String, String) {
    match ops {
        [one] => (String::new(), one.to_string()),
        _ => (
            format!(".v{}", ops.len()),
            format!("{{{}}}", join(ops.iter().copied())),
        ),
    }
}

/// The column stride of a matrix with `rows` rows in memory.
fn col_stride(rows: u32) -> u32 {
    if rows == 2 {
        8
    } else {
        16
    }
}

/// `[base+offset]`.
fn address(base: Reg, offset: u32) -> String {
    if offset == 0 {
        format!("[{base}]")
    } else {
        format!("[{base}+{offset}]")
    }
}

/// Operands separated by commas.
pub(super) fn join(ops: impl Iterator<Item = Op>) -> String {
    ops.map(|o| o.to_string()).collect::<Vec<_>>().join(", ")
}

/// The scalar kind a register variable's leaf holds (integers are treated as `u32`,
/// which is all selection needs).
fn sc_of(o: Op) -> Sc {
    match o {
        Op::Reg(r) => match r.class {
            Class::Pred => Sc::Bool,
            Class::F32 => Sc::F32,
            _ => Sc::U32,
        },
        Op::F32(_) => Sc::F32,
        Op::Bool(_) => Sc::Bool,
        Op::I32(_) | Op::U32(_) => Sc::U32,
    }
}

fn bad_index(i: u32) -> Error {
    Error::Invalid(format!("member {i} does not exist"))
}
