//! Expressions: each evaluates, leaf by leaf, to operands (or to a pointer), at the
//! `Emit` that covers it or, for constants, arguments and variables, on entry.

use super::emit::Leaves;
use super::emit::Op;
use super::types::{Sc, Shape, Ty};
use super::writer::{Frame, Fw, Loc, Ptr, Store, Val};
use super::Error;
use naga::{AddressSpace, Expression, GlobalVariable, Handle, Literal};
use smallvec::smallvec;

impl<'a> Fw<'_, 'a> {
    /// Evaluates expression `h` of `f` and records its value.
    pub fn expr(&mut self, f: &mut Frame<'a>, h: Handle<Expression>) -> Result<(), Error> {
        let v = self.eval(f, h)?;
        if let Some(slot) = f.values.get_mut(h.index()) {
            *slot = Some(v);
        }
        Ok(())
    }

    fn eval(&mut self, f: &Frame<'a>, h: Handle<Expression>) -> Result<Val, Error> {
        use Expression as E;
        let data = |v: Leaves| Ok(Val::Data(v));
        match f.func.expressions[h] {
            E::Literal(l) => data(smallvec![literal(l)?]),
            E::Constant(c) => data(self.global_expr(self.cx.module.constants[c].init)?),
            E::ZeroValue(ty) => data(self.cx.types.zeros(Ty::H(ty))?),
            E::Compose { ref components, .. } => {
                let mut out = Leaves::new();
                for &c in components {
                    out.extend_from_slice(self.data(f, c)?);
                }
                data(out)
            }
            E::Splat { size, value } => data(smallvec![self.scalar(f, value)?; size as usize]),
            E::Swizzle {
                size,
                vector,
                pattern,
            } => {
                let v = self.data(f, vector)?;
                let pick = |c: &naga::SwizzleComponent| {
                    v.get(*c as usize).copied().ok_or_else(bad_swizzle)
                };
                data(
                    pattern[..size as usize]
                        .iter()
                        .map(pick)
                        .collect::<Result<_, _>>()?,
                )
            }
            E::AccessIndex { base, index } => self.access_index(f, base, index),
            E::Access { base, index } => self.access(f, base, index),
            E::FunctionArgument(i) => f
                .args
                .get(i as usize)
                .cloned()
                .ok_or_else(|| Error::Invalid("no such argument".into())),
            E::GlobalVariable(g) => self.global_ptr(g).map(Val::Ptr),
            E::LocalVariable(l) => {
                let store = *f
                    .locals
                    .get(l.index())
                    .ok_or_else(|| Error::Invalid("no such local".into()))?;
                Ok(Val::Ptr(Ptr {
                    loc: loc_of(store),
                    ty: Ty::H(f.func.local_variables[l].ty),
                }))
            }
            E::Load { pointer } => {
                let p = self.ptr(f, pointer)?.clone();
                data(self.load(&p)?)
            }
            E::Unary { op, expr } => self.unary(f, op, expr).map(Val::Data),
            E::Binary { op, left, right } => self.binary(f, op, left, right).map(Val::Data),
            E::Select {
                condition,
                accept,
                reject,
            } => self.select(f, condition, accept, reject).map(Val::Data),
            E::Relational { fun, argument } => self.relational(f, fun, argument).map(Val::Data),
            E::Math {
                fun,
                arg,
                arg1,
                arg2,
                arg3,
            } => self
                .math(f, fun, [Some(arg), arg1, arg2, arg3])
                .map(Val::Data),
            E::As {
                expr,
                kind,
                convert,
            } => self.convert(f, expr, kind, convert).map(Val::Data),
            E::CallResult(_) => Err(Error::Invalid("a call result used before its call".into())),
            ref other => Err(Error::Unsupported(expression_name(other).into())),
        }
    }

    /// The single operand of a scalar expression.
    pub fn scalar(&self, f: &Frame, h: Handle<Expression>) -> Result<Op, Error> {
        match self.data(f, h)? {
            [x] => Ok(*x),
            _ => Err(Error::Invalid(format!("expression {h:?} is not a scalar"))),
        }
    }

    /// A constant from the module's global expressions (naga has folded them to
    /// literals, zeros, compositions and splats).
    pub fn global_expr(&self, h: Handle<Expression>) -> Result<Leaves, Error> {
        let module = self.cx.module;
        match module.global_expressions[h] {
            Expression::Literal(l) => Ok(smallvec![literal(l)?]),
            Expression::Constant(c) => self.global_expr(module.constants[c].init),
            Expression::ZeroValue(ty) => self.cx.types.zeros(Ty::H(ty)),
            Expression::Compose { ref components, .. } => {
                let mut out = Leaves::new();
                for &c in components {
                    out.extend(self.global_expr(c)?);
                }
                Ok(out)
            }
            Expression::Splat { size, value } => match self.global_expr(value)?.as_slice() {
                [x] => Ok(smallvec![*x; size as usize]),
                _ => Err(Error::Invalid("a splat of a non-scalar".into())),
            },
            Expression::Override(_) => {
                Err(Error::Unsupported("pipeline-overridable constants".into()))
            }
            ref other => Err(Error::Unsupported(format!(
                "the constant expression {}",
                expression_name(other)
            ))),
        }
    }

    /// A constant expression of `f` (a local variable's initializer), as immediates:
    /// naga has folded it, though an `Emit` may cover it.
    pub fn const_expr(&self, f: &Frame, h: Handle<Expression>) -> Result<Leaves, Error> {
        if let Some(Some(Val::Data(d))) = f.values.get(h.index()) {
            return Ok(d.clone());
        }
        match f.func.expressions[h] {
            Expression::Literal(l) => Ok(smallvec![literal(l)?]),
            Expression::Constant(c) => self.global_expr(self.cx.module.constants[c].init),
            Expression::ZeroValue(ty) => self.cx.types.zeros(Ty::H(ty)),
            Expression::Compose { ref components, .. } => {
                let mut out = Leaves::new();
                for &c in components {
                    out.extend(self.const_expr(f, c)?);
                }
                Ok(out)
            }
            Expression::Splat { size, value } => match self.const_expr(f, value)?.as_slice() {
                [x] => Ok(smallvec![*x; size as usize]),
                _ => Err(Error::Invalid("a splat of a non-scalar".into())),
            },
            ref other => Err(Error::Unsupported(format!(
                "the initializer {}",
                expression_name(other)
            ))),
        }
    }

    /// A pointer to global variable `g`, where this PTX function keeps it.
    fn global_ptr(&self, g: Handle<GlobalVariable>) -> Result<Ptr, Error> {
        let gv = &self.cx.module.global_variables[g];
        let name = gv.name.as_deref().unwrap_or("?");
        match self.globals.get(g.index()).copied().flatten() {
            Some(store) => Ok(Ptr {
                loc: loc_of(store),
                ty: Ty::H(gv.ty),
            }),
            None => Err(match gv.space {
                AddressSpace::Handle => {
                    Error::Unsupported(format!("textures and samplers (global `{name}`)"))
                }
                AddressSpace::WorkGroup => {
                    Error::Unsupported(format!("var<workgroup> (global `{name}`)"))
                }
                AddressSpace::Immediate => {
                    Error::Unsupported(format!("immediate data (global `{name}`)"))
                }
                space => {
                    Error::Unsupported(format!("the address space {space:?} (global `{name}`)"))
                }
            }),
        }
    }

    fn access_index(
        &mut self,
        f: &Frame,
        base: Handle<Expression>,
        index: u32,
    ) -> Result<Val, Error> {
        if let Val::Ptr(p) = self.val(f, base)? {
            let p = p.clone();
            return self.ptr_index(&p, index).map(Val::Ptr);
        }
        let ty = self.ty(f, base)?;
        let (first, n) = self.element_range(ty, index)?;
        let d = self.data(f, base)?;
        d.get(first as usize..(first + n) as usize)
            .map(|s| Val::Data(Leaves::from_slice(s)))
            .ok_or_else(|| Error::Invalid("an index past the end of a value".into()))
    }

    /// The first leaf and leaf count of member or element `i` of a value of `ty`.
    fn element_range(&self, ty: Ty, i: u32) -> Result<(u32, u32), Error> {
        let types = &self.cx.types;
        match types.shape(ty)? {
            Shape::Struct(h, members) => {
                let m = members
                    .get(i as usize)
                    .ok_or_else(|| Error::Invalid("no such member".into()))?;
                Ok((
                    types.member_first(h, i as usize),
                    types.leaves(Ty::H(m.ty))?,
                ))
            }
            Shape::Array {
                base,
                len: Some(len),
                ..
            } => {
                let n = types.leaves(Ty::H(base))?;
                Ok((i.min(len - 1) * n, n))
            }
            Shape::Vector(len, _) => Ok((i.min(len - 1), 1)),
            Shape::Matrix { cols, rows } => Ok((i.min(cols - 1) * rows, rows)),
            _ => Err(Error::Invalid(
                "an index into a scalar or runtime-sized value".into(),
            )),
        }
    }

    fn access(
        &mut self,
        f: &Frame,
        base: Handle<Expression>,
        index: Handle<Expression>,
    ) -> Result<Val, Error> {
        let i = self.scalar(f, index)?;
        if let Val::Ptr(p) = self.val(f, base)? {
            let p = p.clone();
            return self.ptr_access(&p, i).map(Val::Ptr);
        }
        match i {
            Op::U32(k) => return self.access_index(f, base, k),
            Op::I32(k) => return self.access_index(f, base, u32::try_from(k).unwrap_or(u32::MAX)),
            _ => {}
        }
        let ty = self.ty(f, base)?;
        let (elem, count) = match self.cx.types.shape(ty)? {
            Shape::Array {
                base, len: Some(n), ..
            } => (Ty::H(base), n),
            Shape::Vector(n, sc) => (Ty::S(sc), n),
            Shape::Matrix { cols, rows } => (Ty::V(rows, Sc::F32), cols),
            _ => {
                return Err(Error::Invalid(
                    "a run-time index into a scalar or struct".into(),
                ))
            }
        };
        let mut scs = Vec::new();
        self.cx.types.scalars(elem, &mut scs)?;
        let d = self.data(f, base)?;
        let n = scs.len();
        let mut out = Leaves::with_capacity(n);
        for (j, &sc) in scs.iter().enumerate() {
            let column: Leaves = (0..count as usize)
                .filter_map(|k| d.get(k * n + j).copied())
                .collect();
            out.push(self.select_index(sc, &column, i));
        }
        Ok(Val::Data(out))
    }
}

/// The location a variable's storage starts at.
pub(super) fn loc_of(store: Store) -> Loc {
    match store {
        Store::Regs(var) => Loc::Var { var, first: 0 },
        Store::Mem(space, base) => Loc::Mem {
            space,
            base,
            offset: 0,
        },
    }
}

/// The operand of a literal.
pub(super) fn literal(l: Literal) -> Result<Op, Error> {
    match l {
        Literal::F32(x) => Ok(Op::f32(x)),
        Literal::I32(x) => Ok(Op::I32(x)),
        Literal::U32(x) => Ok(Op::U32(x)),
        Literal::Bool(b) => Ok(Op::Bool(b)),
        other => Err(Error::Unsupported(format!(
            "the literal {other:?} (only f32, i32, u32 and bool)"
        ))),
    }
}

fn bad_swizzle() -> Error {
    Error::Invalid("a swizzle past the end of a vector".into())
}

/// The name of an expression kind, for messages.
pub(super) fn expression_name(e: &Expression) -> &'static str {
    use Expression as E;
    match e {
        E::Override(_) => "pipeline-overridable constants (Expression::Override)",
        E::ImageSample { .. } => "texture sampling (Expression::ImageSample)",
        E::ImageLoad { .. } => "texture loads (Expression::ImageLoad)",
        E::ImageQuery { .. } => "texture queries (Expression::ImageQuery)",
        E::Derivative { .. } => "derivatives (Expression::Derivative)",
        E::AtomicResult { .. } => "atomics (Expression::AtomicResult)",
        E::WorkGroupUniformLoadResult { .. } => {
            "workgroupUniformLoad (Expression::WorkGroupUniformLoadResult)"
        }
        E::ArrayLength(_) => "arrayLength (Expression::ArrayLength)",
        E::RayQueryVertexPositions { .. }
        | E::RayQueryProceedResult
        | E::RayQueryGetIntersection { .. } => "ray queries",
        E::SubgroupBallotResult | E::SubgroupOperationResult { .. } => "subgroup operations",
        E::CooperativeLoad { .. } | E::CooperativeMultiplyAdd { .. } => "cooperative matrices",
        _ => "this expression",
    }
}
