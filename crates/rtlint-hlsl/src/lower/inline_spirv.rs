//! DXC's inline-SPIR-V attributes: built-in inputs and outputs
//! (`vk::ext_builtin_input`, `vk::ext_builtin_output`), member decorations
//! (`vk::ext_decorate`) and instructions (`vk::ext_instruction`).

use super::*;

impl<'a> Lowerer<'a> {
    /// `[[vk::ext_builtin_input(N)]] static const T name;`: an `Input`
    /// variable decorated `BuiltIn N`; `[[vk::ext_builtin_output(N)]] static
    /// T name;`: an `Output` one, which the shader writes (with the
    /// extensions and capabilities its other `vk::ext_*` attributes name,
    /// added where it is used).
    pub(super) fn declare_ext_builtin(&mut self, v: &'a VarDecl) -> Result<()> {
        let Some((a, class)) = v.attrs.iter().find_map(|a| match a.name.as_str() {
            "vk::ext_builtin_input" => Some((a, StorageClass::Input)),
            "vk::ext_builtin_output" => Some((a, StorageClass::Output)),
            _ => None,
        }) else {
            return Ok(());
        };
        let output = class == StorageClass::Output;
        // DXC's rule: an input is `static const`, an output `static`.
        if !v.mods.is_static || v.mods.is_const == output || v.init.is_some() {
            return Err(Error::new(
                v.pos,
                format!(
                    "a `{}` variable must be `{}` without an initializer",
                    a.name,
                    if output { "static" } else { "static const" }
                ),
            ));
        }
        let e = a
            .args
            .first()
            .ok_or_else(|| Error::new(a.pos, format!("expected [[{}(N)]]", a.name)))?;
        let n = self.const_int(e)?;
        let bi = u32::try_from(n)
            .ok()
            .and_then(BuiltIn::from_u32)
            .ok_or_else(|| Error::new(e.pos, format!("unknown SPIR-V built-in {n}")))?;
        // DXC's rule: one built-in is an input or an output, not both.
        if let Some(prev) = self
            .builtin_vars
            .values()
            .find(|b| b.builtin == bi && b.class != class && b.declared.is_some())
        {
            let e = Error::new(
                v.pos,
                format!(
                    "built-in `{bi:?}` ({n}) is already declared as an {}; it cannot be redefined as an {}",
                    if output { "input" } else { "output" },
                    if output { "output" } else { "input" }
                ),
            )
            .len(v.name.len() as u32);
            return Err(match prev.declared {
                Some(p) => e.secondary(p, "first declared here"),
                None => e,
            });
        }
        let mut req = self.ext_requirements(&v.attrs)?;
        // The capability the SPIR-V grammar gives the built-in (any one of
        // those it lists; the first one Vulkan has, unless one is named).
        let caps = Operand::BuiltIn(bi).required_capabilities();
        if !caps.iter().any(|c| req.1.contains(c)) {
            if let Some(c) = caps.into_iter().find(|c| kernel_only(*c).is_none()) {
                req.1.push(c);
            }
        }
        let t = self.resolve_ty(&v.ty, "")?;
        let t = self.apply_dims(t, &v.dims, v.pos, false)?;
        if t.is_resource() || (matches!(t, Ty::RtArray(_)) || t.is_opaque()) {
            return Err(Error::new(
                v.pos,
                "a built-in variable must be a value type",
            ));
        }
        let tid = self.ty_id(&t)?;
        let pty = self.b.type_pointer(None, class, tid);
        let var = self.global_var(pty, class, None);
        self.b.name(var, v.name.clone());
        self.b
            .decorate(var, Decoration::BuiltIn, [Operand::BuiltIn(bi)]);
        self.global_reqs.insert(var, req);
        self.builtin_vars.insert(
            var,
            super::system_values::BuiltinVar {
                builtin: bi,
                class,
                integer: super::system_values::integer_ty(&t),
                declared: Some(v.pos),
            },
        );
        self.global_decls
            .push((var, v.name.clone(), t.clone(), v.pos));
        self.globals.insert(
            v.name.clone(),
            Global::Place(Place::Ptr {
                ptr: var,
                ty: t,
                layout: Layout::None,
                class,
            }),
        );
        Ok(())
    }

    /// `[[vk::ext_decorate(decoration, literals...)]]`: the decoration and
    /// its literal operands, as constant integers.
    pub(super) fn ext_decoration(&mut self, a: &Attr) -> Result<(Decoration, Vec<u32>)> {
        let Some((first, rest)) = a.args.split_first() else {
            return Err(Error::new(
                a.pos,
                "expected [[vk::ext_decorate(decoration, ...)]]",
            ));
        };
        let n = self.const_int(first)?;
        let d = u32::try_from(n)
            .ok()
            .and_then(Decoration::from_u32)
            .ok_or_else(|| Error::new(first.pos, format!("unknown SPIR-V decoration {n}")))?;
        let mut ops = Vec::new();
        for e in rest {
            let v = self.const_int(e)?;
            ops.push(u32::try_from(v).map_err(|_| {
                Error::new(e.pos, format!("{v} is not a 32-bit decoration literal"))
            })?);
        }
        Ok((d, ops))
    }

    /// `[[vk::ext_decorate]]` on a global variable or a parameter: an
    /// `OpDecorate` of `target` per attribute, as DXC emits them.
    pub(super) fn ext_decorate(&mut self, attrs: &[Attr], target: Id) -> Result<()> {
        for a in attrs.iter().filter(|a| a.name == "vk::ext_decorate") {
            let (d, ops) = self.ext_decoration(a)?;
            self.b.decorate(target, d, decoration_operands(d, ops));
        }
        Ok(())
    }
}

/// Extended instruction sets a Vulkan module may import: GLSL.std.450, the
/// debug-info sets, AMD's, and any non-semantic one (`NonSemantic.*`).
fn known_instruction_set(name: &str) -> bool {
    name.starts_with("NonSemantic.")
        || matches!(
            name,
            "GLSL.std.450"
                | "DebugInfo"
                | "OpenCL.DebugInfo.100"
                | "SPV_AMD_shader_ballot"
                | "SPV_AMD_shader_explicit_vertex_parameter"
                | "SPV_AMD_gcn_shader"
                | "SPV_AMD_shader_trinary_minmax"
        )
}

/// A decoration's literal operands as rspirv operands (a `BuiltIn` typed,
/// so the module disassembles by name).
pub(super) fn decoration_operands(d: Decoration, ops: Vec<u32>) -> Vec<Operand> {
    match (d, ops.as_slice()) {
        (Decoration::BuiltIn, [b]) => match BuiltIn::from_u32(*b) {
            Some(b) => vec![Operand::BuiltIn(b)],
            None => vec![Operand::LiteralBit32(*b)],
        },
        _ => ops.into_iter().map(Operand::LiteralBit32).collect(),
    }
}

/// Refuses `[[vk::ext_decorate]]` on a declaration that becomes no variable
/// of its own (`on` says what it is), rather than dropping it.
pub(super) fn no_ext_decorate(attrs: &[Attr], on: &str) -> Result<()> {
    match attrs.iter().find(|a| a.name == "vk::ext_decorate") {
        Some(a) => {
            Err(unsupported(a.pos, format!("`vk::ext_decorate` on {on}")).len(a.name.len() as u32))
        }
        None => Ok(()),
    }
}

impl<'a> Lowerer<'a> {
    /// A call of a `[[vk::ext_instruction(opcode, "set")]]` declaration:
    /// `OpExtInst` of the imported set, or the raw opcode without a set
    /// (no result for `void`), with the arguments as operands. `None` when
    /// `name` is no such declaration.
    pub(super) fn ext_instruction_call(
        &mut self,
        name: &str,
        args: &'a [Expr],
        pos: Pos,
    ) -> Result<Option<Option<Val>>> {
        let Some(f) = self
            .scoped_names(name)
            .iter()
            .find_map(|n| self.ext_insts.get(n))
            .copied()
        else {
            return Ok(None);
        };
        let a = f
            .attrs
            .iter()
            .find(|a| a.name == "vk::ext_instruction")
            .expect("registered with the attribute");
        let expected = || Error::new(a.pos, "expected [[vk::ext_instruction(opcode, \"set\")]]");
        let (op_e, set) = match &a.args[..] {
            [o] => (o, None),
            [o, s] => match &s.kind {
                // A set spirv-val does not know makes the module invalid.
                ExprKind::Str(name) if !known_instruction_set(name) => {
                    return Err(unsupported(
                        s.pos,
                        format!("extended instruction set \"{name}\""),
                    ))
                }
                ExprKind::Str(s) => (o, Some(s.clone())),
                _ => return Err(expected()),
            },
            _ => return Err(expected()),
        };
        let n = self.const_int(op_e)?;
        let opcode = u32::try_from(n)
            .map_err(|_| Error::new(op_e.pos, format!("{n} is not a SPIR-V opcode")))?;
        if args.len() != f.params.len() {
            return Err(Error::new(
                pos,
                format!("`{name}` takes {} argument(s)", f.params.len()),
            )
            .len(name.len() as u32));
        }
        let ret = self.resolve_ty(&f.ret, &f.ns)?;
        if ret.is_opaque() || ret.is_resource() {
            return Err(unsupported(
                f.ret.pos,
                format!("`vk::ext_instruction` returning a {}", self.ty_name(&ret)),
            ));
        }
        let mut ops = Vec::new();
        for (p, e) in f.params.iter().zip(args) {
            let t = self.resolve_ty(&p.ty, &f.ns)?;
            let t = self.apply_dims(t, &p.dims, p.pos, false)?;
            no_ext_decorate(&p.attrs, "a parameter of a `vk::ext_instruction` function")?;
            let has = |n: &str| p.attrs.iter().any(|a| a.name == n);
            if has("vk::ext_reference") {
                // The pointer itself: only a variable holding exactly the
                // parameter's type (no layout) has one of the right type.
                match self.place(e)? {
                    Place::Ptr {
                        ptr,
                        ty,
                        layout: Layout::None,
                        ..
                    } if ty == t => ops.push(Operand::IdRef(ptr)),
                    _ => {
                        return Err(unsupported(
                            e.pos,
                            format!(
                                "a `vk::ext_reference` argument other than a variable of type `{}`",
                                self.ty_name(&t)
                            ),
                        ))
                    }
                }
            } else if has("vk::ext_literal") {
                if !matches!(t, Ty::ScalarKind(ScalarKind::Int | ScalarKind::Uint)) {
                    return Err(unsupported(
                        p.pos,
                        "`vk::ext_literal` parameters other than 32-bit integers",
                    ));
                }
                let v = self.const_int(e).map_err(|_| {
                    Error::new(e.pos, "a `vk::ext_literal` argument must be a constant")
                })?;
                let v = u32::try_from(v)
                    .or_else(|_| i32::try_from(v).map(|v| v as u32))
                    .map_err(|_| Error::new(e.pos, format!("{v} is not a 32-bit literal")))?;
                ops.push(Operand::LiteralBit32(v));
            } else if p.mods.output {
                return Err(unsupported(
                    p.pos,
                    "`out` parameters of a `vk::ext_instruction` function (use `vk::ext_reference`)",
                ));
            } else {
                let v = self.expr(e)?;
                let v = self.convert(v, &t, e.pos, false)?;
                ops.push(Operand::IdRef(v.id));
            }
        }
        let req = self.ext_requirements(&f.attrs)?;
        self.require(&req);
        let rt = self.ty_id(&ret)?;
        let id = match set {
            Some(s) => {
                let set = match self.ext_sets.get(&s) {
                    Some(id) => *id,
                    None if s == "GLSL.std.450" => self.glsl,
                    None => {
                        let id = self.b.ext_inst_import(s.clone());
                        self.ext_sets.insert(s, id);
                        id
                    }
                };
                let mut all = vec![Operand::IdRef(set), Operand::LiteralExtInstInteger(opcode)];
                all.extend(ops);
                // `OpExtInst` always has a result, `void` typed for `void`.
                self.inst(Op::ExtInst, Some(rt), all)?
            }
            None => {
                let op = Op::from_u32(opcode).ok_or_else(|| {
                    unsupported(
                        op_e.pos,
                        format!("SPIR-V opcode {opcode} (unknown to rtlint)"),
                    )
                })?;
                let ty = (ret != Ty::Void).then_some(rt);
                self.inst(op, ty, ops)?
            }
        };
        Ok(Some((ret != Ty::Void).then_some(Val { id, ty: ret })))
    }
}
