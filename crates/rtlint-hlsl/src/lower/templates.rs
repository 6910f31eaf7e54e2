//! Template uses: arguments evaluated or deduced, the instance named, and
//! either found (made in an earlier round) or asked for (see
//! `super::super::template`).

use super::calls::Arg;
use super::*;
use crate::template::Instance;

/// A concrete template argument.
#[derive(Clone, Debug, PartialEq)]
pub(super) enum TVal {
    Type(Ty),
    Int(i64),
}

impl<'a> Lowerer<'a> {
    /// Function templates named `name`, looked up like functions.
    pub(super) fn find_fn_template(&self, name: &str) -> Option<Vec<&'a Function>> {
        self.scoped_names(name)
            .iter()
            .find_map(|k| self.fn_templates.get(k))
            .cloned()
    }

    /// A struct template named `name` (looked up like a type).
    pub(super) fn find_struct_template(&self, name: &str, ns: &str) -> Option<&'a StructDecl> {
        self.names_in_scope(ns, name)
            .iter()
            .find_map(|k| self.struct_templates.get(k))
            .copied()
    }

    fn targ_value(&mut self, a: &TArg, ns: &str) -> Result<TVal> {
        match a {
            TArg::Type(t) => Ok(TVal::Type(self.resolve_ty(t, ns)?)),
            TArg::Expr(e) => {
                // A name the parser could not tell is a type (`S<MyStruct>`).
                if let ExprKind::Ident(n) = &e.kind {
                    if let Some(t) = self.lookup_type_name(n, ns) {
                        return Ok(TVal::Type(t));
                    }
                }
                Ok(TVal::Int(self.const_int(e)?))
            }
        }
    }

    fn targ_name(&self, v: &TVal) -> String {
        match v {
            TVal::Int(i) => i.to_string(),
            TVal::Type(Ty::RayQuery(f)) => format!("RayQuery<{f}>"),
            TVal::Type(t) => self.ty_name(t),
        }
    }

    /// The argument as syntax, for the instance's copy of the template.
    fn canonical(&self, v: &TVal, pos: Pos) -> Result<TArg> {
        let tref = |name: String, args: Vec<TArg>| TypeRef { name, args, pos };
        Ok(match v {
            TVal::Int(i) => TArg::Expr(Expr {
                kind: ExprKind::Int(*i as u64, *i > i32::MAX as i64),
                pos,
            }),
            TVal::Type(t @ (Ty::ScalarKind(_) | Ty::Vec(..) | Ty::Mat(..))) => {
                TArg::Type(tref(self.ty_name(t), Vec::new()))
            }
            TVal::Type(Ty::Struct(k)) => {
                TArg::Type(tref(self.structs[*k as usize].name.clone(), Vec::new()))
            }
            TVal::Type(Ty::RayQuery(f)) => TArg::Type(tref(
                "RayQuery".into(),
                vec![TArg::Expr(Expr {
                    kind: ExprKind::Int(*f as u64, false),
                    pos,
                })],
            )),
            TVal::Type(other) => {
                return Err(unsupported(
                    pos,
                    format!("`{}` as a template argument", self.ty_name(other)),
                ))
            }
        })
    }

    /// Records a missing instance; the error ends this round of lowering.
    fn need(&mut self, template: Pos, args: Vec<TArg>, name: String, pos: Pos) -> Error {
        // Overloaded templates share an instance name (`f<float>`), one instance each.
        if !self
            .needed
            .iter()
            .any(|i| i.name == name && i.template == template)
        {
            self.needed.push(Instance {
                template,
                args,
                name: name.clone(),
            });
        }
        Error::new(pos, format!("template instance `{name}` is not made yet"))
    }

    /// `S<args>`: the instance struct's type.
    pub(super) fn template_struct_ty(
        &mut self,
        sd: &'a StructDecl,
        t: &TypeRef,
        ns: &str,
    ) -> Result<Ty> {
        let mut vals = Vec::new();
        for a in &t.args {
            vals.push(self.targ_value(a, ns)?);
        }
        for p in sd.tparams.iter().skip(vals.len()) {
            match &p.default {
                Some(d) => {
                    let v = self.targ_value(d, ns)?;
                    vals.push(v);
                }
                None => {
                    return Err(Error::new(
                        t.pos,
                        format!("no argument for template parameter `{}`", p.name),
                    ))
                }
            }
        }
        let name = format!(
            "{}<{}>",
            sd.name,
            vals.iter()
                .map(|v| self.targ_name(v))
                .collect::<Vec<_>>()
                .join(",")
        );
        if let Some(&k) = self.struct_names.get(&name) {
            return Ok(Ty::Struct(k));
        }
        if let Some(inst) = self.instance_structs.get(&name).copied() {
            self.declare_struct(inst)?;
            if let Some(&k) = self.struct_names.get(&name) {
                return Ok(Ty::Struct(k));
            }
        }
        let args = vals
            .iter()
            .map(|v| self.canonical(v, t.pos))
            .collect::<Result<Vec<_>>>()?;
        Err(self.need(sd.pos, args, name, t.pos))
    }

    /// Binds template parameters appearing in `pattern` from the argument type.
    fn deduce(&self, pattern: &TypeRef, ty: &Ty, params: &[TParam], out: &mut Vec<Option<TVal>>) {
        let slot = |n: &str| params.iter().position(|p| p.name == n);
        if pattern.args.is_empty() {
            if let Some(i) = slot(&pattern.name) {
                if out[i].is_none() {
                    out[i] = Some(TVal::Type(ty.clone()));
                }
            }
            return;
        }
        let bind = |a: &TArg, v: TVal, out: &mut Vec<Option<TVal>>| {
            let n = match a {
                TArg::Type(t) if t.args.is_empty() => &t.name,
                TArg::Expr(Expr {
                    kind: ExprKind::Ident(n),
                    ..
                }) => n,
                _ => return,
            };
            if let Some(i) = slot(n) {
                if out[i].is_none() {
                    out[i] = Some(v);
                }
            }
        };
        match (pattern.name.as_str(), ty) {
            ("vector", Ty::Vec(s, n)) => {
                if let Some(a) = pattern.args.first() {
                    bind(a, TVal::Type(Ty::ScalarKind(*s)), out);
                }
                if let Some(a) = pattern.args.get(1) {
                    bind(a, TVal::Int(*n as i64), out);
                }
            }
            ("matrix", Ty::Mat(s, r, c)) => {
                let vals = [
                    TVal::Type(Ty::ScalarKind(*s)),
                    TVal::Int(*r as i64),
                    TVal::Int(*c as i64),
                ];
                for (a, v) in pattern.args.iter().zip(vals) {
                    bind(a, v, out);
                }
            }
            ("RayQuery", Ty::RayQuery(f)) => {
                if let Some(a) = pattern.args.first() {
                    bind(a, TVal::Int(*f as i64), out);
                }
            }
            _ => {}
        }
    }

    /// A call of a function template (or method template with `this`).
    pub(super) fn template_call(
        &mut self,
        name: &str,
        templates: Vec<&'a Function>,
        explicit: &'a [TArg],
        args: &'a [Expr],
        this: Option<Place>,
        pos: Pos,
    ) -> Result<Option<Val>> {
        let Some(f) = templates.iter().copied().find(|f| {
            let required = f.params.iter().take_while(|p| p.init.is_none()).count();
            (required..=f.params.len()).contains(&args.len())
        }) else {
            return Err(Error::new(
                pos,
                format!("no template `{name}` takes {} argument(s)", args.len()),
            )
            .len(name.len() as u32));
        };
        if explicit.len() > f.tparams.len() {
            return Err(Error::new(
                pos,
                format!(
                    "`{name}` takes {} template argument(s), {} given",
                    f.tparams.len(),
                    explicit.len()
                ),
            )
            .len(name.len() as u32));
        }
        // Arguments once: places for `out` parameters, values otherwise.
        let mut call_args = Vec::new();
        let mut arg_tys = Vec::new();
        for (a, p) in args.iter().zip(&f.params) {
            if p.mods.output {
                let pl = self.place(a)?;
                arg_tys.push(pl.ty().clone());
                call_args.push(Arg::Place(pl, a.pos));
            } else {
                let v = self.expr(a)?;
                arg_tys.push(v.ty.clone());
                call_args.push(Arg::Value(v, a.pos));
            }
        }
        let ns = self.f.cur_ns.clone();
        let mut vals: Vec<Option<TVal>> = vec![None; f.tparams.len()];
        for (i, a) in explicit.iter().enumerate() {
            vals[i] = Some(self.targ_value(a, &ns)?);
        }
        for (p, ty) in f.params.iter().zip(&arg_tys) {
            let mut ty = ty.clone();
            for _ in &p.dims {
                if let Ty::Array(e, _) = ty {
                    ty = *e;
                }
            }
            self.deduce(&p.ty, &ty, &f.tparams, &mut vals);
        }
        let mut done = Vec::new();
        for (p, v) in f.tparams.iter().zip(vals) {
            let v = match (v, &p.default) {
                (Some(v), _) => v,
                (None, Some(d)) => self.targ_value(d, &f.ns)?,
                (None, None) => {
                    return Err(Error::new(
                        pos,
                        format!(
                            "cannot deduce template parameter `{}` of `{name}`; give it as `{name}<...>`",
                            p.name
                        ),
                    )
                    .len(name.len() as u32))
                }
            };
            done.push(v);
        }
        let suffix = format!(
            "<{}>",
            done.iter()
                .map(|v| self.targ_name(v))
                .collect::<Vec<_>>()
                .join(",")
        );
        let (key, inst_name) = match &this {
            Some(p) => {
                let Ty::Struct(k) = p.ty() else {
                    return Err(Error::new(pos, "a method template needs a struct"));
                };
                let owner = self.structs[*k as usize].name.clone();
                (
                    format!("{owner}::{}{suffix}", f.name),
                    format!("{owner}::{}{suffix}", f.name),
                )
            }
            None => (format!("{}{suffix}", f.name), format!("{}{suffix}", f.name)),
        };
        if let Some(e) = self.unusable.get(&key) {
            // The instance exists but its signature is refused.
            return Err(e.clone());
        }
        // An instance of this template (an overloaded one may share the name).
        let made = self
            .fn_by_name
            .get(&key)
            .filter(|c| c.iter().any(|k| self.funcs[*k].func.pos == f.pos))
            .cloned();
        if let Some(c) = made {
            let mut all = Vec::new();
            if let Some(p) = this {
                all.push(Arg::Place(p, pos));
            }
            all.extend(call_args);
            return self.call_user(name, c, all, pos);
        }
        let canon = done
            .iter()
            .map(|v| self.canonical(v, pos))
            .collect::<Result<Vec<_>>>()?;
        Err(self.need(f.pos, canon, inst_name, pos))
    }

    /// `f<args>(...)`.
    pub(super) fn call_with_targs(
        &mut self,
        name: &str,
        targs: &'a [TArg],
        args: &'a [Expr],
        pos: Pos,
    ) -> Result<Option<Val>> {
        if let Some(this) = self.f.this_place.clone() {
            if let Ty::Struct(k) = this.ty() {
                let key = format!("{}::{name}", self.structs[*k as usize].name);
                if let Some(ts) = self.method_templates.get(&key).cloned() {
                    return self.template_call(name, ts, targs, args, Some(this), pos);
                }
            }
        }
        match self.find_fn_template(name) {
            Some(ts) => self.template_call(name, ts, targs, args, None, pos),
            None if name == "vk::RawBufferLoad" && targs.len() == 1 => {
                self.raw_buffer_load(targs.first(), args, pos).map(Some)
            }
            None if name.starts_with("vk::") => {
                Err(unsupported(pos, format!("`{name}`")).len(name.len() as u32))
            }
            None => Err(
                Error::new(pos, format!("`{name}` is not a function template"))
                    .len(name.len() as u32),
            ),
        }
    }

    /// `obj.f<args>(...)`: a method template, or `Load<T>` of a byte-address buffer.
    pub(super) fn method_with_targs(
        &mut self,
        obj: &'a Expr,
        name: &str,
        targs: &'a [TArg],
        args: &'a [Expr],
        pos: Pos,
    ) -> Result<Option<Val>> {
        let p = self.place(obj)?;
        match p.ty().clone() {
            Ty::Struct(k) => {
                let key = format!("{}::{name}", self.structs[k as usize].name);
                match self.method_templates.get(&key).cloned() {
                    Some(ts) => self.template_call(name, ts, targs, args, Some(p), pos),
                    None => Err(Error::new(pos, format!("`{key}` is not a method template"))),
                }
            }
            Ty::ByteAddress(_) => self.typed_load(p, name, targs, args, pos),
            _ => {
                Err(unsupported(pos, format!("templated method `{name}<...>`"))
                    .len(name.len() as u32))
            }
        }
    }
}
