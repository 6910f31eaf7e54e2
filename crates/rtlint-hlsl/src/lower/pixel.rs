//! Pixel shaders: the entry point is a wrapper, as DXC emits it, that loads
//! the stage inputs into locals, calls the user's function (`src.NAME`) and
//! stores its `out` parameters and return value to the stage outputs.

use super::*;

#[derive(Clone, Copy, PartialEq)]
enum Dir {
    In,
    Out,
}

/// Interface variables being assigned for one wrapper.
#[derive(Default)]
struct Io {
    vars: Vec<Id>,
    /// Locations taken (inputs, outputs), with the semantic that took each.
    taken: [HashMap<u32, String>; 2],
    next_input: u32,
    /// Whether input locations come from `[[vk::location]]` (set by the first input).
    explicit: Option<bool>,
    /// Built-in inputs taken, with where their semantic was written.
    builtins: HashMap<BuiltIn, Pos>,
}

impl<'a> Lowerer<'a> {
    /// Emits the wrapper for pixel entry `k`; gives its id and interface variables.
    pub(super) fn pixel_wrapper(&mut self, k: usize) -> Result<(Id, Vec<Id>)> {
        let sig = self.funcs[k].clone();
        let f = sig.func;
        self.f = FnCtx::new(k, &f.ns, Some(Stage::Fragment), Ty::Void);
        let void = self.b.type_void();
        let fty = self.b.type_function(void, []);
        let id = self.b.id();
        self.b
            .begin_function(void, Some(id), spirv::FunctionControl::NONE, fty)?;
        self.b.name(id, sig.name.clone());
        self.start_block(None)?;
        self.line(f.pos);
        self.run_deferred_inits()?;
        let mut io = Io::default();
        let mut args = Vec::new();
        let mut outs = Vec::new();
        for (p, decl) in sig.params.iter().zip(&f.params) {
            if p.ty.is_resource() || p.ty.is_opaque() {
                return Err(
                    unsupported(decl.pos, "resource parameters on a pixel entry point")
                        .len(decl.name.len() as u32),
                );
            }
            let var = self.local_var(&p.ty, &decl.name)?;
            if p.input {
                self.pixel_io(
                    Dir::In,
                    &p.ty,
                    &decl.semantic,
                    &decl.attrs,
                    decl.mods,
                    decl.pos,
                    var,
                    &mut vec![],
                    &mut io,
                )?;
            }
            if p.out {
                outs.push((
                    var,
                    p.ty.clone(),
                    decl.semantic.clone(),
                    decl.attrs.clone(),
                    decl.pos,
                ));
            }
            args.push(var);
        }
        let ret_id = self.ty_id(&sig.ret)?;
        let r = self.b.function_call(ret_id, None, sig.id, args)?;
        self.fn_calls.entry(k).or_default();
        if sig.ret != Ty::Void {
            let var = self.local_var(&sig.ret, "")?;
            self.b.store(var, r, None, [])?;
            let sem = f.semantic.clone();
            if sem.is_none() && !matches!(sig.ret, Ty::Struct(_)) {
                return Err(Error::new(
                    f.ret.pos,
                    "a pixel shader's return value needs a semantic such as `SV_Target`",
                ));
            }
            outs.push((var, sig.ret.clone(), sem, Vec::new(), f.ret.pos));
        }
        for (var, ty, sem, attrs, pos) in outs {
            let mods = Mods::default();
            self.pixel_io(
                Dir::Out,
                &ty,
                &sem,
                &attrs,
                mods,
                pos,
                var,
                &mut vec![],
                &mut io,
            )?;
        }
        self.b.ret()?;
        self.b.end_function()?;
        Ok((id, io.vars))
    }

    /// Connects the part of local `local` at member `path` (of type `ty`) to
    /// stage inputs or outputs; structs are flattened member by member, as DXC does.
    #[allow(clippy::too_many_arguments)]
    fn pixel_io(
        &mut self,
        dir: Dir,
        ty: &Ty,
        sem: &Option<(String, Pos)>,
        attrs: &[Attr],
        mods: Mods,
        pos: Pos,
        local: Id,
        path: &mut Vec<u32>,
        io: &mut Io,
    ) -> Result<()> {
        if let Ty::Struct(s) = ty {
            if let Some((_, spos)) = sem {
                return Err(unsupported(
                    *spos,
                    "a semantic on a struct; give each member its own",
                ));
            }
            let fields = self.structs[*s as usize].fields.clone();
            let Some(member_io) = self.struct_io.get(s).cloned() else {
                return Err(unsupported(
                    pos,
                    format!("`{}` as a pixel shader input or output", self.ty_name(ty)),
                ));
            };
            for (i, (field, (fsem, fattrs, fmods))) in fields.iter().zip(member_io).enumerate() {
                path.push(i as u32);
                self.pixel_io(
                    dir, &field.ty, &fsem, &fattrs, fmods, field.pos, local, path, io,
                )?;
                path.pop();
            }
            return Ok(());
        }
        let what = if dir == Dir::In { "input" } else { "output" };
        let Some((sem, spos)) = sem else {
            return Err(Error::new(
                pos,
                format!("pixel shader {what}s need a semantic"),
            ));
        };
        let spos = *spos;
        let upper = sem.to_ascii_uppercase();
        let sem_len = sem.len() as u32;
        let user_location = attrs
            .iter()
            .find(|a| a.name == "vk::location")
            .map(|a| match a.args.as_slice() {
                [e] => self.const_int(e).and_then(|n| {
                    u32::try_from(n)
                        .map_err(|_| Error::new(a.pos, "[[vk::location]] needs a location from 0"))
                }),
                _ => Err(Error::new(a.pos, "[[vk::location]] needs one location")),
            })
            .transpose()?;
        let plain = matches!(ty, Ty::ScalarKind(s) | Ty::Vec(s, _) if *s != ScalarKind::Bool);
        // (built-in, its SPIR-V type) or a location.
        let (builtin, location) = match (dir, upper.as_str()) {
            (Dir::In, "SV_POSITION") if *ty == Ty::Vec(ScalarKind::Float, 4) => {
                (Some((BuiltIn::FragCoord, ty.clone())), None)
            }
            (Dir::In, "SV_ISFRONTFACE") if *ty == Ty::ScalarKind(ScalarKind::Bool) => (
                Some((BuiltIn::FrontFacing, Ty::ScalarKind(ScalarKind::Bool))),
                None,
            ),
            (Dir::In, "SV_POSITION" | "SV_ISFRONTFACE") => {
                return Err(Error::new(
                    pos,
                    format!(
                        "`{sem}` must be a `{}`",
                        if upper == "SV_POSITION" {
                            "float4"
                        } else {
                            "bool"
                        }
                    ),
                ));
            }
            (Dir::Out, t) if t.starts_with("SV_TARGET") && plain => {
                let n = &t["SV_TARGET".len()..];
                let n = if n.is_empty() {
                    Some(0)
                } else {
                    n.parse::<u32>().ok().filter(|n| *n < 8)
                };
                let Some(n) = n else {
                    return Err(Error::new(
                        spos,
                        format!("`{sem}` names no render target (SV_Target0 to SV_Target7)"),
                    )
                    .len(sem_len));
                };
                (None, Some(n))
            }
            (_, t) if t.starts_with("SV_") => {
                return Err(unsupported(
                    spos,
                    format!("semantic `{sem}` on a pixel shader {what}"),
                )
                .len(sem_len));
            }
            (Dir::Out, _) => {
                return Err(Error::new(
                    spos,
                    format!(
                        "pixel shader outputs are render targets (`SV_Target[n]`), not `{sem}`"
                    ),
                )
                .len(sem_len));
            }
            (Dir::In, _) if plain => {
                // DXC refuses a mix too: implicit numbers could collide with explicit ones.
                if *io.explicit.get_or_insert(user_location.is_some()) != user_location.is_some() {
                    return Err(Error::new(
                        spos,
                        "pixel shader inputs either all have `[[vk::location]]` or none do",
                    )
                    .len(sem_len));
                }
                let n = user_location.unwrap_or(io.next_input);
                io.next_input = n + 1;
                (None, Some(n))
            }
            (Dir::In, _) => {
                return Err(unsupported(
                    pos,
                    format!(
                        "`{}` as a pixel shader input (scalars and vectors only)",
                        self.ty_name(ty)
                    ),
                ));
            }
        };
        if let Some((bi, _)) = &builtin {
            // DXC's rule: one built-in input per entry point.
            if let Some(first) = io.builtins.insert(*bi, spos) {
                return Err(Error::new(
                    spos,
                    format!("input semantic `{sem}` used more than once"),
                )
                .len(sem_len)
                .secondary(first, "first used here"));
            }
        }
        if let Some(n) = location {
            let d = (dir == Dir::Out) as usize;
            if let Some(other) = io.taken[d].insert(n, sem.clone()) {
                return Err(Error::new(
                    spos,
                    format!("`{sem}` takes {what} location {n}, already taken by `{other}`"),
                )
                .len(sem_len));
            }
        }
        let class = if dir == Dir::In {
            StorageClass::Input
        } else {
            StorageClass::Output
        };
        let var_ty = builtin
            .as_ref()
            .map(|b| b.1.clone())
            .unwrap_or_else(|| ty.clone());
        let tid = self.ty_id(&var_ty)?;
        let pty = self.b.type_pointer(None, class, tid);
        let var = self.global_var(pty, class, None);
        let prefix = if dir == Dir::In {
            "in.var."
        } else {
            "out.var."
        };
        match (builtin, location) {
            (Some((bi, _)), _) => {
                self.b
                    .decorate(var, Decoration::BuiltIn, [Operand::BuiltIn(bi)]);
                self.b.name(var, format!("gl_{bi:?}"));
            }
            (None, Some(n)) => {
                self.b
                    .decorate(var, Decoration::Location, [Operand::LiteralBit32(n)]);
                self.b.name(var, format!("{prefix}{sem}"));
                // Vulkan: integer fragment inputs are not interpolated.
                let integer = system_values::integer_ty(ty);
                if dir == Dir::In && (integer || mods.nointerp) {
                    self.b.decorate(var, Decoration::Flat, []);
                }
                if dir == Dir::In && !integer && !mods.nointerp {
                    if mods.noperspective {
                        self.b.decorate(var, Decoration::NoPerspective, []);
                    }
                    if mods.centroid {
                        self.b.decorate(var, Decoration::Centroid, []);
                    }
                    if mods.sample {
                        self.cap(Capability::SampleRateShading);
                        self.b.decorate(var, Decoration::Sample, []);
                    }
                }
            }
            (None, None) => {}
        }
        io.vars.push(var);
        let lty = self.ty_id(ty)?;
        let place = if path.is_empty() {
            local
        } else {
            let fptr = self.b.type_pointer(None, StorageClass::Function, lty);
            let idx: Vec<Id> = path.iter().map(|i| self.const_u32(*i)).collect();
            self.b.access_chain(fptr, None, local, idx)?
        };
        if dir == Dir::In {
            let v = self.b.load(tid, None, var, None, [])?;
            self.b.store(place, v, None, [])?;
        } else {
            let v = self.b.load(lty, None, place, None, [])?;
            self.b.store(var, v, None, [])?;
        }
        Ok(())
    }

    /// Derivatives, implicit-LOD `Sample` and `discard` exist only in pixel shaders: a function that
    /// uses them must not be reached from another stage's entry point.
    /// Stage-restricted operations in helpers (`TraceRay`, system values, ...)
    /// against an entry point that reaches them.
    pub(super) fn check_stage_uses(&self, reached: &HashSet<usize>, entry: &FnSig) -> Result<()> {
        let Some(stage) = entry.stage else {
            return Ok(());
        };
        let mut fs: Vec<&usize> = reached.iter().collect();
        fs.sort();
        for f in fs {
            for (name, allowed, pos) in self.fn_stage_uses.get(f).into_iter().flatten() {
                if !allowed.contains(&stage) {
                    return Err(Error::new(
                        *pos,
                        format!("`{name}` is not available in {} shaders", stage.hlsl_name()),
                    )
                    .len(name.len() as u32)
                    .secondary(
                        entry.func.pos,
                        format!(
                            "reached from {} entry point `{}`",
                            stage.hlsl_name(),
                            entry.name
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    pub(super) fn check_derivatives(&self, reached: &HashSet<usize>, entry: &FnSig) -> Result<()> {
        let mut uses: Vec<(usize, &(&str, Pos))> = self
            .fn_derivs
            .iter()
            .filter(|(f, _)| reached.contains(f))
            .map(|(f, u)| (*f, u))
            .collect();
        uses.sort_by_key(|u| u.0);
        if let Some((_, (name, pos))) = uses.first() {
            let stage = entry.stage.map(Stage::hlsl_name).unwrap_or("");
            return Err(
                Error::new(*pos, format!("`{name}` is only available in pixel shaders"))
                    .len(name.len() as u32)
                    .secondary(
                        entry.func.pos,
                        format!("reached from {stage} entry point `{}`", entry.name),
                    ),
            );
        }
        Ok(())
    }
}
