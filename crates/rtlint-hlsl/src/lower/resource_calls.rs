//! Helpers and methods returning a resource: SPIR-V's logical addressing
//! cannot return one, so (as DXC's legalization does) such a call is
//! inlined where it is made, naming the resource its `return` gives.

use super::*;

impl<'a> Lowerer<'a> {
    /// Whether `name` is a user function returning a resource.
    pub(super) fn returns_resource(&self, name: &str) -> bool {
        self.find_user(name)
            .is_some_and(|c| c.iter().any(|k| self.funcs[*k].ret.is_resource()))
    }

    /// A call of a helper that returns a resource: SPIR-V's logical
    /// addressing cannot return one, so (as DXC's legalization does) the
    /// helper is inlined. Its body must be `return <resource expression>;`,
    /// evaluated with the parameters bound to the arguments.
    pub(super) fn resource_call(
        &mut self,
        name: &str,
        args: &'a [Expr],
        pos: Pos,
    ) -> Result<Place> {
        let cands = self.find_user(name).unwrap_or_default();
        // Found as `S::m` from a method of `S`: a method of `this`.
        let this = self
            .f
            .this_place
            .clone()
            .filter(|_| cands.iter().any(|k| self.funcs[*k].this.is_some()));
        self.inline_resource_call(name, cands, this, args, pos)
    }

    /// `m(...)` inside a method, or `obj.m(...)`, of a struct whose method
    /// `m` returns a resource: the struct's qualified name and candidates.
    pub(super) fn resource_method(&self, this: &Place, name: &str) -> Option<Vec<usize>> {
        let Ty::Struct(k) = this.ty() else {
            return None;
        };
        let own = format!("{}::", self.structs[*k as usize].name);
        let name = name.strip_prefix(own.as_str()).unwrap_or(name);
        let c = self.fn_by_name.get(&format!("{own}{name}"))?;
        c.iter()
            .any(|k| self.funcs[*k].ret.is_resource())
            .then(|| c.clone())
    }

    /// Inlines a helper (or, with `this`, a method) returning a resource.
    pub(super) fn inline_resource_call(
        &mut self,
        name: &str,
        cands: Vec<usize>,
        this: Option<Place>,
        args: &'a [Expr],
        pos: Pos,
    ) -> Result<Place> {
        let first = this.is_some() as usize;
        let Some(k) = cands.into_iter().find(|k| {
            let f = &self.funcs[*k];
            let n = f.params.len() - first;
            f.this.is_some() == this.is_some() && (n - f.defaults.len()..=n).contains(&args.len())
        }) else {
            return Err(Error::new(
                pos,
                format!("no overload of `{name}` takes {} argument(s)", args.len()),
            )
            .len(name.len() as u32));
        };
        let sig = self.funcs[k].clone();
        let body = sig.func.body.as_deref().unwrap_or_default();
        let [Stmt {
            kind: StmtKind::Return(Some(ret)),
            ..
        }] = body
        else {
            return Err(unsupported(
                sig.func.pos,
                "a function returning a resource whose body is more than `return <resource>;`",
            )
            .len(sig.name.len() as u32));
        };
        if self.f.inline_depth >= 16 {
            return Err(Error::new(
                pos,
                format!("`{name}` is recursive; HLSL does not allow recursion"),
            ));
        }
        let first_default = sig.params.len() - first - sig.defaults.len();
        let mut scope = HashMap::new();
        if let Some(t) = &this {
            scope.insert("this".to_string(), t.clone());
        }
        for (i, (p, decl)) in sig.params[first..].iter().zip(&sig.func.params).enumerate() {
            let a = match args.get(i) {
                Some(a) => a,
                None => sig.defaults[i - first_default],
            };
            if p.out {
                return Err(unsupported(
                    decl.pos,
                    "`out` parameters of a function returning a resource",
                ));
            }
            let place = if p.ty.is_resource() {
                self.place(a)?
            } else {
                let v = self.expr(a)?;
                Place::Value(self.convert(v, &p.ty, a.pos, false)?)
            };
            scope.insert(decl.name.clone(), place);
        }
        // The helper's body sees its parameters and the globals, not the caller's locals.
        let scopes = std::mem::replace(&mut self.f.scopes, vec![scope]);
        let this = std::mem::replace(&mut self.f.this_place, this);
        let ns = std::mem::replace(&mut self.f.cur_ns, sig.func.ns.clone());
        self.f.inline_depth += 1;
        let r = self.place(ret);
        self.f.inline_depth -= 1;
        self.f.scopes = scopes;
        self.f.this_place = this;
        self.f.cur_ns = ns;
        let r = r?;
        if !r.ty().is_resource() {
            return Err(Error::new(ret.pos, "expected a resource"));
        }
        Ok(r)
    }
}
