//! Types, modifiers, attributes, and template parameters and arguments.

use super::*;

impl<'t> Parser<'t> {
    pub(super) fn type_ref(&mut self) -> Result<TypeRef> {
        let (mut name, pos) = self.ident()?;
        if name == "unsigned" {
            // `unsigned int2`, `unsigned int`, `unsigned`: the `uint` types.
            name = match self.peek().and_then(Token::ident) {
                Some(n) if n.starts_with("int") && split_numeric(n).is_some() => {
                    self.i += 1;
                    format!("u{n}")
                }
                _ => "uint".to_string(),
            };
        }
        if !is_builtin_type(&name) && !self.types.contains(&name) {
            if let Some(q) = self.ns_qualified(&name) {
                name = q;
            }
        }
        let mut args = Vec::new();
        if self.is("<") && self.is_template_struct(&name) {
            args = self.template_args()?;
        } else if TEMPLATE_TYPES.contains(&name.as_str()) && self.is("<") {
            self.i += 1;
            loop {
                if self.type_at(0) {
                    args.push(TArg::Type(self.type_ref()?));
                } else {
                    args.push(TArg::Expr(self.binary(0, true)?));
                }
                if self.eat(",") {
                    continue;
                }
                // `>>` closing two template lists is not split here: `vector<vector<...>>` is not HLSL.
                self.expect(">")?;
                break;
            }
        }
        Ok(TypeRef { name, args, pos })
    }

    pub(super) fn attrs(&mut self) -> Result<Vec<Attr>> {
        let mut out = Vec::new();
        while self.is("[") {
            let double = self.is_at(1, "[");
            self.i += if double { 2 } else { 1 };
            loop {
                let (name, pos) = self.ident()?;
                let mut args = Vec::new();
                if self.eat("(") {
                    if !self.is(")") {
                        loop {
                            args.push(self.assign()?);
                            if !self.eat(",") {
                                break;
                            }
                        }
                    }
                    self.expect(")")?;
                }
                let name = match super::super::attrs::lookup(&name) {
                    Some(info) => info.name.to_string(),
                    None => name,
                };
                let attr = Attr { name, args, pos };
                check(&attr)?;
                out.push(attr);
                if !self.eat(",") {
                    break;
                }
            }
            self.expect("]")?;
            if double {
                self.expect("]")?;
            }
        }
        Ok(out)
    }

    /// Whether `#pragma pack_matrix(row_major)` holds at the current token.
    fn row_major_default(&self) -> bool {
        self.pack
            .iter()
            .rev()
            .find(|(at, _)| *at <= self.i)
            .is_some_and(|(_, row)| *row)
    }

    pub(super) fn mods(&mut self) -> Mods {
        let mut m = Mods::default();
        if self.row_major_default() {
            // Explicit `column_major` below turns it off again.
            m.row_major = true;
        }
        loop {
            match self.modifier_at(0) {
                Some("static") => m.is_static = true,
                Some("const") => m.is_const = true,
                Some("groupshared") => m.groupshared = true,
                Some("uniform") => m.uniform = true,
                Some("in") => m.input = true,
                Some("out") => m.output = true,
                Some("inout") => {
                    m.input = true;
                    m.output = true
                }
                Some("row_major") => m.row_major = true,
                Some("column_major") => {
                    m.column_major = true;
                    m.row_major = false;
                }
                Some("precise") => m.precise = true,
                Some("nointerpolation") => m.nointerp = true,
                Some("centroid") => m.centroid = true,
                Some("sample") => m.sample = true,
                Some("noperspective") => m.noperspective = true,
                Some("globallycoherent") => m.globally_coherent = true,
                Some(
                    "inline" | "export" | "extern" | "volatile" | "linear" | "snorm" | "unorm",
                ) => {}
                _ => return m,
            }
            self.i += 1;
        }
    }

    /// `template<typename T, uint N = 4>`.
    pub(super) fn template_params(&mut self) -> Result<Vec<TParam>> {
        self.expect("template")?;
        self.expect("<")?;
        let mut out = Vec::new();
        while !self.is(">") {
            let pos = self.pos();
            let value_ty = if self.eat("typename") || self.eat("class") {
                None
            } else {
                Some(self.type_ref()?)
            };
            let (name, _) = self.ident()?;
            let default = if self.eat("=") {
                Some(if value_ty.is_none() {
                    TArg::Type(self.type_ref()?)
                } else {
                    TArg::Expr(self.binary(0, true)?)
                })
            } else {
                None
            };
            out.push(TParam {
                name,
                value_ty,
                default,
                pos,
            });
            if !self.eat(",") {
                break;
            }
        }
        self.expect(">")?;
        Ok(out)
    }

    /// `<float3, 4>` after a template's name.
    pub(super) fn template_args(&mut self) -> Result<Vec<TArg>> {
        self.expect("<")?;
        let mut args = Vec::new();
        while !self.is(">") {
            if self.type_at(0) {
                args.push(TArg::Type(self.type_ref()?));
            } else {
                args.push(TArg::Expr(self.binary(0, true)?));
            }
            if !self.eat(",") {
                break;
            }
        }
        self.expect(">")?;
        Ok(args)
    }

    /// Whether `<` at `k` opens template arguments: `<` then a type or a
    /// number and a closing `>` before anything that cannot be in a list.
    pub(super) fn template_args_at(&self, k: usize) -> bool {
        if !self.is_at(k, "<") {
            return false;
        }
        let mut j = k + 1;
        let mut depth = 1;
        while let Some(t) = self.peek_at(j) {
            if t.is("<") {
                depth += 1;
            } else if t.is(">") {
                depth -= 1;
                if depth == 0 {
                    return self.is_at(j + 1, "(");
                }
            } else if t.is(";") || t.is("{") || t.is("}") || t.is("&&") || t.is("||") {
                return false;
            }
            j += 1;
        }
        false
    }

    fn is_template_struct(&self, name: &str) -> bool {
        self.template_structs.contains(name)
            || name
                .rsplit_once("::")
                .is_some_and(|(_, bare)| self.template_structs.contains(bare))
    }

    /// How many modifier keywords start at the current token.
    pub(super) fn mods_len(&self) -> usize {
        let mut k = 0;
        while self.modifier_at(k).is_some() {
            k += 1;
        }
        k
    }

    /// The modifier keyword at token `k`, if it is one there.
    fn modifier_at(&self, k: usize) -> Option<&'t str> {
        let w = self.peek_at(k).and_then(Token::ident)?;
        if MODIFIERS.contains(&w) {
            return Some(w);
        }
        (SOFT_MODIFIERS.contains(&w) && self.peek_at(k + 1).and_then(Token::ident).is_some())
            .then_some(w)
    }
}
