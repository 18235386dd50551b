//! The state of the writer: the module-wide context, the PTX function being written,
//! the naga function being translated into it (a frame: several frames share one PTX
//! function where calls are inlined), and the values expressions evaluate to.

use super::analysis::Analysis;
use super::emit::{ins, Class, Label, Leaves, Op, Out, Reg};
use super::types::{Resolved, Sc, Ty, Types};
use super::Error;
use naga::valid::{FunctionInfo, ModuleInfo};
use naga::{Expression, Function, GlobalVariable, Handle, Module};
use std::cell::Cell;

/// Module-wide facts shared by every function's writer.
#[derive(Debug)]
pub(super) struct Cx<'a> {
    pub module: &'a Module,
    pub info: &'a ModuleInfo,
    pub types: Types<'a>,
    pub an: Analysis,
    /// The uniform and storage buffers in kernel-parameter order (group, binding).
    pub buffers: Vec<Handle<GlobalVariable>>,
    /// The kernel's parameter for each of `buffers`.
    pub params: Vec<super::Param>,
    /// The PTX name of each function.
    pub names: Vec<String>,
    /// Whether some function needs the large-argument trigonometric reduction.
    pub trig_reduce: Cell<bool>,
}

/// A state space that pointers point into.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Space {
    Global,
    /// Global memory that no thread writes during the kernel (uniform and read-only
    /// storage buffers): loaded through the non-coherent cache.
    GlobalRo,
    Local,
}

impl Space {
    pub fn ld(self) -> &'static str {
        match self {
            Space::Global => "global",
            Space::GlobalRo => "global.nc",
            Space::Local => "local",
        }
    }

    pub fn st(self) -> &'static str {
        match self {
            Space::Global | Space::GlobalRo => "global",
            Space::Local => "local",
        }
    }
}

/// Where a variable lives: in registers (an index into the writer's variables) or in
/// memory at an address held in a 64-bit register.
#[derive(Debug, Clone, Copy)]
pub(super) enum Store {
    Regs(usize),
    Mem(Space, Reg),
}

/// Where a pointer points.
#[derive(Debug, Clone)]
pub(super) enum Loc {
    /// `offset` bytes past the address in `base`.
    Mem {
        space: Space,
        base: Reg,
        offset: u32,
    },
    /// The leaves of a register variable from `first` on.
    Var { var: usize, first: u32 },
    /// The component `index` (a run-time value) of the vector of `len` leaves at `first`
    /// of a register variable.
    VarElem {
        var: usize,
        first: u32,
        len: u32,
        index: Op,
    },
}

/// A pointer: where, and to what.
#[derive(Debug, Clone)]
pub(super) struct Ptr {
    pub loc: Loc,
    pub ty: Ty,
}

/// What an expression evaluated to.
#[derive(Debug, Clone)]
pub(super) enum Val {
    /// A value: one operand per leaf.
    Data(Leaves),
    Ptr(Ptr),
}

/// How a `return` leaves the function being translated.
#[derive(Debug, Clone)]
pub(super) enum Ret {
    /// From the kernel: `ret`.
    Kernel,
    /// From a `.func`: the value is stored in the aggregate return parameter.
    Func { param: String },
    /// From an inlined call: the value goes to register variable `var`, then a branch
    /// to `end`.
    Inline { var: Option<usize>, end: Label },
}

/// What `break` and `continue` mean here.
#[derive(Debug, Clone)]
pub(super) enum Target {
    Loop { cont: Label, end: Label },
    Switch { end: Label },
}

/// One naga function being translated (the entry point, a `.func`, or an inlined call).
#[derive(Debug)]
pub(super) struct Frame<'a> {
    pub func: &'a Function,
    pub info: &'a FunctionInfo,
    pub name: String,
    pub values: Vec<Option<Val>>,
    pub locals: Vec<Store>,
    pub args: Vec<Val>,
    pub ret: Ret,
    pub targets: Vec<Target>,
}

impl<'a> Frame<'a> {
    pub fn new(
        func: &'a Function,
        info: &'a FunctionInfo,
        name: String,
        args: Vec<Val>,
        ret: Ret,
    ) -> Self {
        Frame {
            func,
            info,
            name,
            values: vec![None; func.expressions.len()],
            locals: Vec::new(),
            args,
            ret,
            targets: Vec::new(),
        }
    }
}

/// The writer of one PTX function.
#[derive(Debug)]
pub(super) struct Fw<'c, 'a> {
    pub cx: &'c Cx<'a>,
    pub out: Out,
    /// The registers of each register variable.
    pub vars: Vec<Leaves>,
    /// Per global variable: where it lives in this PTX function.
    pub globals: Vec<Option<Store>>,
    /// Arguments of sin, cos and tan reduced to [−π, π] since the last control-flow
    /// statement, with their reductions: `sin(a)` and `cos(a)` (a rotation, a twist)
    /// share one. Only straight-line code shares, so each entry's definition dominates
    /// its uses.
    pub reduced: Vec<(Op, Op)>,
}

impl<'c, 'a> Fw<'c, 'a> {
    pub fn new(cx: &'c Cx<'a>) -> Self {
        Fw {
            cx,
            out: Out::default(),
            vars: Vec::new(),
            globals: vec![None; cx.module.global_variables.len()],
            reduced: Vec::new(),
        }
    }

    /// The value of an expression already evaluated.
    pub fn val<'f>(&self, f: &'f Frame, h: Handle<Expression>) -> Result<&'f Val, Error> {
        match f.values.get(h.index()) {
            Some(Some(v)) => Ok(v),
            _ => Err(Error::Invalid(format!(
                "expression {h:?} is used before it is evaluated"
            ))),
        }
    }

    /// The operands of a value expression.
    pub fn data<'f>(&self, f: &'f Frame, h: Handle<Expression>) -> Result<&'f [Op], Error> {
        match self.val(f, h)? {
            Val::Data(d) => Ok(d),
            Val::Ptr(_) => Err(Error::Invalid(format!(
                "expression {h:?} is a pointer, not a value"
            ))),
        }
    }

    /// The pointer a pointer expression evaluated to.
    pub fn ptr<'f>(&self, f: &'f Frame, h: Handle<Expression>) -> Result<&'f Ptr, Error> {
        match self.val(f, h)? {
            Val::Ptr(p) => Ok(p),
            Val::Data(_) => Err(Error::Invalid(format!(
                "expression {h:?} is a value, not a pointer"
            ))),
        }
    }

    /// The type of a value expression.
    pub fn ty(&self, f: &Frame, h: Handle<Expression>) -> Result<Ty, Error> {
        match self.cx.types.resolve(&f.info[h].ty)? {
            Resolved::Value(t) => Ok(t),
            Resolved::Pointer(_) => Err(Error::Invalid(format!(
                "expression {h:?} is a pointer, not a value"
            ))),
        }
    }

    /// The scalar and width of a scalar or vector expression.
    pub fn sv(&self, f: &Frame, h: Handle<Expression>) -> Result<(Sc, u32), Error> {
        self.cx.types.scalar_vector(self.ty(f, h)?)
    }

    /// A fresh register for a value of `sc`.
    pub fn fresh(&mut self, sc: Sc) -> Reg {
        self.out.reg(sc.class())
    }

    /// Copies `src` into a fresh register.
    pub fn mov(&mut self, class: Class, src: Op) -> Op {
        let d = self.out.reg(class);
        ins!(self.out, "mov.{} {d}, {src};", mov_ty(class));
        Op::Reg(d)
    }

    /// Copies `src` into the register `dst`.
    pub fn mov_to(&mut self, dst: Op, src: Op) -> Result<(), Error> {
        match dst {
            Op::Reg(r) if Op::Reg(r) == src => Ok(()),
            Op::Reg(r) => {
                ins!(self.out, "mov.{} {r}, {src};", mov_ty(r.class));
                Ok(())
            }
            _ => Err(Error::Invalid("a store into an immediate".into())),
        }
    }

    /// `d = op a` into a fresh register of `class`.
    pub fn un(&mut self, op: &str, class: Class, a: Op) -> Op {
        let d = self.out.reg(class);
        ins!(self.out, "{op} {d}, {a};");
        Op::Reg(d)
    }

    /// `d = op a, b` into a fresh register of `class`.
    pub fn bin(&mut self, op: &str, class: Class, a: Op, b: Op) -> Op {
        let d = self.out.reg(class);
        ins!(self.out, "{op} {d}, {a}, {b};");
        Op::Reg(d)
    }

    /// `d = op.ty a, b` into a fresh register of `class` (e.g. `op` = "min", `ty` = "f32").
    pub fn bin_typed(&mut self, op: &str, ty: &str, class: Class, a: Op, b: Op) -> Op {
        let d = self.out.reg(class);
        ins!(self.out, "{op}.{ty} {d}, {a}, {b};");
        Op::Reg(d)
    }

    /// `d = op a, b, c` into a fresh register of `class`.
    pub fn tri(&mut self, op: &str, class: Class, a: Op, b: Op, c: Op) -> Op {
        let d = self.out.reg(class);
        ins!(self.out, "{op} {d}, {a}, {b}, {c};");
        Op::Reg(d)
    }

    /// `setp.<cmp> p, a, b` (e.g. `cmp` = "lt.f32").
    pub fn setp(&mut self, cmp: &str, a: Op, b: Op) -> Op {
        self.bin_typed("setp", cmp, Class::Pred, a, b)
    }

    /// `setp.<cmp>.<ty> p, a, b` (e.g. `cmp` = "lt", `ty` = "f32").
    pub fn setp_typed(&mut self, cmp: &str, ty: &str, a: Op, b: Op) -> Op {
        let d = self.out.reg(Class::Pred);
        ins!(self.out, "setp.{cmp}.{ty} {d}, {a}, {b};");
        Op::Reg(d)
    }

    /// `p ? t : f` for leaves of `sc`.
    pub fn selp(&mut self, sc: Sc, t: Op, f: Op, p: Op) -> Op {
        if let Op::Bool(b) = p {
            return if b { t } else { f };
        }
        if sc == Sc::Bool {
            let a = self.bin("and.pred", Class::Pred, p, t);
            let np = self.un("not.pred", Class::Pred, p);
            let b = self.bin("and.pred", Class::Pred, np, f);
            return self.bin("or.pred", Class::Pred, a, b);
        }
        let t_ty = if sc == Sc::F32 { "f32" } else { "b32" };
        let d = self.out.reg(sc.class());
        ins!(self.out, "selp.{t_ty} {d}, {t}, {f}, {p};");
        Op::Reg(d)
    }

    /// The predicate register holding a boolean operand.
    pub fn pred(&mut self, p: Op) -> Reg {
        if let Op::Reg(r) = p {
            if r.class == Class::Pred {
                return r;
            }
        }
        let d = self.out.reg(Class::Pred);
        ins!(self.out, "mov.pred {d}, {p};");
        d
    }

    /// A new register variable holding `init`.
    pub fn new_var(&mut self, scs: &[Sc], init: Option<&[Op]>) -> Result<usize, Error> {
        let mut regs = Leaves::with_capacity(scs.len());
        for (i, &sc) in scs.iter().enumerate() {
            let r = Op::Reg(self.fresh(sc));
            if let Some(v) = init {
                let src = *v
                    .get(i)
                    .ok_or_else(|| Error::Invalid("an initializer of the wrong size".into()))?;
                self.mov_to(r, src)?;
            }
            regs.push(r);
        }
        self.vars.push(regs);
        Ok(self.vars.len() - 1)
    }
}

/// The type suffix of a `mov` between registers of `class`.
pub(super) fn mov_ty(class: Class) -> &'static str {
    match class {
        Class::Pred => "pred",
        Class::B16 => "b16",
        Class::B32 => "b32",
        Class::F32 => "f32",
        Class::B64 => "b64",
        Class::F64 => "f64",
    }
}
