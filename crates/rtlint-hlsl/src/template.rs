//! Templates: a function or struct template is copied with its parameters
//! replaced by concrete arguments, once per distinct argument list used.
//!
//! The lowerer finds which instances a module needs (from explicit
//! arguments `f<float>(x)`, `S<3>`, or arguments deduced from the call) and
//! names each one (`f<float>`, `ns::S<3>`); [`instantiate`] adds the copy to
//! the syntax tree, and lowering starts again until nothing is missing.

use super::ast::*;
use super::error::{Error, Pos, Result};
use std::collections::HashMap;

/// An instance the lowerer needs: the template (by the position of its
/// name), its arguments, and the instance's name.
#[derive(Clone, Debug)]
pub struct Instance {
    pub template: Pos,
    pub args: Vec<TArg>,
    /// The instance's full name, `ns::f<float,3>`.
    pub name: String,
}

/// Adds the instance to `items`: a function or struct after the others, a
/// method into its struct.
pub fn instantiate(items: &mut Vec<Item>, inst: &Instance) -> Result<()> {
    let mut found = None;
    for (i, item) in items.iter_mut().enumerate() {
        match item {
            Item::Function(f) if f.pos == inst.template && !f.tparams.is_empty() => {
                let map = bindings(&f.tparams, &inst.args, inst.template)?;
                let mut g = f.clone();
                g.tparams.clear();
                g.name = inst.name.clone();
                Subst(&map).function(&mut g);
                found = Some((i, Item::Function(g)));
                break;
            }
            Item::Struct(sd) if sd.pos == inst.template && !sd.tparams.is_empty() => {
                let map = bindings(&sd.tparams, &inst.args, inst.template)?;
                let mut t = sd.clone();
                t.tparams.clear();
                t.name = inst.name.clone();
                let s = Subst(&map);
                for b in &mut t.bases {
                    s.ty(b);
                }
                for f in &mut t.fields {
                    s.var(f);
                }
                for m in &mut t.methods {
                    s.function(m);
                }
                found = Some((i, Item::Struct(t)));
                break;
            }
            Item::Struct(sd) => {
                let Some(m) = sd
                    .methods
                    .iter()
                    .find(|m| m.pos == inst.template && !m.tparams.is_empty())
                else {
                    continue;
                };
                let map = bindings(&m.tparams, &inst.args, inst.template)?;
                let mut g = m.clone();
                g.tparams.clear();
                let owner = format!("{}::", sd.name);
                g.name = inst
                    .name
                    .strip_prefix(&owner)
                    .unwrap_or(&inst.name)
                    .to_string();
                Subst(&map).function(&mut g);
                sd.methods.push(g);
                return Ok(());
            }
            _ => {}
        }
    }
    match found {
        Some((_, item)) => {
            items.push(item);
            Ok(())
        }
        None => Err(Error::new(inst.template, "template not found")),
    }
}

/// Parameter name → argument, defaults filling what is left out.
fn bindings(params: &[TParam], args: &[TArg], pos: Pos) -> Result<HashMap<String, TArg>> {
    if args.len() > params.len() {
        return Err(Error::new(
            pos,
            format!(
                "{} template argument(s) given, the template takes {}",
                args.len(),
                params.len()
            ),
        ));
    }
    let mut map = HashMap::new();
    for (i, p) in params.iter().enumerate() {
        let a = match (args.get(i), &p.default) {
            (Some(a), _) => a.clone(),
            (None, Some(d)) => d.clone(),
            (None, None) => {
                return Err(Error::new(
                    pos,
                    format!("no argument for template parameter `{}`", p.name),
                ))
            }
        };
        map.insert(p.name.clone(), a);
    }
    Ok(map)
}

/// Replaces template parameters in a syntax tree.
struct Subst<'m>(&'m HashMap<String, TArg>);

impl Subst<'_> {
    fn ty(&self, t: &mut TypeRef) {
        if t.args.is_empty() {
            if let Some(TArg::Type(r)) = self.0.get(&t.name) {
                let pos = t.pos;
                *t = r.clone();
                t.pos = pos;
                return;
            }
        }
        for a in &mut t.args {
            self.targ(a);
        }
    }

    fn targ(&self, a: &mut TArg) {
        match a {
            TArg::Type(t) => self.ty(t),
            TArg::Expr(e) => {
                // A type parameter written where the parser saw a value (`vector<T, N>`
                // parses `N` as an expression; `T` used as a value argument).
                if let ExprKind::Ident(n) = &e.kind {
                    if let Some(TArg::Type(r)) = self.0.get(n) {
                        *a = TArg::Type(r.clone());
                        return;
                    }
                }
                self.expr(e)
            }
        }
    }

    fn var(&self, v: &mut VarDecl) {
        self.ty(&mut v.ty);
        for d in v.dims.iter_mut().flatten() {
            self.expr(d);
        }
        if let Some(e) = &mut v.init {
            self.expr(e);
        }
    }

    fn function(&self, f: &mut Function) {
        self.ty(&mut f.ret);
        for p in &mut f.params {
            self.var(p);
        }
        if let Some(body) = &mut f.body {
            for s in body {
                self.stmt(s);
            }
        }
    }

    fn stmt(&self, s: &mut Stmt) {
        match &mut s.kind {
            StmtKind::Block(b) => b.iter_mut().for_each(|s| self.stmt(s)),
            StmtKind::Decl(vs) => vs.iter_mut().for_each(|v| self.var(v)),
            StmtKind::Expr(e) => self.expr(e),
            StmtKind::If(c, a, b) => {
                self.expr(c);
                self.stmt(a);
                if let Some(b) = b {
                    self.stmt(b);
                }
            }
            StmtKind::For(init, cond, step, body) => {
                if let Some(i) = init {
                    self.stmt(i);
                }
                if let Some(c) = cond {
                    self.expr(c);
                }
                if let Some(st) = step {
                    self.expr(st);
                }
                self.stmt(body);
            }
            StmtKind::While(c, body) => {
                self.expr(c);
                self.stmt(body);
            }
            StmtKind::DoWhile(body, c) => {
                self.stmt(body);
                self.expr(c);
            }
            StmtKind::Switch(sel, cases) => {
                self.expr(sel);
                for c in cases {
                    for l in c.labels.iter_mut().flatten() {
                        self.expr(l);
                    }
                    c.body.iter_mut().for_each(|s| self.stmt(s));
                }
            }
            StmtKind::Return(Some(e)) => self.expr(e),
            StmtKind::Return(None)
            | StmtKind::Break
            | StmtKind::Continue
            | StmtKind::Discard
            | StmtKind::Empty => {}
        }
    }

    fn expr(&self, e: &mut Expr) {
        match &mut e.kind {
            ExprKind::Ident(n) => {
                if let Some(TArg::Expr(v)) = self.0.get(n.as_str()) {
                    e.kind = v.kind.clone();
                }
            }
            ExprKind::Int(..)
            | ExprKind::Int64(..)
            | ExprKind::Float(_)
            | ExprKind::Bool(_)
            | ExprKind::Str(_) => {}
            ExprKind::Unary(_, a) => self.expr(a),
            ExprKind::Binary(_, a, b) | ExprKind::Assign(_, a, b) | ExprKind::Comma(a, b) => {
                self.expr(a);
                self.expr(b);
            }
            ExprKind::Ternary(c, a, b) => {
                self.expr(c);
                self.expr(a);
                self.expr(b);
            }
            ExprKind::Call(_, args) | ExprKind::InitList(args) => {
                args.iter_mut().for_each(|a| self.expr(a))
            }
            ExprKind::CallT(_, targs, args) => {
                targs.iter_mut().for_each(|a| self.targ(a));
                args.iter_mut().for_each(|a| self.expr(a));
            }
            ExprKind::Construct(t, args) => {
                self.ty(t);
                args.iter_mut().for_each(|a| self.expr(a));
            }
            ExprKind::Method(o, _, args) => {
                self.expr(o);
                args.iter_mut().for_each(|a| self.expr(a));
            }
            ExprKind::MethodT(o, _, targs, args) => {
                self.expr(o);
                targs.iter_mut().for_each(|a| self.targ(a));
                args.iter_mut().for_each(|a| self.expr(a));
            }
            ExprKind::Member(o, _) | ExprKind::SizeOfExpr(o) => self.expr(o),
            ExprKind::Index(a, b) => {
                self.expr(a);
                self.expr(b);
            }
            ExprKind::Cast(t, a) => {
                self.ty(t);
                self.expr(a);
            }
            ExprKind::SizeOf(t, dims) => {
                self.ty(t);
                for d in dims.iter_mut().flatten() {
                    self.expr(d);
                }
            }
        }
    }
}
