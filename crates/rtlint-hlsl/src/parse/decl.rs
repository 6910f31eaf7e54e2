//! Structs and declarators: members, array dimensions, semantics, registers, initializers.

use super::*;

impl<'t> Parser<'t> {
    /// A struct or class. Nested declarations (structs, enums, typedefs,
    /// `static` members) go to `items`, qualified by the struct's name, before it.
    pub(super) fn struct_decl(&mut self, items: &mut Vec<Item>) -> Result<StructDecl> {
        if !self.eat("class") {
            self.expect("struct")?;
        }
        check_site(&self.attrs()?, Site::Struct)?; // `[raypayload]`
        let (name, pos) = self.ident()?;
        self.declare_type(&name);
        let qualified = self.qualify(&name);
        let mut bases = Vec::new();
        if self.eat(":") {
            loop {
                let _ = self.eat("public") || self.eat("private") || self.eat("protected");
                bases.push(self.type_ref()?);
                if !self.eat(",") {
                    break;
                }
            }
        }
        self.expect("{")?;
        self.ns.push(name);
        let body = self.struct_body(items, &qualified);
        self.ns.pop();
        let (fields, methods) = body?;
        Ok(StructDecl {
            name: qualified,
            pos,
            bases,
            tparams: Vec::new(),
            fields,
            methods,
        })
    }

    fn struct_body(
        &mut self,
        items: &mut Vec<Item>,
        qualified: &str,
    ) -> Result<(Vec<VarDecl>, Vec<Function>)> {
        let mut fields = Vec::new();
        let mut methods = Vec::new();
        while !self.is("}") {
            if self.peek().is_none() {
                return Err(self.unexpected("`}`"));
            }
            // `public:` / `private:` / `protected:` sections: access is not checked.
            if ["public", "private", "protected"]
                .iter()
                .any(|k| self.is_kw(k))
                && self.is_at(1, ":")
            {
                self.i += 2;
                continue;
            }
            if ["struct", "class", "enum", "typedef", "using"]
                .iter()
                .any(|k| self.is_kw(k))
            {
                // A nested declaration: a declaration of its own, named `Outer::Inner`.
                self.item(items)?;
                continue;
            }
            let tparams = if self.is_kw("template") {
                self.template_params()?
            } else {
                Vec::new()
            };
            let added: Vec<String> = tparams
                .iter()
                .filter(|p| p.value_ty.is_none() && self.types.insert(p.name.clone()))
                .map(|p| p.name.clone())
                .collect();
            let member = self.struct_member(items, qualified, &mut fields, tparams);
            for a in &added {
                self.types.remove(a);
            }
            if let Some(f) = member? {
                methods.push(f);
            }
        }
        self.i += 1;
        Ok((fields, methods))
    }

    /// One member of a struct body: a method (returned), a field or a static.
    fn struct_member(
        &mut self,
        items: &mut Vec<Item>,
        qualified: &str,
        fields: &mut Vec<VarDecl>,
        tparams: Vec<TParam>,
    ) -> Result<Option<Function>> {
        {
            let fattrs = self.attrs()?;
            let mods = self.mods();
            let ty = self.type_ref()?;
            if self.is_kw("operator") {
                // `T operator[](...)`, `T operator+(...)`: a method named `operator[]`.
                let mpos = self.pos();
                self.i += 1;
                let mut mname = String::from("operator");
                while !self.is("(")
                    || mname == "operator" && self.is_at(1, ")") && self.is_at(2, "(")
                {
                    let t = self.peek().ok_or_else(|| self.unexpected("an operator"))?;
                    mname.push_str(&t.spelling());
                    self.i += 1;
                    if mname.len() > 12 {
                        return Err(Error::new(mpos, "expected an operator after `operator`"));
                    }
                }
                check_site(&fattrs, Site::Function)?;
                let mut f = self.function(fattrs, ty, mname.clone(), mpos)?;
                f.name = mname;
                f.is_static = mods.is_static;
                f.tparams = tparams;
                return Ok(Some(f));
            }
            if self.peek().and_then(Token::ident).is_some() && self.is_at(1, "(") {
                let (mname, mpos) = self.ident()?;
                check_site(&fattrs, Site::Function)?;
                // Without a body, the definition follows outside (`T S::m(...) {}`).
                let mut f = self.function(fattrs, ty, mname.clone(), mpos)?;
                f.name = mname;
                f.is_static = mods.is_static;
                if !tparams.is_empty() {
                    self.template_fns.insert(f.name.clone());
                }
                f.tparams = tparams;
                return Ok(Some(f));
            }
            if !tparams.is_empty() {
                return Err(Error::unsupported(
                    ty.pos,
                    "member templates other than methods",
                ));
            }
            if mods.is_static {
                // A static member is a global named `S::name`.
                check_site(&fattrs, Site::Global)?;
                let mut vars = Vec::new();
                self.declarators(fattrs, mods, ty, &mut vars)?;
                items.extend(vars.into_iter().map(|mut v| {
                    v.name = format!("{qualified}::{}", v.name);
                    Item::Var(v)
                }));
                return Ok(None);
            }
            check_site(&fattrs, Site::Member)?;
            self.declarators(fattrs, mods, ty, fields)?;
            Ok(None)
        }
    }

    pub(super) fn dims(&mut self) -> Result<Vec<Option<Expr>>> {
        let mut dims = Vec::new();
        while self.eat("[") {
            if self.eat("]") {
                dims.push(None);
            } else {
                dims.push(Some(self.ternary()?));
                self.expect("]")?;
            }
        }
        Ok(dims)
    }

    /// `: SEMANTIC`, `: register(...)`, payload access qualifiers; in any order.
    pub(super) fn post_decl(&mut self) -> Result<PostDecl> {
        let mut semantic = None;
        let mut register = None;
        while self.eat(":") {
            let (name, pos) = self.ident()?;
            match name.as_str() {
                "register" => {
                    self.expect("(")?;
                    let (r, rpos) = self.ident()?;
                    let space_of = |s: &str| s.strip_prefix("space").and_then(|n| n.parse().ok());
                    let mut space = 0;
                    let (class, index) = match space_of(&r) {
                        // `register(space99)`: a space, the binding left to the compiler.
                        Some(sp) => {
                            space = sp;
                            ('?', None)
                        }
                        None => {
                            let mut chars = r.chars();
                            let class = chars.next().unwrap_or('?').to_ascii_lowercase();
                            let index = chars.as_str().parse::<u32>().map_err(|_| {
                                Error::new(rpos, format!("malformed register `{r}`"))
                            })?;
                            (class, Some(index))
                        }
                    };
                    if index.is_some() && self.eat(",") {
                        let (s, spos) = self.ident()?;
                        space = s
                            .strip_prefix("space")
                            .and_then(|n| n.parse().ok())
                            .ok_or_else(|| {
                                Error::new(spos, format!("malformed register space `{s}`"))
                            })?;
                    }
                    self.expect(")")?;
                    register = Some(Register {
                        class,
                        index,
                        space,
                        pos,
                    });
                }
                "packoffset" => {
                    return Err(Error::unsupported(pos, "packoffset").len(10));
                }
                "read" | "write" => {
                    // Payload access qualifiers: checked by DXC, no effect on SPIR-V.
                    self.expect("(")?;
                    while !self.eat(")") {
                        if self.peek().is_none() {
                            return Err(self.unexpected("`)`"));
                        }
                        self.i += 1;
                    }
                }
                _ => semantic = Some((name, pos)),
            }
        }
        Ok((semantic, register))
    }

    pub(super) fn declarators(
        &mut self,
        attrs: Vec<Attr>,
        mods: Mods,
        ty: TypeRef,
        out: &mut Vec<VarDecl>,
    ) -> Result<()> {
        loop {
            let (name, pos) = self.ident()?;
            let dims = self.dims()?;
            let bits = match self.peek_at(1) {
                Some(Token {
                    tok: Tok::Int(n, _),
                    pos,
                    ..
                }) if self.is(":") => {
                    self.i += 2;
                    Some((*n as u32, *pos))
                }
                _ => None,
            };
            let (semantic, register) = self.post_decl()?;
            let init = if self.eat("=") {
                Some(self.initializer()?)
            } else {
                None
            };
            out.push(VarDecl {
                attrs: attrs.clone(),
                mods,
                ty: ty.clone(),
                name,
                pos,
                dims,
                semantic,
                register,
                init,
                bits,
            });
            if !self.eat(",") {
                break;
            }
        }
        self.expect(";")?;
        Ok(())
    }

    fn initializer(&mut self) -> Result<Expr> {
        if self.is("{") {
            let pos = self.pos();
            self.enter()?;
            self.i += 1;
            let mut elems = Vec::new();
            while !self.is("}") {
                elems.push(self.initializer()?);
                if !self.eat(",") {
                    break;
                }
            }
            self.expect("}")?;
            self.depth -= 1;
            return Ok(Expr {
                kind: ExprKind::InitList(elems),
                pos,
            });
        }
        self.assign()
    }
}
