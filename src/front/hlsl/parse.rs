//! Parser: preprocessed tokens → [`ast::Item`]s.
//!
//! HLSL, like C, needs to know which names are types (`(T)x` is a cast, `T x;`
//! a declaration), so the parser records struct, typedef and enum names as it
//! meets them.

use super::ast::*;
use super::attrs::{check, check_site, Site};
use super::error::{Error, Pos, Result};
use super::lex::{Tok, Token};
use super::pp::{PACK_COLUMN_MAJOR, PACK_ROW_MAJOR};
use std::collections::HashSet;

pub struct Parser<'t> {
    t: &'t [Token],
    i: usize,
    types: HashSet<String>,
    ns: Vec<String>,
    /// Namespaces named by `using namespace`.
    using: Vec<String>,
    /// `#pragma pack_matrix` changes: (token index from which it holds, row major).
    pack: Vec<(usize, bool)>,
    /// Structs declared inside function bodies, added before the function.
    hoisted: Vec<Item>,
    /// Names of function and struct templates (bare and qualified).
    template_fns: HashSet<String>,
    template_structs: HashSet<String>,
    depth: usize,
}

/// Nesting limit, counted in parser calls (a parenthesised expression costs
/// two): 512 parentheses, past DXC's (clang's `-fbracket-depth`, 256), and
/// shallow enough that a fuzzer's `((((...` cannot overflow the compiler
/// thread's stack (`tests/hlsl_robustness.rs` measures the deepest input).
const MAX_DEPTH: usize = 1024;

/// Keywords `mods` reads.
const MODIFIERS: &[&str] = &[
    "static",
    "const",
    "groupshared",
    "uniform",
    "in",
    "out",
    "inout",
    "row_major",
    "column_major",
    "precise",
    "nointerpolation",
    "inline",
    "export",
    "extern",
    "volatile",
    "linear",
    "snorm",
    "unorm",
    "globallycoherent",
];

/// Interpolation modifiers that are also common variable names: modifiers
/// only when a name follows (`centroid float3 p`, not `centroid += d`).
const SOFT_MODIFIERS: &[&str] = &["centroid", "sample", "noperspective"];

/// What may follow a declarator: a semantic and a register binding.
type PostDecl = (Option<(String, Pos)>, Option<Register>);

const SCALARS: &[&str] = &[
    "bool",
    "int",
    "uint",
    "dword",
    "float",
    "half",
    "double",
    "min16float",
    "min10float",
    "min16int",
    "min12int",
    "min16uint",
    "int16_t",
    "uint16_t",
    "int32_t",
    "uint32_t",
    "int64_t",
    "uint64_t",
    "float16_t",
    "float32_t",
    "float64_t",
];

pub const TEMPLATE_TYPES: &[&str] = &[
    "vector",
    "matrix",
    "RayQuery",
    "StructuredBuffer",
    "RWStructuredBuffer",
    "ConstantBuffer",
    "Texture1D",
    "Texture2D",
    "Texture3D",
    "TextureCube",
    "Texture2DArray",
    "Texture1DArray",
    "TextureCubeArray",
    "RWTexture1DArray",
    "RWTexture1D",
    "RWTexture2D",
    "RWTexture3D",
    "RWTexture2DArray",
    "Buffer",
    "RWBuffer",
    "AppendStructuredBuffer",
    "ConsumeStructuredBuffer",
    "Texture2DMS",
];

const PLAIN_TYPES: &[&str] = &[
    "void",
    "RayDesc",
    "BuiltInTriangleIntersectionAttributes",
    "RaytracingAccelerationStructure",
    "SamplerState",
    "SamplerComparisonState",
    "ByteAddressBuffer",
    "RWByteAddressBuffer",
    "string",
    "HitObject",
    // DXR state-object subobjects (see `subobject`).
    "TriangleHitGroup",
    "ProceduralPrimitiveHitGroup",
    "RaytracingShaderConfig",
    "RaytracingPipelineConfig",
    "RaytracingPipelineConfig1",
    "GlobalRootSignature",
    "LocalRootSignature",
    "StateObjectConfig",
    "SubobjectToExportsAssociation",
];

/// Splits `float3x4` into (`float`, 3, 4); `float3` gives (`float`, 3, 0).
pub fn split_numeric(name: &str) -> Option<(&'static str, u8, u8)> {
    for s in SCALARS {
        if let Some(rest) = name.strip_prefix(s) {
            let b = rest.as_bytes();
            let dim = |c: u8| (b'1'..=b'4').contains(&c).then_some(c - b'0');
            return match b.len() {
                0 => Some((s, 0, 0)),
                1 => Some((s, dim(b[0])?, 0)),
                3 if b[1] == b'x' => Some((s, dim(b[0])?, dim(b[2])?)),
                _ => continue,
            };
        }
    }
    None
}

pub fn is_builtin_type(name: &str) -> bool {
    split_numeric(name).is_some() || TEMPLATE_TYPES.contains(&name) || PLAIN_TYPES.contains(&name)
}

pub fn parse(tokens: &[Token]) -> Result<Vec<Item>> {
    // `#pragma pack_matrix` markers: (index of the next token, row major).
    let mut pack = Vec::new();
    let mut kept = Vec::with_capacity(tokens.len());
    for t in tokens {
        match t.tok {
            Tok::Punct(PACK_ROW_MAJOR) => pack.push((kept.len(), true)),
            Tok::Punct(PACK_COLUMN_MAJOR) => pack.push((kept.len(), false)),
            _ => kept.push(t.clone()),
        }
    }
    let mut p = Parser {
        t: &kept,
        pack,
        hoisted: Vec::new(),
        template_fns: HashSet::new(),
        template_structs: HashSet::new(),
        i: 0,
        types: HashSet::new(),
        ns: Vec::new(),
        using: Vec::new(),
        depth: 0,
    };
    let mut items = Vec::new();
    while p.i < p.t.len() {
        p.item(&mut items)?;
    }
    Ok(items)
}

impl<'t> Parser<'t> {
    fn peek(&self) -> Option<&'t Token> {
        self.t.get(self.i)
    }
    fn peek_at(&self, k: usize) -> Option<&'t Token> {
        self.t.get(self.i + k)
    }
    fn is(&self, p: &str) -> bool {
        self.peek().is_some_and(|t| t.is(p))
    }
    fn is_at(&self, k: usize, p: &str) -> bool {
        self.peek_at(k).is_some_and(|t| t.is(p))
    }
    fn is_kw(&self, k: &str) -> bool {
        self.peek().and_then(Token::ident) == Some(k)
    }
    fn pos(&self) -> Pos {
        self.peek()
            .or_else(|| self.t.last())
            .map(|t| t.pos)
            .unwrap_or_default()
    }
    fn eat(&mut self, p: &str) -> bool {
        if self.is(p) || self.is_kw(p) {
            self.i += 1;
            true
        } else {
            false
        }
    }
    fn unexpected(&self, what: &str) -> Error {
        match self.peek() {
            Some(t) => {
                let s = t.spelling();
                Error::new(t.pos, format!("expected {what}, found `{s}`")).len(s.len() as u32)
            }
            None => Error::new(self.pos(), format!("expected {what}, found end of file")),
        }
    }
    fn expect(&mut self, p: &str) -> Result<Pos> {
        let pos = self.pos();
        if self.eat(p) {
            Ok(pos)
        } else {
            Err(self.unexpected(&format!("`{p}`")))
        }
    }
    fn ident(&mut self) -> Result<(String, Pos)> {
        match self.peek() {
            Some(t) if t.ident().is_some() => {
                self.i += 1;
                let mut name = t.ident().unwrap_or_default().to_string();
                // `a::b::c` reads as one qualified name.
                while self.is("::") && self.peek_at(1).and_then(Token::ident).is_some() {
                    name.push_str("::");
                    name.push_str(self.peek_at(1).and_then(Token::ident).unwrap_or_default());
                    self.i += 2;
                }
                // DXC's `dx` namespace holds built-ins (`dx::HitObject`,
                // `dx::MaybeReorderThread`): they are known by their bare names.
                if let Some(bare) = name.strip_prefix("dx::") {
                    name = bare.to_string();
                }
                Ok((name, t.pos))
            }
            _ => Err(self.unexpected("a name")),
        }
    }
    fn enter(&mut self) -> Result<()> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            return Err(Error::new(self.pos(), "nesting too deep"));
        }
        Ok(())
    }

    /// Whether the identifier at `k` names a type.
    fn type_at(&self, k: usize) -> bool {
        let Some(name) = self.peek_at(k).and_then(Token::ident) else {
            return false;
        };
        if name == "unsigned" {
            return true;
        }
        if (is_builtin_type(name) || self.types.contains(name)) && !self.is_at(k + 1, "::") {
            return true;
        }
        // A qualified name whose last part is a known type.
        let mut full = name.to_string();
        let mut j = k + 1;
        while self.is_at(j, "::") {
            let Some(n) = self.peek_at(j + 1).and_then(Token::ident) else {
                break;
            };
            full.push_str("::");
            full.push_str(n);
            j += 2;
        }
        let full = full.strip_prefix("dx::").unwrap_or(&full);
        is_builtin_type(full) || self.types.contains(full) || self.ns_qualified(full).is_some()
    }

    fn ns_qualified(&self, name: &str) -> Option<String> {
        let mut prefix = self.ns.join("::");
        loop {
            if prefix.is_empty() {
                return self
                    .using
                    .iter()
                    .map(|u| format!("{u}::{name}"))
                    .find(|q| self.types.contains(q));
            }
            let q = format!("{prefix}::{name}");
            if self.types.contains(&q) {
                return Some(q);
            }
            match prefix.rfind("::") {
                Some(k) => prefix.truncate(k),
                None => prefix.clear(),
            }
        }
    }

    fn declare_type(&mut self, name: &str) {
        let q = self.qualify(name);
        self.types.insert(q);
    }

    fn qualify(&self, name: &str) -> String {
        if self.ns.is_empty() {
            name.to_string()
        } else {
            format!("{}::{name}", self.ns.join("::"))
        }
    }

    fn type_ref(&mut self) -> Result<TypeRef> {
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

    fn attrs(&mut self) -> Result<Vec<Attr>> {
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
                let name = match super::attrs::lookup(&name) {
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

    fn mods(&mut self) -> Mods {
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
                Some(
                    "inline" | "export" | "extern" | "volatile" | "linear" | "snorm" | "unorm"
                    | "globallycoherent",
                ) => {}
                _ => return m,
            }
            self.i += 1;
        }
    }

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

    /// `template<typename T, uint N = 4>`.
    fn template_params(&mut self) -> Result<Vec<TParam>> {
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
    fn template_args(&mut self) -> Result<Vec<TArg>> {
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
    fn template_args_at(&self, k: usize) -> bool {
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
    fn mods_len(&self) -> usize {
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

    fn item(&mut self, items: &mut Vec<Item>) -> Result<()> {
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

    /// A struct or class. Nested declarations (structs, enums, typedefs,
    /// `static` members) go to `items`, qualified by the struct's name, before it.
    fn struct_decl(&mut self, items: &mut Vec<Item>) -> Result<StructDecl> {
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

    fn dims(&mut self) -> Result<Vec<Option<Expr>>> {
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
    fn post_decl(&mut self) -> Result<PostDecl> {
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

    fn declarators(
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

    fn function(
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

    fn block(&mut self) -> Result<Vec<Stmt>> {
        self.expect("{")?;
        let mut out = Vec::new();
        while !self.is("}") {
            if self.peek().is_none() {
                return Err(self.unexpected("`}`"));
            }
            out.push(self.stmt()?);
        }
        self.i += 1;
        Ok(out)
    }

    fn stmt(&mut self) -> Result<Stmt> {
        self.enter()?;
        let s = self.stmt_inner();
        self.depth -= 1;
        s
    }

    fn stmt_inner(&mut self) -> Result<Stmt> {
        // [unroll], [loop], [branch], [flatten]: hints only.
        check_site(&self.attrs()?, Site::Statement)?;
        let pos = self.pos();
        let kind = match self.peek().map(|t| &t.tok) {
            None => return Err(self.unexpected("a statement")),
            Some(Tok::Punct("{")) => StmtKind::Block(self.block()?),
            Some(Tok::Punct(";")) => {
                self.i += 1;
                StmtKind::Empty
            }
            Some(Tok::Ident(k)) if (&**k == "struct" || &**k == "class") && self.is_at(2, "{") => {
                // A struct declared in a function: declared before the function
                // (named as written), then the declarators if any.
                let mut nested = Vec::new();
                let sd = self.struct_decl(&mut nested)?;
                let ty = TypeRef {
                    name: sd.name.clone(),
                    args: Vec::new(),
                    pos: sd.pos,
                };
                self.hoisted.extend(nested);
                self.hoisted.push(Item::Struct(sd));
                if self.eat(";") {
                    StmtKind::Empty
                } else {
                    let mut vars = Vec::new();
                    self.declarators(Vec::new(), Mods::default(), ty, &mut vars)?;
                    StmtKind::Decl(vars)
                }
            }
            Some(Tok::Ident(k)) => match &**k {
                "if" => {
                    self.i += 1;
                    self.expect("(")?;
                    let c = self.expr()?;
                    self.expect(")")?;
                    let then = Box::new(self.stmt()?);
                    let els = if self.eat("else") {
                        Some(Box::new(self.stmt()?))
                    } else {
                        None
                    };
                    StmtKind::If(c, then, els)
                }
                "for" => {
                    self.i += 1;
                    self.expect("(")?;
                    let init = if self.eat(";") {
                        None
                    } else {
                        Some(Box::new(self.simple_stmt()?))
                    };
                    let cond = if self.is(";") {
                        None
                    } else {
                        Some(self.expr()?)
                    };
                    self.expect(";")?;
                    let step = if self.is(")") {
                        None
                    } else {
                        Some(self.expr()?)
                    };
                    self.expect(")")?;
                    StmtKind::For(init, cond, step, Box::new(self.stmt()?))
                }
                "while" => {
                    self.i += 1;
                    self.expect("(")?;
                    let c = self.expr()?;
                    self.expect(")")?;
                    StmtKind::While(c, Box::new(self.stmt()?))
                }
                "do" => {
                    self.i += 1;
                    let body = Box::new(self.stmt()?);
                    self.expect("while")?;
                    self.expect("(")?;
                    let c = self.expr()?;
                    self.expect(")")?;
                    self.expect(";")?;
                    StmtKind::DoWhile(body, c)
                }
                "switch" => {
                    self.i += 1;
                    self.expect("(")?;
                    let e = self.expr()?;
                    self.expect(")")?;
                    self.expect("{")?;
                    let mut cases: Vec<Case> = Vec::new();
                    while !self.eat("}") {
                        let cpos = self.pos();
                        let mut labels = Vec::new();
                        loop {
                            if self.eat("case") {
                                labels.push(Some(self.ternary()?));
                                self.expect(":")?;
                            } else if self.eat("default") {
                                labels.push(None);
                                self.expect(":")?;
                            } else {
                                break;
                            }
                        }
                        if labels.is_empty() {
                            return Err(self.unexpected("`case` or `default`"));
                        }
                        let mut body = Vec::new();
                        while !self.is_kw("case") && !self.is_kw("default") && !self.is("}") {
                            if self.peek().is_none() {
                                return Err(self.unexpected("`}`"));
                            }
                            body.push(self.stmt()?);
                        }
                        cases.push(Case {
                            labels,
                            body,
                            pos: cpos,
                        });
                    }
                    StmtKind::Switch(e, cases)
                }
                "break" => {
                    self.i += 1;
                    self.expect(";")?;
                    StmtKind::Break
                }
                "continue" => {
                    self.i += 1;
                    self.expect(";")?;
                    StmtKind::Continue
                }
                "discard" => {
                    self.i += 1;
                    self.expect(";")?;
                    StmtKind::Discard
                }
                "return" => {
                    self.i += 1;
                    let v = if self.is(";") {
                        None
                    } else {
                        Some(self.expr()?)
                    };
                    self.expect(";")?;
                    StmtKind::Return(v)
                }
                _ => return self.simple_stmt(),
            },
            Some(_) => return self.simple_stmt(),
        };
        Ok(Stmt { kind, pos })
    }

    /// A declaration or expression statement, with its `;`.
    fn simple_stmt(&mut self) -> Result<Stmt> {
        let pos = self.pos();
        let starts_decl = matches!(
            self.peek().and_then(Token::ident),
            Some(
                "const"
                    | "static"
                    | "row_major"
                    | "column_major"
                    | "precise"
                    | "groupshared"
                    | "uniform"
            )
        ) || (self.type_at(0) && !self.is_at(1, "(") && !self.is_at(1, "::"))
            || (self.type_at(0) && self.is_at(1, "::") && {
                let mut k = 1;
                while self.is_at(k, "::") {
                    k += 2;
                }
                !self.is_at(k, "(")
            });
        if starts_decl {
            if self.is_kw("struct") {
                return Err(Error::unsupported(pos, "local struct declaration"));
            }
            let mods = self.mods();
            let ty = self.type_ref()?;
            let mut vars = Vec::new();
            self.declarators(Vec::new(), mods, ty, &mut vars)?;
            return Ok(Stmt {
                kind: StmtKind::Decl(vars),
                pos,
            });
        }
        // `Name name` can only be a declaration: the type is unknown.
        if let (Some(a), Some(_)) = (
            self.peek().and_then(Token::ident),
            self.peek_at(1).and_then(Token::ident),
        ) {
            return Err(Error::new(pos, format!("unknown type `{a}`")).len(a.len() as u32));
        }
        let e = self.expr()?;
        self.expect(";")?;
        Ok(Stmt {
            kind: StmtKind::Expr(e),
            pos,
        })
    }

    pub fn expr(&mut self) -> Result<Expr> {
        let mut e = self.assign()?;
        while self.is(",") {
            let pos = self.pos();
            self.i += 1;
            let r = self.assign()?;
            e = Expr {
                kind: ExprKind::Comma(Box::new(e), Box::new(r)),
                pos,
            };
        }
        Ok(e)
    }

    fn assign(&mut self) -> Result<Expr> {
        self.enter()?;
        let lhs = self.ternary()?;
        let op = match self.peek().map(|t| &t.tok) {
            Some(Tok::Punct("=")) => Some(None),
            Some(Tok::Punct(p)) => match *p {
                "+=" => Some(Some(BinOp::Add)),
                "-=" => Some(Some(BinOp::Sub)),
                "*=" => Some(Some(BinOp::Mul)),
                "/=" => Some(Some(BinOp::Div)),
                "%=" => Some(Some(BinOp::Rem)),
                "<<=" => Some(Some(BinOp::Shl)),
                ">>=" => Some(Some(BinOp::Shr)),
                "&=" => Some(Some(BinOp::BitAnd)),
                "|=" => Some(Some(BinOp::BitOr)),
                "^=" => Some(Some(BinOp::BitXor)),
                _ => None,
            },
            _ => None,
        };
        let out = if let Some(op) = op {
            let pos = self.pos();
            self.i += 1;
            let rhs = self.assign()?;
            Expr {
                kind: ExprKind::Assign(op, Box::new(lhs), Box::new(rhs)),
                pos,
            }
        } else {
            lhs
        };
        self.depth -= 1;
        Ok(out)
    }

    fn ternary(&mut self) -> Result<Expr> {
        let c = self.binary(0, false)?;
        if self.is("?") {
            let pos = self.pos();
            self.i += 1;
            self.enter()?;
            let a = self.assign()?;
            self.expect(":")?;
            let b = self.assign()?;
            self.depth -= 1;
            return Ok(Expr {
                kind: ExprKind::Ternary(Box::new(c), Box::new(a), Box::new(b)),
                pos,
            });
        }
        Ok(c)
    }

    /// Precedence climbing; `in_template` stops at `>` (template argument lists).
    fn binary(&mut self, min: u8, in_template: bool) -> Result<Expr> {
        let mut lhs = self.unary()?;
        // Each operator of a chain deepens the tree later passes recurse
        // over (`a + b + c` is `(a + b) + c`): it counts as a level until the
        // chain ends.
        let mut chain = 0;
        let out = loop {
            let Some(Tok::Punct(p)) = self.peek().map(|t| &t.tok) else {
                break lhs;
            };
            let (prec, op) = match *p {
                "||" => (1, BinOp::Or),
                "&&" => (2, BinOp::And),
                "|" => (3, BinOp::BitOr),
                "^" => (4, BinOp::BitXor),
                "&" => (5, BinOp::BitAnd),
                "==" => (6, BinOp::Eq),
                "!=" => (6, BinOp::Ne),
                "<" => (7, BinOp::Lt),
                ">" if !in_template => (7, BinOp::Gt),
                "<=" => (7, BinOp::Le),
                ">=" => (7, BinOp::Ge),
                "<<" => (8, BinOp::Shl),
                ">>" if !in_template => (8, BinOp::Shr),
                "+" => (9, BinOp::Add),
                "-" => (9, BinOp::Sub),
                "*" => (10, BinOp::Mul),
                "/" => (10, BinOp::Div),
                "%" => (10, BinOp::Rem),
                _ => break lhs,
            };
            if prec <= min {
                break lhs;
            }
            let pos = self.pos();
            self.i += 1;
            self.enter()?;
            chain += 1;
            let rhs = self.binary(prec, in_template)?;
            lhs = Expr {
                kind: ExprKind::Binary(op, Box::new(lhs), Box::new(rhs)),
                pos,
            };
        };
        self.depth -= chain;
        Ok(out)
    }

    fn enum_value_ahead(&self) -> bool {
        let mut k = 1;
        while self.is_at(k, "::") && self.peek_at(k + 1).and_then(Token::ident).is_some() {
            k += 2;
        }
        k > 1 && !self.is_at(k, "(") && !self.is_at(k, "<")
    }

    /// At `(`: a cast when a type and `)` follow.
    fn cast_ahead(&self) -> bool {
        if !self.is("(") || !self.type_at(1) {
            return false;
        }
        // Skip the type (with a template list) and look for `)`.
        let mut k = 2;
        if self.peek_at(1).and_then(Token::ident) == Some("unsigned")
            && self
                .peek_at(2)
                .and_then(Token::ident)
                .is_some_and(|n| n.starts_with("int"))
        {
            k = 3;
        }
        while self.is_at(k, "::") {
            k += 2;
        }
        if self.is_at(k, "<") {
            let mut depth = 0;
            while let Some(t) = self.peek_at(k) {
                if t.is("<") {
                    depth += 1;
                } else if t.is(">") {
                    depth -= 1;
                    if depth == 0 {
                        break;
                    }
                } else if t.is(";") {
                    return false;
                }
                k += 1;
            }
            k += 1;
        }
        self.is_at(k, ")")
    }

    fn unary(&mut self) -> Result<Expr> {
        self.enter()?;
        let pos = self.pos();
        let op = match self.peek().map(|t| &t.tok) {
            Some(Tok::Punct("-")) => Some(UnOp::Neg),
            Some(Tok::Punct("+")) => Some(UnOp::Plus),
            Some(Tok::Punct("!")) => Some(UnOp::Not),
            Some(Tok::Punct("~")) => Some(UnOp::BitNot),
            Some(Tok::Punct("++")) => Some(UnOp::PreInc),
            Some(Tok::Punct("--")) => Some(UnOp::PreDec),
            _ => None,
        };
        let e = if let Some(op) = op {
            self.i += 1;
            let e = self.unary()?;
            Expr {
                kind: ExprKind::Unary(op, Box::new(e)),
                pos,
            }
        } else if self.cast_ahead() {
            self.i += 1;
            let ty = self.type_ref()?;
            self.expect(")")?;
            let e = self.unary()?;
            Expr {
                kind: ExprKind::Cast(ty, Box::new(e)),
                pos,
            }
        } else {
            self.postfix()?
        };
        self.depth -= 1;
        Ok(e)
    }

    fn args(&mut self) -> Result<Vec<Expr>> {
        self.expect("(")?;
        let mut args = Vec::new();
        if !self.is(")") {
            loop {
                args.push(self.assign()?);
                if !self.eat(",") {
                    break;
                }
            }
        }
        self.expect(")")?;
        Ok(args)
    }

    fn postfix(&mut self) -> Result<Expr> {
        let mut e = self.primary()?;
        loop {
            let pos = self.pos();
            if self.eat(".") {
                // Member and method expressions point at the name after the dot.
                let (name, pos) = self.ident()?;
                if self.template_args_at(0) {
                    let targs = self.template_args()?;
                    let args = self.args()?;
                    e = Expr {
                        kind: ExprKind::MethodT(Box::new(e), name, targs, args),
                        pos,
                    };
                    continue;
                }
                if self.is("(") {
                    let args = self.args()?;
                    e = Expr {
                        kind: ExprKind::Method(Box::new(e), name, args),
                        pos,
                    };
                } else {
                    e = Expr {
                        kind: ExprKind::Member(Box::new(e), name),
                        pos,
                    };
                }
            } else if self.eat("[") {
                let idx = self.expr()?;
                self.expect("]")?;
                e = Expr {
                    kind: ExprKind::Index(Box::new(e), Box::new(idx)),
                    pos,
                };
            } else if self.is("++") || self.is("--") {
                let op = if self.is("++") {
                    UnOp::PostInc
                } else {
                    UnOp::PostDec
                };
                self.i += 1;
                e = Expr {
                    kind: ExprKind::Unary(op, Box::new(e)),
                    pos,
                };
            } else {
                return Ok(e);
            }
        }
    }

    fn primary(&mut self) -> Result<Expr> {
        let pos = self.pos();
        let Some(t) = self.peek() else {
            return Err(self.unexpected("an expression"));
        };
        let kind = match &t.tok {
            Tok::Int(v, u) if *v > u32::MAX as u64 => {
                self.i += 1;
                ExprKind::Int64(*v, *u)
            }
            Tok::Int(v, u) => {
                self.i += 1;
                ExprKind::Int(*v, *u)
            }
            Tok::Long(v, u) => {
                self.i += 1;
                ExprKind::Int64(*v, *u)
            }
            Tok::Float(f) => {
                self.i += 1;
                ExprKind::Float(*f)
            }
            Tok::Str(s) => {
                self.i += 1;
                // Adjacent literals join, as in C: `"SRV(t0), " "UAV(u0)"`.
                let mut s = s.to_string();
                while let Some(Tok::Str(more)) = self.peek().map(|t| &t.tok) {
                    s.push_str(more);
                    self.i += 1;
                }
                ExprKind::Str(s)
            }
            Tok::Punct("(") => {
                self.i += 1;
                let e = self.expr()?;
                self.expect(")")?;
                return Ok(e);
            }
            Tok::Ident(k) if &**k == "true" || &**k == "false" => {
                self.i += 1;
                ExprKind::Bool(&**k == "true")
            }
            Tok::Ident(k) if &**k == "sizeof" && self.is_at(1, "(") => {
                self.i += 2;
                if !self.type_at(0) {
                    let e = self.expr()?;
                    self.expect(")")?;
                    return Ok(Expr {
                        kind: ExprKind::SizeOfExpr(Box::new(e)),
                        pos,
                    });
                }
                let ty = self.type_ref()?;
                let dims = self.dims()?;
                self.expect(")")?;
                ExprKind::SizeOf(ty, dims)
            }
            // `Enum::Value` names a value even though `Enum` is a type.
            Tok::Ident(_) if self.type_at(0) && !self.enum_value_ahead() => {
                let ty = self.type_ref()?;
                if !self.is("(") {
                    return Err(self.unexpected("`(` after a type name in an expression"));
                }
                let args = self.args()?;
                ExprKind::Construct(ty, args)
            }
            Tok::Ident(_) => {
                let (name, _) = self.ident()?;
                let bare = name.rsplit("::").next().unwrap_or(&name);
                let builtin_template = matches!(
                    name.as_str(),
                    "vk::RawBufferLoad" | "vk::RawBufferStore" | "vk::ReadClock"
                );
                if (self.template_fns.contains(bare) || builtin_template)
                    && self.template_args_at(0)
                {
                    let targs = self.template_args()?;
                    let args = self.args()?;
                    return Ok(Expr {
                        kind: ExprKind::CallT(name, targs, args),
                        pos,
                    });
                }
                if self.is("(") {
                    let args = self.args()?;
                    ExprKind::Call(name, args)
                } else {
                    ExprKind::Ident(name)
                }
            }
            _ => return Err(self.unexpected("an expression")),
        };
        Ok(Expr { kind, pos })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::front::hlsl::lex::lex;

    fn items(s: &str) -> Vec<Item> {
        parse(&lex(s, 0).unwrap()).unwrap()
    }

    /// On a thread with the compiler's stack, as the front-end runs it.
    fn err(s: &str) -> (u32, u32, String) {
        let s = s.to_string();
        std::thread::Builder::new()
            .stack_size(64 << 20)
            .spawn(move || {
                let e = parse(&lex(&s, 0).unwrap()).unwrap_err();
                (e.pos.line, e.pos.col, e.message)
            })
            .unwrap()
            .join()
            .unwrap()
    }

    #[test]
    fn numeric_type_names() {
        assert_eq!(split_numeric("float3x4"), Some(("float", 3, 4)));
        assert_eq!(split_numeric("uint2"), Some(("uint", 2, 0)));
        assert_eq!(split_numeric("min16float"), Some(("min16float", 0, 0)));
        assert_eq!(split_numeric("float5"), None);
        assert_eq!(split_numeric("floaty"), None);
    }

    #[test]
    fn declarations() {
        let it = items(
            "struct P { float3 c : COLOR; uint d[2]; };\n\
             typedef float4 F4;\n\
             enum class E { A, B = 3 };\n\
             cbuffer C : register(b1, space2) { float4x4 m; F4 v; };\n\
             RaytracingAccelerationStructure s : register(t0);\n\
             [[vk::binding(3, 1)]] RWTexture2D<float4> img;\n\
             static const float k[2] = { 1.0, 2.0 };\n\
             namespace N { float f(float x) { return x; } }\n\
             [shader(\"raygeneration\")] void rg() { P p; p.c.xy = (float2)N::f(1); }",
        );
        assert_eq!(it.len(), 9);
        match &it[3] {
            Item::CBuffer {
                register: Some(r),
                members,
                ..
            } => {
                assert_eq!((r.class, r.index, r.space), ('b', Some(1), 2));
                assert_eq!(members.len(), 2);
            }
            other => panic!("{other:?}"),
        }
        match &it[5] {
            Item::Var(v) => {
                assert_eq!(v.ty.name, "RWTexture2D");
                assert_eq!(v.attrs[0].name, "vk::binding");
            }
            other => panic!("{other:?}"),
        }
        match &it[7] {
            Item::Function(f) => assert_eq!(f.name, "N::f"),
            other => panic!("{other:?}"),
        }
        match &it[8] {
            Item::Function(f) => {
                assert_eq!(f.attrs[0].name, "shader");
                let body = f.body.as_ref().unwrap();
                assert!(matches!(body[0].kind, StmtKind::Decl(_)));
                let StmtKind::Expr(e) = &body[1].kind else {
                    panic!()
                };
                let ExprKind::Assign(None, _, rhs) = &e.kind else {
                    panic!()
                };
                assert!(matches!(rhs.kind, ExprKind::Cast(..)));
            }
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn precedence_and_templates() {
        let it = items("RayQuery<RAY_FLAG_NONE | RAY_FLAG_FORCE_OPAQUE> q; int f() { return 1 + 2 * 3 << 1 > 2 ? a : b; }");
        match &it[0] {
            Item::Var(v) => assert!(matches!(v.ty.args[0], TArg::Expr(_))),
            other => panic!("{other:?}"),
        }
        let Item::Function(f) = &it[1] else { panic!() };
        let StmtKind::Return(Some(e)) = &f.body.as_ref().unwrap()[0].kind else {
            panic!()
        };
        let ExprKind::Ternary(c, ..) = &e.kind else {
            panic!()
        };
        let ExprKind::Binary(BinOp::Gt, l, _) = &c.kind else {
            panic!()
        };
        assert!(matches!(l.kind, ExprKind::Binary(BinOp::Shl, ..)));
    }

    #[test]
    fn errors_point_at_the_token() {
        assert_eq!(
            err("void f() {\n  x = ;\n}"),
            (2, 7, "expected an expression, found `;`".into())
        );
        assert_eq!(
            err("struct S { float a }"),
            (1, 20, "expected `;`, found `}`".into())
        );
        assert!(err("template<typename T> typedef T X;")
            .2
            .starts_with("not supported: templates other than functions and structs"));
        assert!(err("cbuffer C { float a : packoffset(c0); }")
            .2
            .starts_with("not supported: packoffset"));
        let deep = format!(
            "void f() {{ x = {}1{}; }}",
            "(".repeat(1000),
            ")".repeat(1000)
        );
        assert_eq!(err(&deep).2, "nesting too deep");
    }
}
