//! Syntax tree of the HLSL subset, every node with the position of its first token.

use super::error::Pos;

#[derive(Clone, Debug)]
pub struct TypeRef {
    /// As written; namespace-qualified names keep their `::`.
    pub name: String,
    pub args: Vec<TArg>,
    pub pos: Pos,
}

#[derive(Clone, Debug)]
pub enum TArg {
    Type(TypeRef),
    Expr(Expr),
}

/// A template parameter: `typename T` / `class T`, or a value `uint N`.
#[derive(Clone, Debug)]
pub struct TParam {
    pub name: String,
    /// `None` for a type parameter; the value's type otherwise.
    pub value_ty: Option<TypeRef>,
    pub default: Option<TArg>,
    pub pos: Pos,
}

#[derive(Clone, Debug)]
pub struct Attr {
    /// `shader`, `numthreads`, `vk::binding`, ...
    pub name: String,
    pub args: Vec<Expr>,
    pub pos: Pos,
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Mods {
    pub is_static: bool,
    pub is_const: bool,
    pub groupshared: bool,
    pub uniform: bool,
    pub input: bool,
    pub output: bool,
    pub row_major: bool,
    pub column_major: bool,
    pub precise: bool,
    /// Interpolation of pixel shader inputs (`nointerpolation`, `centroid`,
    /// `sample`, `noperspective`; `linear` is the default).
    pub nointerp: bool,
    pub centroid: bool,
    pub sample: bool,
    pub noperspective: bool,
    /// `globallycoherent` (a resource: `Coherent`).
    pub globally_coherent: bool,
}

#[derive(Clone, Debug)]
pub struct Register {
    /// `t`, `u`, `b`, `s`; `?` for a space alone (`register(space1)`).
    pub class: char,
    /// `None` for a space alone: the binding is the next free one in it.
    pub index: Option<u32>,
    pub space: u32,
    pub pos: Pos,
}

#[derive(Clone, Debug)]
pub struct VarDecl {
    pub attrs: Vec<Attr>,
    pub mods: Mods,
    pub ty: TypeRef,
    pub name: String,
    pub pos: Pos,
    /// Array dimensions outermost first; `None` for `[]`.
    pub dims: Vec<Option<Expr>>,
    pub semantic: Option<(String, Pos)>,
    pub register: Option<Register>,
    pub init: Option<Expr>,
    /// `uint x : 24;`: a bit field of that many bits.
    pub bits: Option<(u32, Pos)>,
}

#[derive(Clone, Debug)]
pub struct Function {
    pub attrs: Vec<Attr>,
    pub ret: TypeRef,
    pub name: String,
    /// Enclosing namespace, `a::b::` or empty; unqualified names look here first.
    pub ns: String,
    pub pos: Pos,
    pub params: Vec<VarDecl>,
    pub semantic: Option<(String, Pos)>,
    pub body: Option<Vec<Stmt>>,
    /// A `static` struct method: no `this`.
    pub is_static: bool,
    /// Template parameters: a template, instantiated where it is used.
    pub tparams: Vec<TParam>,
}

#[derive(Clone, Debug)]
pub struct StructDecl {
    pub name: String,
    pub pos: Pos,
    /// `struct B : A`: A's members come first.
    pub bases: Vec<TypeRef>,
    /// Template parameters: a template, instantiated where it is used.
    pub tparams: Vec<TParam>,
    pub fields: Vec<VarDecl>,
    /// Methods: functions with an implicit `inout` `this`.
    pub methods: Vec<Function>,
}

#[derive(Clone, Debug)]
pub enum Item {
    Struct(StructDecl),
    Typedef {
        ty: TypeRef,
        dims: Vec<Option<Expr>>,
        name: String,
        pos: Pos,
    },
    Enum {
        name: String,
        scoped: bool,
        underlying: Option<TypeRef>,
        variants: Vec<(String, Pos, Option<Expr>)>,
        pos: Pos,
    },
    Var(VarDecl),
    CBuffer {
        attrs: Vec<Attr>,
        name: String,
        pos: Pos,
        register: Option<Register>,
        members: Vec<VarDecl>,
    },
    Function(Function),
    /// `using namespace a::b;`: unqualified names also look in `a::b::`.
    Using(String),
}

#[derive(Clone, Debug)]
pub struct Expr {
    pub kind: ExprKind,
    pub pos: Pos,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UnOp {
    Neg,
    Plus,
    Not,
    BitNot,
    PreInc,
    PreDec,
    PostInc,
    PostDec,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BinOp {
    Add,
    Sub,
    Mul,
    Div,
    Rem,
    Shl,
    Shr,
    BitAnd,
    BitOr,
    BitXor,
    And,
    Or,
    Eq,
    Ne,
    Lt,
    Le,
    Gt,
    Ge,
}

impl BinOp {
    pub fn as_str(self) -> &'static str {
        use BinOp::*;
        match self {
            Add => "+",
            Sub => "-",
            Mul => "*",
            Div => "/",
            Rem => "%",
            Shl => "<<",
            Shr => ">>",
            BitAnd => "&",
            BitOr => "|",
            BitXor => "^",
            And => "&&",
            Or => "||",
            Eq => "==",
            Ne => "!=",
            Lt => "<",
            Le => "<=",
            Gt => ">",
            Ge => ">=",
        }
    }
}

#[derive(Clone, Debug)]
pub enum ExprKind {
    Int(u64, bool),
    /// A 64-bit literal (`1ull`, `0x1ffffffffl`, or too large for 32 bits).
    Int64(u64, bool),
    Float(f64),
    Bool(bool),
    /// Only in attributes (`[shader("miss")]`).
    Str(String),
    Ident(String),
    Unary(UnOp, Box<Expr>),
    Binary(BinOp, Box<Expr>, Box<Expr>),
    Assign(Option<BinOp>, Box<Expr>, Box<Expr>),
    Ternary(Box<Expr>, Box<Expr>, Box<Expr>),
    /// A call of a function or intrinsic by name.
    Call(String, Vec<Expr>),
    /// `f<T, 3>(args)`: a call with explicit template arguments.
    CallT(String, Vec<TArg>, Vec<Expr>),
    /// `obj.f<T>(args)`.
    MethodT(Box<Expr>, String, Vec<TArg>, Vec<Expr>),
    /// `float3(...)`, `RayDesc(...)`: a constructor.
    Construct(TypeRef, Vec<Expr>),
    Method(Box<Expr>, String, Vec<Expr>),
    Member(Box<Expr>, String),
    Index(Box<Expr>, Box<Expr>),
    Cast(TypeRef, Box<Expr>),
    InitList(Vec<Expr>),
    /// `sizeof(T)` or `sizeof(T[N])`: bytes, scalars packed (as DXC's HLSL 2021).
    SizeOf(TypeRef, Vec<Option<Expr>>),
    /// `sizeof(expression)`: the size of the expression's type (names,
    /// members and elements only; it is not evaluated).
    SizeOfExpr(Box<Expr>),
    Comma(Box<Expr>, Box<Expr>),
}

#[derive(Clone, Debug)]
pub struct Stmt {
    pub kind: StmtKind,
    pub pos: Pos,
}

#[derive(Clone, Debug)]
pub struct Case {
    /// `None` is `default:`.
    pub labels: Vec<Option<Expr>>,
    pub body: Vec<Stmt>,
    pub pos: Pos,
}

#[derive(Clone, Debug)]
pub enum StmtKind {
    Block(Vec<Stmt>),
    Decl(Vec<VarDecl>),
    Expr(Expr),
    If(Expr, Box<Stmt>, Option<Box<Stmt>>),
    For(Option<Box<Stmt>>, Option<Expr>, Option<Expr>, Box<Stmt>),
    While(Expr, Box<Stmt>),
    DoWhile(Box<Stmt>, Expr),
    Switch(Expr, Vec<Case>),
    Break,
    Continue,
    Return(Option<Expr>),
    Discard,
    Empty,
}
