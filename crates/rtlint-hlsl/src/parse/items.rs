//! Top-level items: declarations, functions, templates, namespaces, subobjects.

use super::*;

impl<'t> Parser<'t> {
    /// `template<...>` and the function, struct or alias it introduces.
    fn template_item(&mut self, items: &mut Vec<Item>) -> Result<()> {
        let tpos = self.pos();
        let tparams = self.template_params()?;
        let added: Vec<String> = tparams
            .iter()
            .filter(|p| p.value_ty.is_none() && self.types.insert(p.name.clone()))
            .map(|p| p.name.clone())
            .collect();
        let mut one = Vec::new();
        let r = self.item(&mut one);
        for a in &added {
            self.types.remove(a);
        }
        r?;
        // Nested declarations (static members of a templated struct) are not templates.
        let Some(last) = one.pop() else {
            return Err(Error::new(
                tpos,
                "expected a declaration after `template<...>`",
            ));
        };
        match last {
            Item::Function(mut f) => {
                self.template_fns.insert(f.name.clone());
                if let Some((_, bare)) = f.name.rsplit_once("::") {
                    self.template_fns.insert(bare.to_string());
                }
                f.tparams = tparams;
                items.extend(one);
                items.push(Item::Function(f));
            }
            Item::Struct(mut sd) => {
                self.template_structs.insert(sd.name.clone());
                if let Some((_, bare)) = sd.name.rsplit_once("::") {
                    self.template_structs.insert(bare.to_string());
                }
                sd.tparams = tparams;
                if !one.is_empty() {
                    return Err(Error::unsupported(
                        sd.pos,
                        "static members or nested types in a struct template",
                    ));
                }
                items.push(Item::Struct(sd));
            }
            _ => {
                return Err(
                    Error::unsupported(tpos, "templates other than functions and structs").len(8),
                )
            }
        }
        Ok(())
    }

    pub(super) fn item(&mut self, items: &mut Vec<Item>) -> Result<()> {
        if self.eat(";") {
            return Ok(());
        }
        let attrs = self.attrs()?;
        let declares_code = self.is_kw("cbuffer") || self.is_kw("tbuffer") || {
            let k = self.mods_len();
            self.type_at(k)
        };
        if !declares_code {
            check_site(&attrs, Site::Struct)?;
        }
        if self.is_kw("namespace") {
            self.i += 1;
            let (name, _) = self.ident()?;
            self.expect("{")?;
            self.ns.push(name);
            while !self.is("}") {
                if self.peek().is_none() {
                    return Err(self.unexpected("`}`"));
                }
                self.item(items)?;
            }
            self.i += 1;
            self.ns.pop();
            return Ok(());
        }
        let record = self.is_kw("struct") || self.is_kw("class");
        if record && self.is_at(2, ";") {
            // A forward declaration: `struct X;`, `class Foo;`.
            self.i += 1;
            let (name, _) = self.ident()?;
            self.declare_type(&name);
            self.expect(";")?;
            return Ok(());
        }
        if record && (self.peek_at(2).is_some_and(|t| t.is("{") || t.is(":")) || self.is_at(1, "["))
        {
            let s = self.struct_decl(items)?;
            self.expect(";")?;
            items.append(&mut self.hoisted);
            items.push(Item::Struct(s));
            return Ok(());
        }
        if self.is_kw("using") {
            self.i += 1;
            if self.eat("namespace") {
                let (name, _) = self.ident()?;
                self.expect(";")?;
                if name != "dx" {
                    self.using.push(name.clone());
                    items.push(Item::Using(name));
                }
                return Ok(());
            }
            // `using Name = Type;`: a typedef.
            let (name, pos) = self.ident()?;
            self.expect("=")?;
            let _ = self.mods();
            let ty = self.type_ref()?;
            let dims = self.dims()?;
            self.expect(";")?;
            self.declare_type(&name);
            items.push(Item::Typedef {
                ty,
                dims,
                name: self.qualify(&name),
                pos,
            });
            return Ok(());
        }
        if self.is_kw("typedef") {
            self.i += 1;
            let _ = self.mods();
            let ty = self.type_ref()?;
            let (name, pos) = self.ident()?;
            let dims = self.dims()?;
            self.expect(";")?;
            self.declare_type(&name);
            items.push(Item::Typedef {
                ty,
                dims,
                name: self.qualify(&name),
                pos,
            });
            return Ok(());
        }
        if self.is_kw("enum") {
            self.i += 1;
            let scoped = self.eat("class") || self.eat("struct");
            let (name, pos) = self.ident()?;
            let underlying = if self.eat(":") {
                Some(self.type_ref()?)
            } else {
                None
            };
            self.expect("{")?;
            let mut variants = Vec::new();
            while !self.is("}") {
                let (v, vp) = self.ident()?;
                let value = if self.eat("=") {
                    Some(self.ternary()?)
                } else {
                    None
                };
                variants.push((v, vp, value));
                if !self.eat(",") {
                    break;
                }
            }
            self.expect("}")?;
            self.expect(";")?;
            self.declare_type(&name);
            items.push(Item::Enum {
                name: self.qualify(&name),
                scoped,
                underlying,
                variants,
                pos,
            });
            return Ok(());
        }
        if self.is_kw("cbuffer") || self.is_kw("tbuffer") {
            let kw_pos = self.pos();
            if self.is_kw("tbuffer") {
                return Err(Error::unsupported(kw_pos, "tbuffer").len(7));
            }
            check_site(&attrs, Site::Global)?;
            self.i += 1;
            let (name, pos) = self.ident()?;
            let (_, register) = self.post_decl()?;
            self.expect("{")?;
            let mut members = Vec::new();
            while !self.is("}") {
                if self.peek().is_none() {
                    return Err(self.unexpected("`}`"));
                }
                let mattrs = self.attrs()?;
                check_site(&mattrs, Site::Member)?;
                let mods = self.mods();
                let ty = self.type_ref()?;
                self.declarators(mattrs, mods, ty, &mut members)?;
            }
            self.i += 1;
            self.eat(";");
            items.push(Item::CBuffer {
                attrs,
                name,
                pos,
                register,
                members,
            });
            return Ok(());
        }
        let mods = self.mods();
        if self.is_kw("struct") {
            // `struct S { ... } s;` or `struct S s;`: not worth supporting.
            return Err(
                Error::unsupported(self.pos(), "struct declared inside a declaration").len(6),
            );
        }
        if self.is_kw("template") {
            return self.template_item(items);
        }
        if !self.type_at(0) {
            return Err(self.unexpected("a declaration"));
        }
        let ty = self.type_ref()?;
        // Function: type name `(`.
        if self.peek().and_then(Token::ident).is_some() && {
            let mut k = 1;
            while self.is_at(k, "::") {
                k += 2;
            }
            self.is_at(k, "(")
        } {
            let (name, pos) = self.ident()?;
            if let Some((owner, method)) = name.rsplit_once("::") {
                // `T S::m(...) { ... }`: the definition of a method declared in `S`.
                let owner = self
                    .ns_qualified(owner)
                    .unwrap_or_else(|| owner.to_string());
                if let Some(sd) = items.iter_mut().rev().find_map(|it| match it {
                    Item::Struct(sd) if sd.name == owner => Some(sd),
                    _ => None,
                }) {
                    check_site(&attrs, Site::Function)?;
                    let mut f = self.function(attrs, ty, method.to_string(), pos)?;
                    f.name = method.to_string();
                    let Some(decl) = sd.methods.iter_mut().find(|m| {
                        m.name == method && m.body.is_none() && m.params.len() == f.params.len()
                    }) else {
                        return Err(Error::new(
                            pos,
                            format!(
                                "`{owner}` declares no method `{method}` with {} parameter(s)",
                                f.params.len()
                            ),
                        ));
                    };
                    f.is_static = decl.is_static;
                    for (d, p) in decl.params.iter().zip(f.params.iter_mut()) {
                        if p.init.is_none() {
                            p.init = d.init.clone();
                        }
                    }
                    *decl = f;
                    items.append(&mut self.hoisted);
                    return Ok(());
                }
            }
            check_site(&attrs, Site::Function)?;
            let f = self.function(attrs, ty, name, pos)?;
            items.append(&mut self.hoisted);
            items.push(Item::Function(f));
            return Ok(());
        }
        check_site(&attrs, Site::Global)?;
        let mut vars = Vec::new();
        self.declarators(attrs, mods, ty, &mut vars)?;
        items.extend(vars.into_iter().map(|mut v| {
            v.name = self.qualify(&v.name);
            Item::Var(v)
        }));
        Ok(())
    }

    pub(super) fn function(
        &mut self,
        attrs: Vec<Attr>,
        ret: TypeRef,
        name: String,
        pos: Pos,
    ) -> Result<Function> {
        self.expect("(")?;
        let mut params = Vec::new();
        if !(self.is(")") || self.is_kw("void") && self.is_at(1, ")")) {
            loop {
                let pattrs = self.attrs()?;
                check_site(&pattrs, Site::Param)?;
                let mods = self.mods();
                if !self.type_at(0) {
                    return Err(self.unexpected("a parameter type"));
                }
                let ty = self.type_ref()?;
                let (pname, ppos) = self.ident()?;
                let dims = self.dims()?;
                let (semantic, register) = self.post_decl()?;
                // A default value: used for trailing arguments a call leaves out.
                let init = if self.eat("=") {
                    Some(self.ternary()?)
                } else {
                    None
                };
                params.push(VarDecl {
                    attrs: pattrs,
                    mods,
                    ty,
                    name: pname,
                    pos: ppos,
                    dims,
                    semantic,
                    register,
                    init,
                    bits: None,
                });
                if !self.eat(",") {
                    break;
                }
            }
        } else if self.is_kw("void") {
            self.i += 1;
        }
        self.expect(")")?;
        let (semantic, _) = self.post_decl()?;
        let body = if self.eat(";") {
            None
        } else {
            Some(self.block()?)
        };
        Ok(Function {
            attrs,
            ret,
            name: self.qualify(&name),
            ns: if self.ns.is_empty() {
                String::new()
            } else {
                format!("{}::", self.ns.join("::"))
            },
            pos,
            params,
            semantic,
            body,
            is_static: false,
            tparams: Vec::new(),
        })
    }
}
