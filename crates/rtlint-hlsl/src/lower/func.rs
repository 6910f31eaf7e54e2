//! Functions: bodies, entry-point parameters, stage variables and the
//! per-function emission helpers.

use super::inline_spirv::no_ext_decorate;
use super::*;

impl<'a> Lowerer<'a> {
    pub(super) fn check_recursion(&self) -> Result<()> {
        // Depth-first search for a cycle in the call graph.
        fn visit(
            k: usize,
            calls: &HashMap<usize, BTreeSet<usize>>,
            state: &mut HashMap<usize, u8>,
        ) -> Option<usize> {
            match state.get(&k) {
                Some(1) => return Some(k),
                Some(2) => return None,
                _ => {}
            }
            state.insert(k, 1);
            for c in calls.get(&k).into_iter().flatten() {
                if let Some(r) = visit(*c, calls, state) {
                    return Some(r);
                }
            }
            state.insert(k, 2);
            None
        }
        let mut state = HashMap::new();
        let mut keys: Vec<usize> = self.fn_calls.keys().copied().collect();
        keys.sort_unstable();
        for k in keys {
            if let Some(r) = visit(k, &self.fn_calls, &mut state) {
                let f = self.funcs[r].func;
                return Err(Error::new(
                    f.pos,
                    format!(
                        "function `{}` is recursive; HLSL does not allow recursion",
                        f.name
                    ),
                )
                .len(f.name.len() as u32));
            }
        }
        Ok(())
    }

    /// Static globals with non-constant initializers, computed at the start
    /// of an entry point (as DXC does): each in its own namespace, seeing
    /// globals only.
    pub(super) fn run_deferred_inits(&mut self) -> Result<()> {
        let scopes = std::mem::replace(&mut self.f.scopes, vec![HashMap::new()]);
        let ns = self.f.cur_ns.clone();
        for (var, t, e, scope) in self.deferred_inits.clone() {
            self.f.cur_ns = scope;
            self.line(e.pos);
            let v = self.expr_as(e, &t)?;
            self.use_global(var);
            if self.f.term {
                self.start_block(None)?;
            }
            self.b.store(var, v.id, None, [])?;
        }
        self.f.cur_ns = ns;
        self.f.scopes = scopes;
        Ok(())
    }

    pub(super) fn lower_function(&mut self, k: usize) -> Result<()> {
        let sig = self.funcs[k].clone();
        let f = sig.func;
        self.f = FnCtx::new(k, &f.ns, sig.stage, sig.ret.clone());
        if sig.ret.is_opaque() {
            return Err(unsupported(
                f.ret.pos,
                format!("functions returning a {}", self.ty_name(&sig.ret)),
            ));
        }
        let ret_id = self.ty_id(&sig.ret)?;
        // A pixel entry point is lowered as an ordinary function (`src.NAME`,
        // as DXC names it) that a wrapper calls; see `pixel_wrapper`.
        if let Some(stage) = sig.stage.filter(|s| *s != Stage::Fragment) {
            if sig.ret != Ty::Void {
                return Err(unsupported(
                    f.ret.pos,
                    format!("{} entry points returning a value", stage.hlsl_name()),
                ));
            }
            let fty = self.b.type_function(ret_id, []);
            self.b
                .begin_function(ret_id, Some(sig.id), spirv::FunctionControl::NONE, fty)?;
            self.b.name(sig.id, f.name.clone());
            self.start_block(None)?;
            self.line(f.pos);
            self.f.this_place = None;
            self.bind_entry_params(f, &sig, stage)?;
            self.run_deferred_inits()?;
        } else {
            let mut ptys = Vec::new();
            let is_bound = |i: usize| sig.bound.iter().any(|(b, _)| *b == i);
            for (i, p) in sig.params.iter().enumerate() {
                if is_bound(i) {
                    continue;
                }
                let (class, _) = self.param_class(&p.ty);
                let t = if p.ty.is_resource() {
                    self.descriptor_array_type(&p.ty, &[])?.0
                } else {
                    self.ty_id(&p.ty)?
                };
                ptys.push(self.b.type_pointer(None, class, t));
            }
            if let Some((t, _)) = &sig.ret_slot {
                // The caller's ray query variable, where the result is made.
                let tid = self.ty_id(t)?;
                ptys.push(self.b.type_pointer(None, StorageClass::Function, tid));
            }
            let fty = self.b.type_function(ret_id, ptys.clone());
            self.b
                .begin_function(ret_id, Some(sig.id), spirv::FunctionControl::NONE, fty)?;
            if sig.stage == Some(Stage::Fragment) {
                self.b.name(sig.id, format!("src.{}", sig.name));
            } else {
                self.b.name(sig.id, sig.name.clone());
            }
            let mut ptys = ptys.into_iter();
            let mut params = sig.params.iter();
            if let Some(k) = sig.this {
                // `this`, and each member by its bare name.
                let pty = ptys.next().unwrap_or_default();
                let p = params.next().map(|p| p.ty.clone()).unwrap_or(Ty::Struct(k));
                let id = self.b.function_parameter(pty)?;
                self.b.name(id, "this");
                let this = Place::Ptr {
                    ptr: id,
                    ty: p,
                    layout: Layout::None,
                    class: StorageClass::Function,
                };
                self.f.scopes[0].insert("this".to_string(), this.clone());
                self.f.this_place = Some(this);
            } else {
                self.f.this_place = None;
            }
            let first = sig.this.is_some() as usize;
            for (j, (p, decl)) in params.zip(&f.params).enumerate() {
                if let Some((_, place)) = sig.bound.iter().find(|(b, _)| *b == j + first) {
                    // A buffer this copy is specialized on: no parameter.
                    no_ext_decorate(&decl.attrs, "a resource parameter")?;
                    if let Place::Ptr { ptr, .. } = place {
                        self.use_global(*ptr);
                    }
                    self.f.scopes[0].insert(decl.name.clone(), place.clone());
                    continue;
                }
                let pty = ptys.next().unwrap_or_default();
                let id = self.b.function_parameter(pty)?;
                self.b.name(id, decl.name.clone());
                if sig.stage.is_some() {
                    // A pixel entry point's parameters are its inputs.
                    no_ext_decorate(&decl.attrs, "an entry point's parameter")?;
                }
                self.ext_decorate(&decl.attrs, id)?;
                if p.ty.is_resource() {
                    self.resource_vars.insert(id);
                }
                self.local_decls.push((
                    self.f.cur_fn,
                    id,
                    decl.name.clone(),
                    p.ty.clone(),
                    decl.pos,
                ));
                let (class, layout) = self.param_class(&p.ty);
                self.f.scopes[0].insert(
                    decl.name.clone(),
                    Place::Ptr {
                        ptr: id,
                        ty: p.ty.clone(),
                        layout,
                        class,
                    },
                );
            }
            if let Some((t, name)) = &sig.ret_slot {
                let pty = ptys.next().unwrap_or_default();
                let id = self.b.function_parameter(pty)?;
                self.b.name(id, name.clone());
                let slot = Place::Ptr {
                    ptr: id,
                    ty: t.clone(),
                    layout: Layout::None,
                    class: StorageClass::Function,
                };
                self.f.ret_slot = Some((name.clone(), slot));
            }
            self.start_block(None)?;
        }
        let req = self.ext_requirements(&f.attrs)?;
        self.require(&req);
        let body = f.body.as_deref().unwrap_or(&[]);
        self.block(body)?;
        if !self.f.term {
            if sig.ret == Ty::Void {
                self.b.ret()?;
            } else {
                self.b.unreachable()?;
            }
        }
        self.b.end_function()?;
        Ok(())
    }

    /// How a parameter is passed: values by a Function-storage pointer (the
    /// caller's copy); resources by a pointer to the resource variable itself.
    pub(super) fn param_class(&self, t: &Ty) -> (StorageClass, Layout) {
        match t {
            Ty::StructuredBuffer(..) | Ty::ByteAddress(_) => {
                (StorageClass::StorageBuffer, Layout::Std430)
            }
            Ty::ConstantBuffer(_) => (StorageClass::Uniform, Layout::CBuffer),
            Ty::Accel | Ty::Sampler | Ty::SamplerCmp | Ty::Texture { .. } => {
                (StorageClass::UniformConstant, Layout::None)
            }
            Ty::Array(e, _) | Ty::RtArray(e) if e.is_resource() => self.param_class(e),
            _ => (StorageClass::Function, Layout::None),
        }
    }

    pub(super) fn bind_entry_params(
        &mut self,
        f: &'a Function,
        sig: &FnSig,
        stage: Stage,
    ) -> Result<()> {
        for (i, (p, decl)) in sig.params.iter().zip(&f.params).enumerate() {
            // Entry point parameters become stage variables or payloads.
            no_ext_decorate(&decl.attrs, "an entry point's parameter")?;
            let is_struct = matches!(p.ty, Ty::Struct(_));
            // DXR fixes the parameters by position: payload (or callable data)
            // first, `inout`; hit attributes second, `in`.
            let class = match (stage, i) {
                (Stage::ClosestHit | Stage::AnyHit | Stage::Miss, 0)
                    if is_struct && p.out && p.input =>
                {
                    Some(StorageClass::IncomingRayPayloadKHR)
                }
                (Stage::ClosestHit | Stage::AnyHit, 1) if is_struct && !p.out => {
                    Some(StorageClass::HitAttributeKHR)
                }
                (Stage::Callable, 0) if is_struct && p.out && p.input => {
                    Some(StorageClass::IncomingCallableDataKHR)
                }
                _ => None,
            };
            if let Some(class) = class {
                let var = self.rt_var(class, &p.ty)?;
                self.f.scopes[0].insert(
                    decl.name.clone(),
                    Place::Ptr {
                        ptr: var,
                        ty: p.ty.clone(),
                        layout: Layout::None,
                        class,
                    },
                );
                continue;
            }
            if stage == Stage::Compute && !p.out {
                let Some((sem, spos)) = &decl.semantic else {
                    return Err(Error::new(
                        decl.pos,
                        "compute entry point parameters need a system-value semantic",
                    ));
                };
                let (bi, bty) = match sem.to_ascii_uppercase().as_str() {
                    "SV_DISPATCHTHREADID" => {
                        (BuiltIn::GlobalInvocationId, Ty::Vec(ScalarKind::Uint, 3))
                    }
                    "SV_GROUPTHREADID" => {
                        (BuiltIn::LocalInvocationId, Ty::Vec(ScalarKind::Uint, 3))
                    }
                    "SV_GROUPID" => (BuiltIn::WorkgroupId, Ty::Vec(ScalarKind::Uint, 3)),
                    "SV_GROUPINDEX" => (
                        BuiltIn::LocalInvocationIndex,
                        Ty::ScalarKind(ScalarKind::Uint),
                    ),
                    _ => {
                        return Err(unsupported(
                            *spos,
                            format!("semantic `{sem}` on a compute parameter"),
                        ))
                    }
                };
                let v = self.read_builtin(bi, &bty)?;
                let v = self.convert(v, &p.ty, decl.pos, true)?;
                let var = self.local_var(&p.ty, &decl.name)?;
                self.b.store(var, v.id, None, [])?;
                self.f.scopes[0].insert(
                    decl.name.clone(),
                    Place::Ptr {
                        ptr: var,
                        ty: p.ty.clone(),
                        layout: Layout::None,
                        class: StorageClass::Function,
                    },
                );
                continue;
            }
            return Err(unsupported(
                decl.pos,
                format!("this parameter in a {} entry point", stage.hlsl_name()),
            )
            .len(decl.name.len() as u32)
            .note("ray-tracing entry points take `inout` payload / callable data and `in` hit attributes (structs)"));
        }
        Ok(())
    }

    /// The ray-tracing interface variable of `class` for type `t` (one per type).
    pub(super) fn rt_var(&mut self, class: StorageClass, t: &Ty) -> Result<Id> {
        self.rt_var_named(class, t, None)
    }

    /// [`Self::rt_var`]; a payload variable made now is named after `arg`
    /// when it is a variable (`rtlint live` names payloads by what the
    /// source traces), else `payload`.
    pub(super) fn rt_var_named(
        &mut self,
        class: StorageClass,
        t: &Ty,
        arg: Option<&Expr>,
    ) -> Result<Id> {
        self.ray_tracing_caps();
        let key = (class, t.clone());
        let var = match self.rt_vars.get(&key) {
            Some(v) => *v,
            None => {
                let tid = self.ty_id(t)?;
                let pty = self.b.type_pointer(None, class, tid);
                let var = self.global_var(pty, class, None);
                let name = match (class, arg.map(|e| &e.kind)) {
                    (StorageClass::RayPayloadKHR, Some(ExprKind::Ident(n))) => n.as_str(),
                    _ => match class {
                        StorageClass::RayPayloadKHR => "payload",
                        StorageClass::IncomingRayPayloadKHR => "incoming.payload",
                        StorageClass::HitAttributeKHR => "hit.attributes",
                        StorageClass::CallableDataKHR => "callable.data",
                        _ => "incoming.callable.data",
                    },
                };
                self.b.name(var, name);
                if matches!(
                    class,
                    StorageClass::RayPayloadKHR | StorageClass::CallableDataKHR
                ) {
                    let n = self.next_location.entry(class).or_insert(0);
                    let loc = *n;
                    *n += 1;
                    self.b
                        .decorate(var, Decoration::Location, [Operand::LiteralBit32(loc)]);
                }
                self.rt_vars.insert(key, var);
                var
            }
        };
        self.use_global(var);
        Ok(var)
    }

    /// A module-scope variable, even while a function is being emitted
    /// (`Builder::variable` would put it in the selected block).
    pub(super) fn global_var(&mut self, pty: Id, class: StorageClass, init: Option<Id>) -> Id {
        let id = self.b.id();
        let mut ops = vec![Operand::StorageClass(class)];
        ops.extend(init.map(Operand::IdRef));
        self.b.insert_types_global_values(
            InsertPoint::End,
            Instruction::new(Op::Variable, Some(pty), Some(id), ops),
        );
        id
    }

    pub(super) fn use_global(&mut self, id: Id) {
        self.fn_used.entry(self.f.cur_fn).or_default().insert(id);
        if let Some(req) = self.global_reqs.get(&id).cloned() {
            self.require(&req);
        }
    }

    pub(super) fn read_builtin(&mut self, bi: BuiltIn, t: &Ty) -> Result<Val> {
        let var = match self.builtins.get(&bi) {
            Some(v) => *v,
            None => {
                let tid = self.ty_id(t)?;
                let pty = self.b.type_pointer(None, StorageClass::Input, tid);
                let var = self.global_var(pty, StorageClass::Input, None);
                self.b
                    .decorate(var, Decoration::BuiltIn, [Operand::BuiltIn(bi)]);
                self.b.name(var, format!("{bi:?}"));
                self.builtins.insert(bi, var);
                self.builtin_vars.insert(
                    var,
                    system_values::BuiltinVar {
                        builtin: bi,
                        class: StorageClass::Input,
                        integer: system_values::integer_ty(t),
                        declared: None,
                    },
                );
                var
            }
        };
        self.use_global(var);
        let tid = self.ty_id(t)?;
        let id = self.b.load(tid, None, var, None, [])?;
        Ok(Val { id, ty: t.clone() })
    }

    pub(super) fn start_block(&mut self, label: Option<Id>) -> Result<Id> {
        let l = self.b.begin_block(label)?;
        self.f.cur_label = l;
        self.f.term = false;
        Ok(l)
    }

    pub(super) fn line(&mut self, pos: Pos) {
        if self.f.term || self.b.selected_block().is_none() {
            return;
        }
        if let Some(f) = self.file_ids.get(pos.file as usize) {
            let f = *f;
            self.b.line(f, pos.line, pos.col);
        }
    }

    /// Emits one instruction with a result; starts a dead block after a terminator.
    pub(super) fn op(&mut self, op: Op, ty: Id, args: &[Id]) -> Result<Id> {
        self.inst(
            op,
            Some(ty),
            args.iter().map(|a| Operand::IdRef(*a)).collect(),
        )
    }

    pub(super) fn inst(&mut self, op: Op, ty: Option<Id>, operands: Vec<Operand>) -> Result<Id> {
        if self.f.term {
            self.start_block(None)?;
        }
        let id = self.b.id();
        // Pointers reached through a NonUniformResourceIndex stay NonUniform.
        let nonuniform = op == Op::AccessChain
            && operands.iter().enumerate().any(|(i, o)| {
                matches!(o, Operand::IdRef(x)
                    if (i == 0 && self.nonuniform_ptrs.contains(x)) || (i > 0 && self.nonuniform.contains(x)))
            });
        let inst = Instruction::new(op, ty, ty.map(|_| id), operands);
        self.b.insert_into_block(InsertPoint::End, inst)?;
        if nonuniform {
            self.b.decorate(id, Decoration::NonUniform, []);
            self.nonuniform_ptrs.insert(id);
        }
        Ok(id)
    }

    pub(super) fn local_var(&mut self, t: &Ty, name: &str) -> Result<Id> {
        let tid = self.ty_id(t)?;
        let pty = self.b.type_pointer(None, StorageClass::Function, tid);
        if self.f.term {
            self.start_block(None)?;
        }
        // Placed here, hoisted to the entry block when the module is finished.
        let id = self.b.variable(pty, None, StorageClass::Function, None);
        if !name.is_empty() {
            self.b.name(id, name);
        }
        Ok(id)
    }
}
