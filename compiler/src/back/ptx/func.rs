//! Functions: the kernel (`.entry`) with its buffer parameters and built-in inputs,
//! `.func`s with scalarised parameters and an aggregate return value, inlined calls,
//! and what every function does on entry (variables, constants, arguments).

use super::emit::Leaves;
use super::emit::{ins, Class, Op, Reg};
use super::types::{Sc, Ty};
use super::writer::{Cx, Frame, Fw, Ret, Space, Store, Val};
use super::Error;
use naga::{
    AddressSpace, Binding, BuiltIn, EntryPoint, Expression, Function, GlobalVariable, Handle,
};
use smallvec::smallvec;
use std::fmt::Write;

/// Whether a global variable is read-only for the whole kernel.
fn read_only(g: &GlobalVariable) -> bool {
    match g.space {
        AddressSpace::Uniform => true,
        AddressSpace::Storage { access } => !access.contains(naga::StorageAccess::STORE),
        _ => false,
    }
}

/// Global `g`'s buffer, at the address in `base`, for the function `fw` writes: read through
/// the read-only path where the kernel never stores to it.
fn bind_buffer(fw: &mut Fw, g: Handle<GlobalVariable>, base: Reg) {
    let space = if read_only(&fw.cx.module.global_variables[g]) {
        Space::GlobalRo
    } else {
        Space::Global
    };
    fw.globals[g.index()] = Some(Store::Mem(space, base));
}

/// The PTX type of one leaf in a parameter (booleans travel as `b32`).
fn param_ty(sc: Sc) -> &'static str {
    if sc == Sc::F32 {
        "f32"
    } else {
        "b32"
    }
}

impl<'c, 'a> Fw<'c, 'a> {
    /// Translates `f`'s body: variables, entry-time expressions, then statements.
    pub fn run(&mut self, f: &mut Frame<'a>, mem_locals: &[bool]) -> Result<(), Error> {
        let name = f.name.clone();
        self.out.comment(format_args!("fn {name}"));
        self.run_body(f, mem_locals)
            .map_err(|e| e.in_function(&name))
    }

    fn run_body(&mut self, f: &mut Frame<'a>, mem_locals: &[bool]) -> Result<(), Error> {
        let func = f.func;
        for (h, lv) in func.local_variables.iter() {
            let name = lv.name.as_deref().unwrap_or("local");
            let store = self.alloc(
                Ty::H(lv.ty),
                mem_locals.get(h.index()).copied().unwrap_or(false),
                name,
            )?;
            f.locals.push(store);
        }
        let emitted = super::analysis::emitted(func);
        for (h, e) in func.expressions.iter() {
            if !emitted[h.index()] && !is_statement_result(e) {
                self.expr(f, h)?;
            }
        }
        for (h, lv) in func.local_variables.iter() {
            let value = match lv.init {
                Some(init) => self.const_expr(f, init)?,
                None => self.cx.types.zeros(Ty::H(lv.ty))?,
            };
            let store = f.locals[h.index()];
            self.init(store, Ty::H(lv.ty), &value)?;
        }
        self.block(f, &func.body)
    }

    /// Storage for a variable of `ty`: `.local` memory if `mem`, else registers.
    fn alloc(&mut self, ty: Ty, mem: bool, name: &str) -> Result<Store, Error> {
        if mem {
            let size = self.cx.types.size(ty);
            let array = self.out.local_array(size, &ident(name));
            let base = self.out.reg(Class::B64);
            ins!(self.out, "mov.u64 {base}, {array};");
            return Ok(Store::Mem(Space::Local, base));
        }
        let mut scs = Vec::new();
        self.cx.types.scalars(ty, &mut scs)?;
        Ok(Store::Regs(self.new_var(&scs, None)?))
    }

    /// Gives a variable its first value.
    fn init(&mut self, store: Store, ty: Ty, value: &[Op]) -> Result<(), Error> {
        if let Store::Mem(space, base) = store {
            if value
                .iter()
                .all(|o| matches!(o, Op::F32(0) | Op::I32(0) | Op::U32(0) | Op::Bool(false)))
            {
                self.zero_fill(space, base, self.cx.types.size(ty));
                return Ok(());
            }
        }
        let p = super::writer::Ptr {
            loc: super::expr::loc_of(store),
            ty,
        };
        self.store(&p, value)
    }

    /// Zeroes `size` bytes (rounded up to 16, as `.local` arrays are) at `base`: by
    /// 16-byte stores, in a loop where there are many.
    fn zero_fill(&mut self, space: Space, base: Reg, size: u32) {
        let words = size.div_ceil(16);
        let sp = space.st();
        if words <= 8 {
            for i in 0..words {
                ins!(
                    self.out,
                    "st.{sp}.v4.u32 [{base}+{}], {{0, 0, 0, 0}};",
                    16 * i
                );
            }
            return;
        }
        let (addr, end) = (self.out.reg(Class::B64), self.out.reg(Class::B64));
        let top = self.out.label("zero_fill");
        ins!(self.out, "mov.b64 {addr}, {base};");
        ins!(self.out, "add.s64 {end}, {base}, {};", 16 * words);
        self.out.place(&top);
        ins!(self.out, "st.{sp}.v4.u32 [{addr}], {{0, 0, 0, 0}};");
        ins!(self.out, "add.s64 {addr}, {addr}, 16;");
        let more = self.setp("lt.u64", Op::Reg(addr), Op::Reg(end));
        ins!(self.out, "@{more} bra {top};");
    }

    /// Stores leaf `x` at `offset` in the aggregate parameter `param`.
    pub fn store_param(&mut self, param: &str, offset: u32, x: Op) {
        let x = self.param_leaf(x);
        let ty = if is_f32(x) { "f32" } else { "b32" };
        ins!(self.out, "st.param.{ty} [{param}+{offset}], {x};");
    }

    /// A leaf as it travels in a parameter: booleans become 0 or 1.
    fn param_leaf(&mut self, x: Op) -> Op {
        match x {
            Op::Bool(b) => Op::U32(u32::from(b)),
            Op::Reg(r) if r.class == Class::Pred => self.selp(Sc::U32, Op::U32(1), Op::U32(0), x),
            other => other,
        }
    }

    /// Loads a leaf of `sc` from a parameter address (`[name+offset]`).
    fn load_param(&mut self, sc: Sc, addr: &str) -> Op {
        let d = self.out.reg(if sc == Sc::F32 {
            Class::F32
        } else {
            Class::B32
        });
        ins!(self.out, "ld.param.{} {d}, {addr};", param_ty(sc));
        if sc == Sc::Bool {
            return self.setp("ne.b32", Op::Reg(d), Op::U32(0));
        }
        Op::Reg(d)
    }

    /// A call statement: inlined, or a `.func` call.
    pub fn call(
        &mut self,
        f: &mut Frame<'a>,
        callee: Handle<Function>,
        args: &[Handle<Expression>],
        result: Option<Handle<Expression>>,
    ) -> Result<(), Error> {
        let name = self
            .cx
            .names
            .get(callee.index())
            .cloned()
            .unwrap_or_default();
        let values: Vec<Val> = args
            .iter()
            .map(|&a| self.val(f, a).cloned())
            .collect::<Result<_, _>>()?;
        let v = if self
            .cx
            .an
            .inline
            .get(callee.index())
            .copied()
            .unwrap_or(false)
        {
            self.out.comment(format_args!("inlined call of {name}"));
            self.inline(callee, values)?
        } else {
            self.out.comment(format_args!("call {name}"));
            self.call_func(callee, &name, &values)?
        };
        if let (Some(r), Some(v)) = (result, v) {
            if let Some(slot) = f.values.get_mut(r.index()) {
                *slot = Some(Val::Data(v));
            }
        }
        Ok(())
    }

    fn inline(
        &mut self,
        callee: Handle<Function>,
        args: Vec<Val>,
    ) -> Result<Option<Leaves>, Error> {
        let cx = self.cx;
        let func = &cx.module.functions[callee];
        let var = match &func.result {
            Some(r) => {
                let mut scs = Vec::new();
                cx.types.scalars(Ty::H(r.ty), &mut scs)?;
                Some(self.new_var(&scs, None)?)
            }
            None => None,
        };
        let end = self.out.label("inline_end");
        let name = func.name.clone().unwrap_or_default();
        let mut frame = Frame::new(
            func,
            &cx.info[callee],
            name,
            args,
            Ret::Inline {
                var,
                end: end.clone(),
            },
        );
        let mem = cx
            .an
            .mem_locals
            .get(callee.index())
            .cloned()
            .unwrap_or_default();
        self.run(&mut frame, &mem)?;
        self.out.place(&end);
        Ok(var.and_then(|v| self.vars.get(v).cloned()))
    }

    fn call_func(
        &mut self,
        callee: Handle<Function>,
        name: &str,
        args: &[Val],
    ) -> Result<Option<Leaves>, Error> {
        let cx = self.cx;
        let func = &cx.module.functions[callee];
        self.out.raw("\t{\n");
        let mut params = Vec::new();
        for &g in &buffers_used(cx, callee) {
            let base = match self.globals.get(g.index()).copied().flatten() {
                Some(Store::Mem(_, base)) => base,
                _ => return Err(Error::Invalid("a buffer without an address".into())),
            };
            let p = format!("param{}", params.len());
            ins!(self.out, ".param .b64 {p};");
            ins!(self.out, "st.param.b64 [{p}], {base};");
            params.push(p);
        }
        for a in args {
            let Val::Data(d) = a else {
                return Err(Error::Invalid("a pointer argument to a .func".into()));
            };
            for &x in d {
                let x = self.param_leaf(x);
                let p = format!("param{}", params.len());
                let ty = if is_f32(x) { "f32" } else { "b32" };
                ins!(self.out, ".param .{ty} {p};");
                ins!(self.out, "st.param.{ty} [{p}], {x};");
                params.push(p);
            }
        }
        let mut result = None;
        let ret = match &func.result {
            Some(r) => {
                let mut scs = Vec::new();
                cx.types.scalars(Ty::H(r.ty), &mut scs)?;
                ins!(
                    self.out,
                    ".param .align 4 .b8 retval0[{}];",
                    4 * scs.len().max(1)
                );
                result = Some(scs);
                "(retval0), "
            }
            None => "",
        };
        ins!(self.out, "call {ret}{name}, ({});", params.join(", "));
        let v = result.map(|scs| {
            scs.iter()
                .enumerate()
                .map(|(i, &sc)| self.load_param(sc, &format!("[retval0+{}]", 4 * i)))
                .collect()
        });
        self.out.raw("\t}\n");
        Ok(v)
    }
}

/// The buffers a function reads or writes (its hidden leading parameters).
fn buffers_used(cx: &Cx, h: Handle<Function>) -> Vec<Handle<GlobalVariable>> {
    let fi = &cx.info[h];
    cx.buffers
        .iter()
        .copied()
        .filter(|&g| !fi[g].is_empty())
        .collect()
}

/// Results of statements, which get their values when the statement runs.
fn is_statement_result(e: &Expression) -> bool {
    matches!(
        e,
        Expression::CallResult(_)
            | Expression::AtomicResult { .. }
            | Expression::WorkGroupUniformLoadResult { .. }
            | Expression::RayQueryProceedResult
            | Expression::SubgroupBallotResult
            | Expression::SubgroupOperationResult { .. }
    )
}

fn ends_in_return(b: &naga::Block) -> bool {
    matches!(b.last(), Some(naga::Statement::Return { .. }))
}

fn is_f32(x: Op) -> bool {
    matches!(x, Op::F32(_)) || matches!(x, Op::Reg(r) if r.class == Class::F32)
}

/// `name` with every character PTX does not allow in an identifier replaced by `_`.
pub(super) fn ident(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// A `.func` for naga function `h`.
pub(super) fn write_func(cx: &Cx, h: Handle<Function>) -> Result<String, Error> {
    let func = &cx.module.functions[h];
    let name = cx.names.get(h.index()).cloned().unwrap_or_default();
    let mut fw = Fw::new(cx);
    let mut params = Vec::new();
    for g in buffers_used(cx, h) {
        let p = format!("{name}_param_{}", params.len());
        let base = fw.out.reg(Class::B64);
        ins!(fw.out, "ld.param.b64 {base}, [{p}];");
        bind_buffer(&mut fw, g, base);
        params.push(format!(".param .b64 {p}"));
    }
    let mut args = Vec::with_capacity(func.arguments.len());
    for a in &func.arguments {
        let mut scs = Vec::new();
        cx.types.scalars(Ty::H(a.ty), &mut scs)?;
        let mut leaves = Leaves::with_capacity(scs.len());
        for sc in scs {
            let p = format!("{name}_param_{}", params.len());
            leaves.push(fw.load_param(sc, &format!("[{p}]")));
            params.push(format!(".param .{} {p}", param_ty(sc)));
        }
        args.push(Val::Data(leaves));
    }
    let (ret_decl, ret) = match &func.result {
        Some(r) => {
            let param = format!("{name}_retval");
            let n = cx.types.leaves(Ty::H(r.ty))?;
            (
                format!("(.param .align 4 .b8 {param}[{}]) ", 4 * n.max(1)),
                Ret::Func { param },
            )
        }
        None => (
            String::new(),
            Ret::Func {
                param: String::new(),
            },
        ),
    };
    let fname = func.name.clone().unwrap_or_default();
    let mut frame = Frame::new(func, &cx.info[h], fname.clone(), args, ret);
    let mem = cx.an.mem_locals.get(h.index()).cloned().unwrap_or_default();
    fw.run(&mut frame, &mem)?;
    if !ends_in_return(&func.body) {
        ins!(fw.out, "ret;");
    }
    let mut s = format!(
        "// fn {}\n.func {ret_decl}{name}(",
        super::emit::ascii(&fname)
    );
    s.push_str(&params.join(", "));
    s.push_str(")\n{\n");
    s.push_str(&fw.out.finish());
    s.push_str("}\n");
    Ok(s)
}

/// The `.entry` for the entry point.
pub(super) fn write_kernel(cx: &Cx, ep: &EntryPoint, index: usize) -> Result<String, Error> {
    let info = cx.info.get_entry_point(index);
    let mut fw = Fw::new(cx);
    let name = &ep.name;
    let mut params = Vec::new();
    for (&g, param) in cx.buffers.iter().zip(&cx.params) {
        let p = &param.name;
        params.push(format!(".param .{} {p}", param.ty));
        if info[g].is_empty() {
            continue;
        }
        let raw = fw.out.reg(Class::B64);
        let base = fw.out.reg(Class::B64);
        ins!(fw.out, "ld.param.u64 {raw}, [{p}];");
        ins!(fw.out, "cvta.to.global.u64 {base}, {raw};");
        bind_buffer(&mut fw, g, base);
    }
    fw.privates(info)?;
    let mut args = Vec::with_capacity(ep.function.arguments.len());
    for a in &ep.function.arguments {
        args.push(Val::Data(fw.input(a.binding.as_ref(), a.ty)?));
    }
    let mut frame = Frame::new(&ep.function, info, name.clone(), args, Ret::Kernel);
    fw.run(&mut frame, &cx.an.entry_mem_locals)?;
    if !ends_in_return(&ep.function.body) {
        ins!(fw.out, "ret;");
    }
    let [x, y, z] = ep.workgroup_size;
    let mut s = String::new();
    // No .reqntid: ptxas reads a small block as a call for many blocks per SM and caps
    // the registers (spilling); the launch uses the workgroup size as the block.
    let _ = writeln!(
        s,
        "// entry point {name}, workgroup size ({x}, {y}, {z}): launch with this block"
    );
    let _ = write!(
        s,
        ".visible .entry {name}(\n\t{}\n)\n{{\n",
        params.join(",\n\t")
    );
    s.push_str(&fw.out.finish());
    s.push_str("}\n");
    Ok(s)
}

impl Fw<'_, '_> {
    /// Gives each `var<private>` the entry point uses its storage and first value.
    fn privates(&mut self, info: &naga::valid::FunctionInfo) -> Result<(), Error> {
        let cx = self.cx;
        for (g, gv) in cx.module.global_variables.iter() {
            if gv.space != AddressSpace::Private || info[g].is_empty() {
                continue;
            }
            let ty = Ty::H(gv.ty);
            let name = gv.name.as_deref().unwrap_or("private");
            let store = self.alloc(
                ty,
                cx.an.mem_privates.get(g.index()).copied().unwrap_or(false),
                name,
            )?;
            let value = match gv.init {
                Some(init) => self.global_expr(init)?,
                None => cx.types.zeros(ty)?,
            };
            self.init(store, ty, &value)?;
            self.globals[g.index()] = Some(store);
        }
        Ok(())
    }

    /// The value of a kernel input: a built-in, or a struct of built-ins.
    fn input(
        &mut self,
        binding: Option<&Binding>,
        ty: Handle<naga::Type>,
    ) -> Result<Leaves, Error> {
        match binding {
            Some(Binding::BuiltIn(b)) => self.builtin(*b),
            Some(Binding::Location { .. }) => Err(Error::Unsupported(
                "location inputs to a compute shader".into(),
            )),
            None => match &self.cx.module.types[ty].inner {
                naga::TypeInner::Struct { members, .. } => {
                    let mut out = Leaves::new();
                    for m in members {
                        out.extend(self.input(m.binding.as_ref(), m.ty)?);
                    }
                    Ok(out)
                }
                _ => Err(Error::Invalid("a kernel input without a binding".into())),
            },
        }
    }

    fn special(&mut self, reg: &str) -> Op {
        let d = self.out.reg(Class::B32);
        ins!(self.out, "mov.u32 {d}, {reg};");
        Op::Reg(d)
    }

    fn builtin(&mut self, b: BuiltIn) -> Result<Leaves, Error> {
        let xyz = ["x", "y", "z"];
        Ok(match b {
            BuiltIn::LocalInvocationId => xyz
                .iter()
                .map(|c| self.special(&format!("%tid.{c}")))
                .collect(),
            BuiltIn::WorkGroupId => xyz
                .iter()
                .map(|c| self.special(&format!("%ctaid.{c}")))
                .collect(),
            BuiltIn::NumWorkGroups => xyz
                .iter()
                .map(|c| self.special(&format!("%nctaid.{c}")))
                .collect(),
            BuiltIn::GlobalInvocationId => {
                let mut out = Leaves::with_capacity(3);
                for c in xyz {
                    let id = self.special(&format!("%ctaid.{c}"));
                    let n = self.special(&format!("%ntid.{c}"));
                    let t = self.special(&format!("%tid.{c}"));
                    out.push(self.tri("mad.lo.u32", Class::B32, id, n, t));
                }
                out
            }
            BuiltIn::LocalInvocationIndex => {
                let (x, y, z) = (
                    self.special("%tid.x"),
                    self.special("%tid.y"),
                    self.special("%tid.z"),
                );
                let (nx, ny) = (self.special("%ntid.x"), self.special("%ntid.y"));
                let zy = self.tri("mad.lo.u32", Class::B32, z, ny, y);
                smallvec![self.tri("mad.lo.u32", Class::B32, zy, nx, x)]
            }
            BuiltIn::SubgroupInvocationId => smallvec![self.special("%laneid")],
            BuiltIn::SubgroupSize => smallvec![Op::U32(32)],
            other => return Err(Error::Unsupported(format!("the built-in input {other:?}"))),
        })
    }
}
