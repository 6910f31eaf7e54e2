//! Parser: preprocessed tokens → [`ast::Item`]s.
//!
//! HLSL, like C, needs to know which names are types (`(T)x` is a cast, `T x;`
//! a declaration), so the parser records struct, typedef and enum names as it
//! meets them.

mod decl;
mod expr;
mod items;
mod stmt;
mod types;

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
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lex::lex;

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
