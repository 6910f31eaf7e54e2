//! Statements.

use super::*;

impl<'t> Parser<'t> {
    pub(super) fn block(&mut self) -> Result<Vec<Stmt>> {
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
}
