//! Facts about the module that the writer needs before it writes any function: which
//! functions the entry point reaches, which of them are inlined, which variables live
//! in local memory (those indexed with a run-time index) and which expressions the
//! statements emit. Each is one linear pass over the IR.

use super::types::{Resolved, Shape, Types};
use super::Error;
use naga::valid::{FunctionInfo, ModuleInfo};
use naga::{AddressSpace, Block, Expression, Function, Handle, Module, Statement, TypeInner};

/// What the writer knows about the module before writing it.
#[derive(Debug)]
pub(super) struct Analysis {
    /// Per function: reached from the entry point.
    pub reachable: Vec<bool>,
    /// Per function: expanded at each call instead of written as a `.func` (see
    /// [`inlining`]).
    pub inline: Vec<bool>,
    /// Per function, per local variable: kept in `.local` memory.
    pub mem_locals: Vec<Vec<bool>>,
    /// Per local variable of the entry point: kept in `.local` memory.
    pub entry_mem_locals: Vec<bool>,
    /// Per global variable: a `var<private>` kept in `.local` memory.
    pub mem_privates: Vec<bool>,
    /// Per function: runs a loop, its own or one of a function it calls.
    pub loops: Vec<bool>,
}

/// Where a pointer expression points: into which variable or argument.
#[derive(Debug, Clone, Copy)]
enum Root {
    Local(usize),
    Global(usize),
    Arg(usize),
}

impl Analysis {
    pub fn new(
        module: &Module,
        info: &ModuleInfo,
        types: &Types,
        entry: usize,
    ) -> Result<Self, Error> {
        let ep = &module.entry_points[entry];
        let nf = module.functions.len();
        let mut a = Analysis {
            reachable: vec![false; nf],
            inline: vec![false; nf],
            mem_locals: vec![Vec::new(); nf],
            entry_mem_locals: Vec::new(),
            mem_privates: vec![false; module.global_variables.len()],
            loops: vec![false; nf],
        };
        a.mark_reachable(module, &ep.function);
        // Callees come before their callers in naga's arena, so one forward pass sees
        // each callee's facts before any call to it.
        let mut arg_dyn: Vec<Vec<bool>> = vec![Vec::new(); nf];
        for (h, f) in module.functions.iter() {
            if !a.reachable[h.index()] {
                continue;
            }
            let fi = &info[h];
            let (locals, args) = a.memory(types, f, fi, &arg_dyn)?;
            a.mem_locals[h.index()] = locals;
            arg_dyn[h.index()] = args;
        }
        let (locals, _) = a.memory(types, &ep.function, info.get_entry_point(entry), &arg_dyn)?;
        a.entry_mem_locals = locals;
        a.inline = inlining(module, info, &a.reachable, &ep.function);
        // Callees come first, so each call sees its callee's mark.
        for (h, f) in module.functions.iter() {
            let marked = has_loop(&f.body, &a.loops);
            a.loops[h.index()] = marked;
        }
        Ok(a)
    }

    fn mark_reachable(&mut self, module: &Module, f: &Function) {
        let mut stack = Vec::new();
        calls(&f.body, &mut stack);
        while let Some(h) = stack.pop() {
            if !std::mem::replace(&mut self.reachable[h.index()], true) {
                calls(&module.functions[h].body, &mut stack);
            }
        }
    }

    /// Marks the variables `f` indexes at run time; returns its own locals' marks and
    /// which of its pointer arguments it indexes at run time.
    fn memory(
        &mut self,
        types: &Types,
        f: &Function,
        fi: &FunctionInfo,
        arg_dyn: &[Vec<bool>],
    ) -> Result<(Vec<bool>, Vec<bool>), Error> {
        let mut locals = vec![false; f.local_variables.len()];
        let mut args = vec![false; f.arguments.len()];
        let mut roots: Vec<Option<Root>> = Vec::with_capacity(f.expressions.len());
        for (h, e) in f.expressions.iter() {
            let root = |b: Handle<Expression>| roots.get(b.index()).copied().flatten();
            let (r, dynamic) = match *e {
                Expression::LocalVariable(l) => (Some(Root::Local(l.index())), false),
                Expression::GlobalVariable(g) => (Some(Root::Global(g.index())), false),
                Expression::FunctionArgument(i) => (Some(Root::Arg(i as usize)), false),
                Expression::AccessIndex { base, .. } => (root(base), false),
                Expression::Access { base, .. } => (root(base), indexes_memory(types, fi, base)?),
                _ => (None, false),
            };
            if let (true, Some(r)) = (dynamic, r) {
                self.mark(r, &mut locals, &mut args);
            }
            roots.push(r);
            debug_assert_eq!(roots.len(), h.index() + 1);
        }
        let mut marks = Vec::new();
        visit(&f.body, &mut |s| {
            if let Statement::Call {
                function,
                arguments,
                ..
            } = s
            {
                let callee = &arg_dyn[function.index()];
                for (i, a) in arguments.iter().enumerate() {
                    if callee.get(i).copied().unwrap_or(false) {
                        marks.extend(roots.get(a.index()).copied().flatten());
                    }
                }
            }
        });
        for r in marks {
            self.mark(r, &mut locals, &mut args);
        }
        Ok((locals, args))
    }

    fn mark(&mut self, r: Root, locals: &mut [bool], args: &mut [bool]) {
        let slot = match r {
            Root::Local(i) => locals.get_mut(i),
            Root::Global(i) => self.mem_privates.get_mut(i),
            Root::Arg(i) => args.get_mut(i),
        };
        if let Some(s) = slot {
            *s = true;
        }
    }
}

/// The most expressions inlining a function may duplicate (its size times the number of
/// copies beyond the first): below it a call costs more than the copies (ptxas cannot
/// optimise across a call, and saves registers around it); above it the copies cost
/// more (code size, and register pressure that ptxas resolves by spilling). The budget
/// inlines seed6's `sdf` (4 copies, about 1 800 duplicated expressions) and calls temple's
/// (about 5× that), each the faster way for its kernel (docs/ptx.md, "Calls").
const DUPLICATION_BUDGET: u64 = 2500;

/// Per function: inlined at each call. A function is inlined where it must be (it takes
/// a pointer or uses a `var<private>`), where it is called once, or where the copies
/// stay within [`DUPLICATION_BUDGET`]. Linear in the module's size.
fn inlining(module: &Module, info: &ModuleInfo, reachable: &[bool], entry: &Function) -> Vec<bool> {
    let nf = module.functions.len();
    let mut callees: Vec<Vec<Handle<Function>>> = vec![Vec::new(); nf];
    for (h, f) in module.functions.iter() {
        if reachable[h.index()] {
            calls(&f.body, &mut callees[h.index()]);
        }
    }
    // Copies of each function if every caller were inlined: callers come after their
    // callees in naga's arena, so a backward pass sees every caller's count first.
    let mut copies = vec![0u64; nf];
    let mut from_entry = Vec::new();
    calls(&entry.body, &mut from_entry);
    for c in from_entry {
        copies[c.index()] = copies[c.index()].saturating_add(1);
    }
    for i in (0..nf).rev() {
        for c in &callees[i] {
            copies[c.index()] = copies[c.index()].saturating_add(copies[i]);
        }
    }
    let mut size = vec![0u64; nf];
    let mut inline = vec![false; nf];
    for (h, f) in module.functions.iter() {
        let i = h.index();
        if !reachable[i] {
            continue;
        }
        let inlined = callees[i]
            .iter()
            .filter(|c| inline[c.index()])
            .fold(0u64, |a, c| a.saturating_add(size[c.index()]));
        size[i] = (f.expressions.len() as u64).saturating_add(inlined);
        let forced = takes_pointer(module, f) || uses_private(module, &info[h]);
        let copies = copies[i].max(1);
        inline[i] = forced || size[i].saturating_mul(copies - 1) <= DUPLICATION_BUDGET;
    }
    inline
}

/// Whether `Access { base, .. }` indexes an array or matrix behind a pointer (a vector
/// in registers is indexed by selection instead).
fn indexes_memory(
    types: &Types,
    fi: &FunctionInfo,
    base: Handle<Expression>,
) -> Result<bool, Error> {
    match types.resolve(&fi[base].ty)? {
        Resolved::Pointer(ty) => Ok(matches!(
            types.shape(ty)?,
            Shape::Array { .. } | Shape::Matrix { .. }
        )),
        Resolved::Value(_) => Ok(false),
    }
}

fn takes_pointer(module: &Module, f: &Function) -> bool {
    f.arguments
        .iter()
        .any(|a| matches!(module.types[a.ty].inner, TypeInner::Pointer { .. }))
}

fn uses_private(module: &Module, fi: &FunctionInfo) -> bool {
    module
        .global_variables
        .iter()
        .any(|(h, g)| g.space == AddressSpace::Private && !fi[h].is_empty())
}

/// Whether `block` runs a loop: a `loop` statement, or a call of a function marked in
/// `loops`.
pub(super) fn has_loop(block: &Block, loops: &[bool]) -> bool {
    let mut found = false;
    visit(block, &mut |s| match *s {
        Statement::Loop { .. } => found = true,
        Statement::Call { function, .. } => {
            found |= loops.get(function.index()).copied().unwrap_or(true)
        }
        _ => {}
    });
    found
}

/// Pushes every function `block` calls.
fn calls(block: &Block, out: &mut Vec<Handle<Function>>) {
    visit(block, &mut |s| {
        if let Statement::Call { function, .. } = *s {
            out.push(function);
        }
    });
}

/// Calls `f` on every statement of `block`, nested ones included.
pub(super) fn visit(block: &Block, f: &mut impl FnMut(&Statement)) {
    for s in block.iter() {
        f(s);
        match s {
            Statement::Block(b) => visit(b, f),
            Statement::If { accept, reject, .. } => {
                visit(accept, f);
                visit(reject, f);
            }
            Statement::Switch { cases, .. } => {
                for c in cases {
                    visit(&c.body, f);
                }
            }
            Statement::Loop {
                body, continuing, ..
            } => {
                visit(body, f);
                visit(continuing, f);
            }
            _ => {}
        }
    }
}

/// Per expression of `f`: evaluated by an `Emit` statement (the others are constants,
/// arguments, variables and results of statements).
pub(super) fn emitted(f: &Function) -> Vec<bool> {
    let mut marks = vec![false; f.expressions.len()];
    visit(&f.body, &mut |s| {
        if let Statement::Emit(range) = s {
            for h in range.clone() {
                if let Some(m) = marks.get_mut(h.index()) {
                    *m = true;
                }
            }
        }
    });
    marks
}
