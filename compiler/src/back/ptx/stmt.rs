//! Statements: naga's structured control flow as labelled branches, stores, calls,
//! barriers and returns.

use super::analysis::{has_loop, visit};
use super::emit::{ins, Op};
use super::types::Sc;
use super::writer::{Frame, Fw, Ret, Target};
use super::Error;
use naga::{Barrier, Block, Expression, Handle, Statement, SwitchCase, SwitchValue};

/// The most values (scalar leaves) hoisted out of one loop.
const HOIST_LEAVES: u32 = 8;

impl<'a> Fw<'_, 'a> {
    pub fn block(&mut self, f: &mut Frame<'a>, b: &'a Block) -> Result<(), Error> {
        b.iter().try_for_each(|s| self.stmt(f, s))
    }

    fn stmt(&mut self, f: &mut Frame<'a>, s: &'a Statement) -> Result<(), Error> {
        // Values computed for sharing (trigonometric reductions) stay within straight-line
        // code: control flow on either side ends their scope.
        let straight = matches!(s, Statement::Emit(_) | Statement::Store { .. });
        if !straight {
            self.reduced.clear();
        }
        let r = self.stmt_inner(f, s);
        if !straight {
            self.reduced.clear();
        }
        r
    }

    fn stmt_inner(&mut self, f: &mut Frame<'a>, s: &'a Statement) -> Result<(), Error> {
        match *s {
            Statement::Emit(ref range) => self.emit(f, range.clone()),
            Statement::Block(ref b) => self.block(f, b),
            Statement::If {
                condition,
                ref accept,
                ref reject,
            } => self.if_(f, condition, accept, reject),
            Statement::Switch {
                selector,
                ref cases,
            } => self.switch(f, selector, cases),
            Statement::Loop {
                ref body,
                ref continuing,
                break_if,
            } => self.loop_(f, body, continuing, break_if),
            Statement::Break => self.break_(f),
            Statement::Continue => self.continue_(f),
            Statement::Return { value } => self.return_(f, value),
            Statement::Store { pointer, value } => {
                let p = self.ptr(f, pointer)?.clone();
                let v = self.data(f, value)?.to_vec();
                self.store(&p, &v)
            }
            Statement::Call {
                function,
                ref arguments,
                result,
            } => self.call(f, function, arguments, result),
            Statement::ControlBarrier(b) => {
                self.out.comment(format_args!("barrier {b:?}"));
                ins!(
                    self.out,
                    "{};",
                    if b == Barrier::SUB_GROUP {
                        "bar.warp.sync -1"
                    } else {
                        "bar.sync 0"
                    }
                );
                Ok(())
            }
            Statement::MemoryBarrier(b) => {
                ins!(
                    self.out,
                    "{};",
                    if b.contains(Barrier::STORAGE) {
                        "membar.gl"
                    } else {
                        "membar.cta"
                    }
                );
                Ok(())
            }
            ref other => Err(Error::Unsupported(statement_name(other).into())),
        }
    }

    fn emit(&mut self, f: &mut Frame<'a>, range: naga::Range<Expression>) -> Result<(), Error> {
        for h in range {
            // Unused, or evaluated early (a load hoisted out of its loop).
            if f.info[h].ref_count == 0 || f.values.get(h.index()).is_some_and(Option::is_some) {
                continue;
            }
            if let Some(name) = f.func.named_expressions.get(&h) {
                self.out.comment(format_args!("let {name}"));
            }
            self.expr(f, h)?;
        }
        Ok(())
    }

    /// The predicate of a boolean scalar expression.
    fn cond(&self, f: &Frame, h: Handle<Expression>) -> Result<Op, Error> {
        self.scalar(f, h)
    }

    fn if_(
        &mut self,
        f: &mut Frame<'a>,
        c: Handle<Expression>,
        accept: &'a Block,
        reject: &'a Block,
    ) -> Result<(), Error> {
        let p = match self.cond(f, c)? {
            Op::Bool(true) => return self.block(f, accept),
            Op::Bool(false) => return self.block(f, reject),
            p => self.pred(p),
        };
        let g = self.out.label_group();
        let (else_, end) = (format!("$L{g}_else"), format!("$L{g}_endif"));
        self.out.comment(format_args!("if"));
        ins!(
            self.out,
            "@!{p} bra {};",
            if reject.is_empty() { &end } else { &else_ }
        );
        self.block(f, accept)?;
        if !reject.is_empty() {
            ins!(self.out, "bra {end};");
            self.out.place(&else_);
            self.block(f, reject)?;
        }
        self.out.place(&end);
        Ok(())
    }

    fn loop_(
        &mut self,
        f: &mut Frame<'a>,
        body: &'a Block,
        continuing: &'a Block,
        break_if: Option<Handle<Expression>>,
    ) -> Result<(), Error> {
        let g = self.out.label_group();
        let (head, cont, end) = (
            format!("$L{g}_loop"),
            format!("$L{g}_continuing"),
            format!("$L{g}_loop_end"),
        );
        self.hoist_uniform_loads(f, body, continuing)?;
        self.out.comment(format_args!("loop"));
        self.out.place(&head);
        f.targets.push(Target::Loop {
            cont: cont.clone(),
            end: end.clone(),
        });
        let r = self.block(f, body);
        f.targets.pop();
        r?;
        self.out.place(&cont);
        self.block(f, continuing)?;
        if let Some(b) = break_if {
            match self.cond(f, b)? {
                Op::Bool(true) => ins!(self.out, "bra {end};"),
                Op::Bool(false) => {}
                p => {
                    let p = self.pred(p);
                    ins!(self.out, "@{p} bra {end};");
                }
            }
        }
        ins!(self.out, "bra {head};");
        self.out.place(&end);
        Ok(())
    }

    /// Loads from uniform buffers at fixed offsets in an innermost loop (one that runs no
    /// other loop, its own or in a function it calls), evaluated once before the loop
    /// instead of at each iteration: `params.counts.w` in the sphere tracer's loop
    /// condition. ptxas does not move `ld.global.nc` out of loops itself, and a load the
    /// loop's branch waits for costs an L1 round trip per iteration (Vulkan reads the
    /// same value as a constant-bank operand). Uniform buffers cover their whole type, so
    /// loading early, even what only one branch of the body reads, stays in bounds. At
    /// most [`HOIST_LEAVES`] values, to keep register pressure in the loop down.
    fn hoist_uniform_loads(
        &mut self,
        f: &mut Frame<'a>,
        body: &'a Block,
        continuing: &'a Block,
    ) -> Result<(), Error> {
        let loops = &self.cx.an.loops;
        if has_loop(body, loops) || has_loop(continuing, loops) {
            return Ok(());
        }
        let mut found = Vec::new();
        for b in [body, continuing] {
            visit(b, &mut |s| {
                if let Statement::Emit(range) = s {
                    found.extend(range.clone().filter(|&h| f.info[h].ref_count > 0));
                }
            });
        }
        let mut budget = HOIST_LEAVES;
        for h in found {
            let Some(chain) = self.uniform_chain(f, h) else {
                continue;
            };
            let Ok(super::types::Resolved::Value(ty)) = self.cx.types.resolve(&f.info[h].ty) else {
                continue;
            };
            let n = self.cx.types.leaves(ty)?;
            if n > budget {
                continue;
            }
            budget -= n;
            if budget == HOIST_LEAVES - n {
                self.out
                    .comment(format_args!("uniform loads hoisted out of the loop"));
            }
            for &c in chain.iter().rev() {
                if f.values.get(c.index()).is_some_and(Option::is_none) {
                    self.expr(f, c)?;
                }
            }
        }
        Ok(())
    }

    /// For a `Load` from a uniform buffer through members and constant indices only: the
    /// load and the pointer expressions it goes through, outermost first.
    fn uniform_chain(&self, f: &Frame, h: Handle<Expression>) -> Option<Vec<Handle<Expression>>> {
        let Expression::Load { pointer } = f.func.expressions[h] else {
            return None;
        };
        let mut chain = vec![h];
        let mut p = pointer;
        loop {
            match f.func.expressions[p] {
                Expression::AccessIndex { base, .. } => {
                    chain.push(p);
                    p = base;
                }
                Expression::Access { base, index }
                    if matches!(f.func.expressions[index], Expression::Literal(_)) =>
                {
                    chain.push(p);
                    p = base;
                }
                Expression::GlobalVariable(g) => {
                    let uniform =
                        self.cx.module.global_variables[g].space == naga::AddressSpace::Uniform;
                    // The global's pointer is evaluated on entry (it is not emitted).
                    let ready = f.values.get(p.index()).is_some_and(Option::is_some);
                    return (uniform && ready).then_some(chain);
                }
                _ => return None,
            }
        }
    }

    fn switch(
        &mut self,
        f: &mut Frame<'a>,
        selector: Handle<Expression>,
        cases: &'a [SwitchCase],
    ) -> Result<(), Error> {
        let (sc, _) = self.sv(f, selector)?;
        let sel = match self.scalar(f, selector)? {
            Op::Reg(r) => Op::Reg(r),
            imm => self.mov(sc.class(), imm),
        };
        let g = self.out.label_group();
        let label = |i: usize| format!("$L{g}_case{i}");
        let end = format!("$L{g}_switch_end");
        self.out.comment(format_args!("switch"));
        let mut default = end.clone();
        for (i, c) in cases.iter().enumerate() {
            let v = match c.value {
                SwitchValue::I32(v) => Op::I32(v),
                SwitchValue::U32(v) => Op::U32(v),
                SwitchValue::Default => {
                    default = label(i);
                    continue;
                }
            };
            let t = if sc == Sc::I32 { "s32" } else { "u32" };
            let p = self.setp(&format!("eq.{t}"), sel, v);
            ins!(self.out, "@{p} bra {};", label(i));
        }
        ins!(self.out, "bra {default};");
        f.targets.push(Target::Switch { end: end.clone() });
        let r = cases.iter().enumerate().try_for_each(|(i, c)| {
            self.out.place(&label(i));
            self.block(f, &c.body)?;
            if !c.fall_through {
                ins!(self.out, "bra {end};");
            }
            Ok(())
        });
        f.targets.pop();
        r?;
        self.out.place(&end);
        Ok(())
    }

    fn break_(&mut self, f: &Frame) -> Result<(), Error> {
        match f.targets.last() {
            Some(Target::Loop { end, .. } | Target::Switch { end }) => {
                ins!(self.out, "bra {end};");
                Ok(())
            }
            None => Err(Error::Invalid("break outside a loop or switch".into())),
        }
    }

    fn continue_(&mut self, f: &Frame) -> Result<(), Error> {
        let cont = f.targets.iter().rev().find_map(|t| match t {
            Target::Loop { cont, .. } => Some(cont),
            Target::Switch { .. } => None,
        });
        match cont {
            Some(c) => {
                ins!(self.out, "bra {c};");
                Ok(())
            }
            None => Err(Error::Invalid("continue outside a loop".into())),
        }
    }

    fn return_(&mut self, f: &Frame, value: Option<Handle<Expression>>) -> Result<(), Error> {
        let v = match value {
            Some(h) => self.data(f, h)?.to_vec(),
            None => Vec::new(),
        };
        match f.ret {
            Ret::Kernel => ins!(self.out, "ret;"),
            Ret::Func { ref param } => {
                for (i, &x) in v.iter().enumerate() {
                    self.store_param(param, 4 * i as u32, x);
                }
                ins!(self.out, "ret;");
            }
            Ret::Inline { var, ref end } => {
                if let Some(var) = var {
                    let dst = self.vars.get(var).cloned().unwrap_or_default();
                    if dst.len() != v.len() {
                        return Err(Error::Invalid("a return value of the wrong size".into()));
                    }
                    dst.iter()
                        .zip(&v)
                        .try_for_each(|(&d, &s)| self.mov_to(d, s))?;
                }
                ins!(self.out, "bra {end};");
            }
        }
        Ok(())
    }
}

/// The name of a statement kind, for messages.
fn statement_name(s: &Statement) -> &'static str {
    match s {
        Statement::Kill => "discard (Statement::Kill)",
        Statement::ImageStore { .. } => "texture stores (Statement::ImageStore)",
        Statement::Atomic { .. } => "atomics (Statement::Atomic)",
        Statement::ImageAtomic { .. } => "texture atomics (Statement::ImageAtomic)",
        Statement::WorkGroupUniformLoad { .. } => {
            "workgroupUniformLoad (Statement::WorkGroupUniformLoad)"
        }
        Statement::RayQuery { .. } | Statement::RayPipelineFunction(_) => "ray tracing",
        Statement::SubgroupBallot { .. }
        | Statement::SubgroupGather { .. }
        | Statement::SubgroupCollectiveOperation { .. } => "subgroup operations",
        Statement::CooperativeStore { .. } => "cooperative matrices",
        _ => "this statement",
    }
}
