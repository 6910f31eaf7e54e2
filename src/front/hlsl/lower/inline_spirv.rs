//! DXC's inline-SPIR-V attributes that declare things: built-in inputs
//! (`vk::ext_builtin_input`) and member decorations (`vk::ext_decorate`).

use super::*;

impl<'a> Lowerer<'a> {
    /// `[[vk::ext_builtin_input(N)]] static const T name;`: an `Input`
    /// variable decorated `BuiltIn N` (with the extensions and capabilities
    /// its other `vk::ext_*` attributes name, added where it is used).
    pub(super) fn declare_ext_builtin(&mut self, v: &'a VarDecl) -> Result<()> {
        let Some(a) = v.attrs.iter().find(|a| a.name == "vk::ext_builtin_input") else {
            return Ok(());
        };
        if !(v.mods.is_static && v.mods.is_const) || v.init.is_some() {
            return Err(Error::new(
                v.pos,
                "a `vk::ext_builtin_input` variable must be `static const` without an initializer",
            ));
        }
        let e = a
            .args
            .first()
            .ok_or_else(|| Error::new(a.pos, "expected [[vk::ext_builtin_input(N)]]"))?;
        let n = self.const_int(e)?;
        let bi = u32::try_from(n)
            .ok()
            .and_then(BuiltIn::from_u32)
            .ok_or_else(|| Error::new(e.pos, format!("unknown SPIR-V built-in {n}")))?;
        let req = self.ext_requirements(&v.attrs)?;
        let t = self.resolve_ty(&v.ty, "")?;
        let t = self.apply_dims(t, &v.dims, v.pos, false)?;
        if t.is_resource() || (matches!(t, Ty::RtArray(_)) || t.is_opaque()) {
            return Err(Error::new(v.pos, "a built-in input must be a value type"));
        }
        let tid = self.ty_id(&t)?;
        let pty = self.b.type_pointer(None, StorageClass::Input, tid);
        let var = self.global_var(pty, StorageClass::Input, None);
        self.b.name(var, v.name.clone());
        self.b
            .decorate(var, Decoration::BuiltIn, [Operand::BuiltIn(bi)]);
        self.global_reqs.insert(var, req);
        self.global_decls
            .push((var, v.name.clone(), t.clone(), v.pos));
        self.globals.insert(
            v.name.clone(),
            Global::Place(Place::Ptr {
                ptr: var,
                ty: t,
                layout: Layout::None,
                class: StorageClass::Input,
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
}
