//! Expressions, by precedence climbing.

use super::*;

impl<'t> Parser<'t> {
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

    pub(super) fn assign(&mut self) -> Result<Expr> {
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

    pub(super) fn ternary(&mut self) -> Result<Expr> {
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
    pub(super) fn binary(&mut self, min: u8, in_template: bool) -> Result<Expr> {
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
