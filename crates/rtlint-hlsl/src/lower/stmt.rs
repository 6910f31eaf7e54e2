//! Statements: blocks, control flow, local declarations.

use super::*;

impl<'a> Lowerer<'a> {
    pub(super) fn block(&mut self, stmts: &'a [Stmt]) -> Result<()> {
        self.f.scopes.push(HashMap::new());
        for s in stmts {
            if self.f.term {
                break; // the rest is unreachable
            }
            self.stmt(s)?;
        }
        self.f.scopes.pop();
        Ok(())
    }

    pub(super) fn cond(&mut self, e: &'a Expr) -> Result<Id> {
        let v = self.expr(e)?;
        if !matches!(v.ty, Ty::ScalarKind(_)) {
            return Err(Error::new(
                e.pos,
                format!(
                    "condition must be a scalar, found `{}`",
                    self.ty_name(&v.ty)
                ),
            ));
        }
        Ok(self
            .convert(v, &Ty::ScalarKind(ScalarKind::Bool), e.pos, false)?
            .id)
    }

    pub(super) fn branch(&mut self, to: Id) -> Result<()> {
        if !self.f.term {
            self.b.branch(to)?;
            self.f.term = true;
        }
        Ok(())
    }

    pub(super) fn stmt(&mut self, s: &'a Stmt) -> Result<()> {
        self.line(s.pos);
        match &s.kind {
            StmtKind::Empty => {}
            StmtKind::Block(b) => self.block(b)?,
            StmtKind::Expr(e) => {
                self.expr_void(e)?;
            }
            StmtKind::Decl(vars) => {
                for v in vars {
                    self.local_decl(v)?;
                }
            }
            StmtKind::If(c, then, els) => {
                let c = self.cond(c)?;
                let (lt, lm) = (self.b.id(), self.b.id());
                let le = if els.is_some() { self.b.id() } else { lm };
                self.b.selection_merge(lm, spirv::SelectionControl::NONE)?;
                self.b.branch_conditional(c, lt, le, [])?;
                self.start_block(Some(lt))?;
                self.scoped(then)?;
                self.branch(lm)?;
                if let Some(e) = els {
                    self.start_block(Some(le))?;
                    self.scoped(e)?;
                    self.branch(lm)?;
                }
                self.start_block(Some(lm))?;
            }
            StmtKind::While(c, body) => self.lower_loop(Some(c), None, body, false)?,
            StmtKind::DoWhile(body, c) => self.lower_loop(Some(c), None, body, true)?,
            StmtKind::For(init, c, step, body) => {
                self.f.scopes.push(HashMap::new());
                if let Some(i) = init {
                    self.stmt(i)?;
                }
                self.lower_loop(c.as_ref(), step.as_ref(), body, false)?;
                self.f.scopes.pop();
            }
            StmtKind::Break => {
                let Some(f) = self.f.flow.last() else {
                    return Err(Error::new(s.pos, "`break` outside a loop or switch").len(5));
                };
                let to = f.brk;
                self.b.branch(to)?;
                self.f.term = true;
            }
            StmtKind::Continue => {
                let Some(to) = self.f.flow.iter().rev().find_map(|f| f.cont) else {
                    return Err(Error::new(s.pos, "`continue` outside a loop").len(8));
                };
                self.b.branch(to)?;
                self.f.term = true;
            }
            StmtKind::Return(v) => {
                let ret = self.f.ret_ty.clone();
                match (v, ret == Ty::Void) {
                    (None, true) => self.b.ret()?,
                    (Some(e), false) => {
                        let v = self.expr(e)?;
                        let v = self.convert(v, &ret, e.pos, false)?;
                        if self.f.term {
                            self.start_block(None)?;
                        }
                        self.b.ret_value(v.id)?;
                    }
                    // `return f();` of a void `f` in a void function, as C++ allows.
                    (
                        Some(
                            e @ Expr {
                                kind:
                                    ExprKind::Call(..)
                                    | ExprKind::Method(..)
                                    | ExprKind::CallT(..)
                                    | ExprKind::MethodT(..),
                                ..
                            },
                        ),
                        true,
                    ) => {
                        if self.call_expr(e)?.is_some() {
                            return Err(Error::new(e.pos, "this function returns void"));
                        }
                        if self.f.term {
                            self.start_block(None)?;
                        }
                        self.b.ret()?;
                    }
                    // `return q;` of the local a ray query is made in (`ret_slot`).
                    (
                        Some(Expr {
                            kind: ExprKind::Ident(n),
                            ..
                        }),
                        true,
                    ) if self.f.ret_slot.as_ref().is_some_and(|(r, _)| r == n) => {
                        if self.f.term {
                            self.start_block(None)?;
                        }
                        self.b.ret()?;
                    }
                    (Some(e), true) => return Err(Error::new(e.pos, "this function returns void")),
                    (None, false) => return Err(Error::new(s.pos, "missing return value").len(6)),
                }
                self.f.term = true;
            }
            StmtKind::Discard => {
                match self.f.cur_stage {
                    Some(Stage::Fragment) => {}
                    Some(st) => {
                        return Err(Error::new(
                            s.pos,
                            format!(
                                "`discard` is only available in pixel shaders, not {} shaders",
                                st.hlsl_name()
                            ),
                        )
                        .len(7))
                    }
                    None => {
                        self.fn_derivs
                            .entry(self.f.cur_fn)
                            .or_insert(("discard", s.pos));
                    }
                }
                if self.f.term {
                    self.start_block(None)?;
                }
                // OpKill: SPIR-V 1.4 without SPV_KHR_terminate_invocation, as Vulkan 1.2 accepts.
                self.b.kill()?;
                self.f.term = true;
            }
            StmtKind::Switch(sel, cases) => self.lower_switch(sel, cases)?,
        }
        Ok(())
    }

    pub(super) fn scoped(&mut self, s: &'a Stmt) -> Result<()> {
        self.f.scopes.push(HashMap::new());
        let r = self.stmt(s);
        self.f.scopes.pop();
        r
    }

    pub(super) fn lower_loop(
        &mut self,
        cond: Option<&'a Expr>,
        step: Option<&'a Expr>,
        body: &'a Stmt,
        do_while: bool,
    ) -> Result<()> {
        let (header, body_l, cont, merge) = (self.b.id(), self.b.id(), self.b.id(), self.b.id());
        self.branch(header)?;
        self.start_block(Some(header))?;
        self.b
            .loop_merge(merge, cont, spirv::LoopControl::NONE, [])?;
        if do_while {
            self.b.branch(body_l)?;
        } else {
            let check = self.b.id();
            self.b.branch(check)?;
            self.start_block(Some(check))?;
            match cond {
                Some(c) => {
                    let c = self.cond(c)?;
                    self.b.branch_conditional(c, body_l, merge, [])?;
                }
                None => self.b.branch(body_l)?,
            }
        }
        self.start_block(Some(body_l))?;
        self.f.flow.push(Flow {
            brk: merge,
            cont: Some(cont),
        });
        let r = self.scoped(body);
        self.f.flow.pop();
        r?;
        self.branch(cont)?;
        self.start_block(Some(cont))?;
        if do_while {
            let c = match cond {
                Some(c) => self.cond(c)?,
                None => self.const_bool(true),
            };
            self.b.branch_conditional(c, header, merge, [])?;
        } else {
            if let Some(s) = step {
                self.expr_void(s)?;
            }
            self.b.branch(header)?;
        }
        self.f.term = true;
        self.start_block(Some(merge))?;
        Ok(())
    }

    pub(super) fn lower_switch(&mut self, sel: &'a Expr, cases: &'a [Case]) -> Result<()> {
        let v = self.expr(sel)?;
        let v = match v.ty {
            Ty::ScalarKind(ScalarKind::Int) | Ty::ScalarKind(ScalarKind::Uint) => v,
            // Case labels are 32-bit: a 16-bit selector is extended (same cases).
            Ty::ScalarKind(ScalarKind::Bool | ScalarKind::Int16 | ScalarKind::Uint16) => {
                self.convert(v, &Ty::ScalarKind(ScalarKind::Int), sel.pos, false)?
            }
            _ => return Err(Error::new(sel.pos, "switch needs an integer scalar")),
        };
        let merge = self.b.id();
        let labels: Vec<Id> = cases.iter().map(|_| self.b.id()).collect();
        let mut default = merge;
        let mut targets = Vec::new();
        let mut seen = HashSet::new();
        for (c, l) in cases.iter().zip(&labels) {
            for lab in &c.labels {
                match lab {
                    None => default = *l,
                    Some(e) => {
                        let n = self.const_int(e)? as u32;
                        if !seen.insert(n) {
                            return Err(Error::new(e.pos, format!("duplicate case {n}")));
                        }
                        targets.push((Operand::LiteralBit32(n), *l));
                    }
                }
            }
        }
        self.b
            .selection_merge(merge, spirv::SelectionControl::NONE)?;
        self.b.switch(v.id, default, targets)?;
        self.f.flow.push(Flow {
            brk: merge,
            cont: None,
        });
        for (i, (c, l)) in cases.iter().zip(&labels).enumerate() {
            self.start_block(Some(*l))?;
            self.f.scopes.push(HashMap::new());
            let mut r = Ok(());
            for s in &c.body {
                if self.f.term {
                    break;
                }
                r = self.stmt(s);
                if r.is_err() {
                    break;
                }
            }
            self.f.scopes.pop();
            if let Err(e) = r {
                self.f.flow.pop();
                return Err(e);
            }
            // Falling through to the next case is allowed in SPIR-V too.
            let next = labels.get(i + 1).copied().unwrap_or(merge);
            self.branch(next)?;
        }
        self.f.flow.pop();
        self.start_block(Some(merge))?;
        Ok(())
    }

    pub(super) fn local_decl(&mut self, v: &'a VarDecl) -> Result<()> {
        let ns = self.f.cur_ns.clone();
        let base = self.resolve_ty(&v.ty, &ns)?;
        // `float a[] = {...}` takes its size from the initializer.
        let t = if v.dims.first().is_some_and(|d| d.is_none()) {
            let n = match &v.init {
                Some(Expr {
                    kind: ExprKind::InitList(items),
                    ..
                }) => items.len() as u32,
                _ => return Err(Error::new(v.pos, "array size missing")),
            };
            let inner = self.apply_dims(base, &v.dims[1..], v.pos, false)?;
            Ty::Array(Box::new(inner), n)
        } else {
            self.apply_dims(base, &v.dims, v.pos, false)?
        };
        if t.is_resource() {
            // `Texture2D t = textures[i];`: a name for the resource it is
            // initialized with (as DXC's legalization makes of it).
            let place = match &v.init {
                Some(init) if !v.mods.is_static => match Self::heap_index(init) {
                    Some((sampler, idx)) => self.heap_place(sampler, idx, &t, init.pos)?,
                    None => self.place(init)?,
                },
                _ => {
                    return Err(unsupported(
                        v.pos,
                        "local resource variables without an initializer, or static",
                    )
                    .len(v.name.len() as u32))
                }
            };
            if !matches!(place, Place::Ptr { .. }) || place.ty() != &t {
                return Err(Error::new(
                    v.pos,
                    format!(
                        "`{}` must be initialized with a `{}` variable or array element",
                        v.name,
                        self.ty_name(&t)
                    ),
                ));
            }
            self.bind(&v.name, place);
            return Ok(());
        }
        if v.mods.is_static {
            let init = match &v.init {
                Some(e) => self.const_value(e, &t)?,
                None => None,
            };
            let tid = self.ty_id(&t)?;
            let first = match init {
                Some(i) => i,
                None => self.b.constant_null(tid),
            };
            let var = self.private_var(tid, first, &v.name);
            let place = Place::Ptr {
                ptr: var,
                ty: t.clone(),
                layout: Layout::None,
                class: StorageClass::Private,
            };
            if let (None, Some(e)) = (init, &v.init) {
                // Initialized when the declaration is first reached, as C++
                // and DXC do: a Private flag guards the store.
                let bool_ty = self.ty_id(&Ty::ScalarKind(ScalarKind::Bool))?;
                let no = self.const_bool(false);
                let flag = self.private_var(bool_ty, no, &format!("{}.init.done", v.name));
                if self.f.term {
                    self.start_block(None)?;
                }
                let done = self.b.load(bool_ty, None, flag, None, [])?;
                let (lt, lm) = (self.b.id(), self.b.id());
                self.b.selection_merge(lm, spirv::SelectionControl::NONE)?;
                self.b.branch_conditional(done, lm, lt, [])?;
                self.start_block(Some(lt))?;
                let val = self.expr_as(e, &t)?;
                self.b.store(var, val.id, None, [])?;
                let yes = self.const_bool(true);
                self.b.store(flag, yes, None, [])?;
                self.branch(lm)?;
                self.start_block(Some(lm))?;
            }
            self.bind(&v.name, place);
            return Ok(());
        }
        if v.mods.is_const && !v.mods.is_static {
            // `const int N = 3;`: a name for the constant (usable as an array size).
            if let (Ty::ScalarKind(_), Some(init)) = (&t, &v.init) {
                let val = self.expr_as(init, &t)?;
                if self.known(&val).is_some() {
                    self.bind(&v.name, Place::Value(val));
                    return Ok(());
                }
                let var = self.local_var(&t, &v.name)?;
                self.local_decls
                    .push((self.f.cur_fn, var, v.name.clone(), t.clone(), v.pos));
                if self.f.term {
                    self.start_block(None)?;
                }
                self.b.store(var, val.id, None, [])?;
                self.bind(
                    &v.name,
                    Place::Ptr {
                        ptr: var,
                        ty: t,
                        layout: Layout::None,
                        class: StorageClass::Function,
                    },
                );
                return Ok(());
            }
        }
        if let Some((name, slot)) = self.f.ret_slot.clone() {
            if name == v.name && slot.ty() == &t && v.init.is_none() {
                // The returned ray query lives in the caller's variable.
                self.bind(&v.name, slot);
                return Ok(());
            }
        }
        if let (Ty::RayQuery(_), Some(init)) = (&t, &v.init) {
            // `RayQuery<F> q = make(...);`: made in `q` by a function returning it.
            let var = self.local_var(&t, &v.name)?;
            self.bind(
                &v.name,
                Place::Ptr {
                    ptr: var,
                    ty: t.clone(),
                    layout: Layout::None,
                    class: StorageClass::Function,
                },
            );
            self.f.ret_dest = Some((var, t.clone()));
            let r = self.call_expr(init);
            let unused = self.f.ret_dest.take();
            r?;
            if unused.is_some() {
                return Err(unsupported(
                    init.pos,
                    "initializing a RayQuery other than by a function returning one",
                ));
            }
            return Ok(());
        }
        if t == Ty::HitObject {
            // Made in place: `HitObject h = HitObject::TraceRay(...)`; a Nop without initializer.
            let var = self.local_var(&t, &v.name)?;
            self.bind(
                &v.name,
                Place::Ptr {
                    ptr: var,
                    ty: t,
                    layout: Layout::None,
                    class: StorageClass::Function,
                },
            );
            return match &v.init {
                Some(init) => self.make_hit_object(var, init),
                None => {
                    self.ser_caps();
                    self.inst(Op::HitObjectRecordEmptyNV, None, vec![Operand::IdRef(var)])?;
                    Ok(())
                }
            };
        }
        let var = self.local_var(&t, &v.name)?;
        self.local_decls
            .push((self.f.cur_fn, var, v.name.clone(), t.clone(), v.pos));
        // In scope in its own initializer, as in C (`RayDesc r = r = make();`).
        self.bind(
            &v.name,
            Place::Ptr {
                ptr: var,
                ty: t.clone(),
                layout: Layout::None,
                class: StorageClass::Function,
            },
        );
        if let Some(init) = &v.init {
            let val = self.expr_as(init, &t)?;
            if self.f.term {
                self.start_block(None)?;
            }
            self.b.store(var, val.id, None, [])?;
        }
        Ok(())
    }

    /// A `Private` variable (module scope, also for a function's `static`
    /// locals) of type `tid` starting as `init`.
    fn private_var(&mut self, tid: Id, init: Id, name: &str) -> Id {
        let pty = self.b.type_pointer(None, StorageClass::Private, tid);
        let var = self.global_var(pty, StorageClass::Private, Some(init));
        self.b.name(var, name.to_string());
        self.use_global(var);
        var
    }
}
