//! `#if` and `#elif` expressions: integers with C's operators and precedence.

use super::*;

/// Integer expressions of `#if`, with C's precedence.
struct CondExpr<'t> {
    t: &'t [Token],
    i: usize,
}

impl CondExpr<'_> {
    fn peek(&self, p: &str) -> bool {
        self.t.get(self.i).is_some_and(|t| t.is(p))
    }
    fn pos(&self) -> Pos {
        self.t
            .get(self.i)
            .or_else(|| self.t.last())
            .map(|t| t.pos)
            .unwrap_or_default()
    }
    fn ternary(&mut self) -> Result<i64> {
        let c = self.binary(0)?;
        if self.peek("?") {
            self.i += 1;
            let a = self.ternary()?;
            if !self.peek(":") {
                return Err(Error::new(self.pos(), "expected `:` in #if expression"));
            }
            self.i += 1;
            let b = self.ternary()?;
            return Ok(if c != 0 { a } else { b });
        }
        Ok(c)
    }
    fn binary(&mut self, min: u8) -> Result<i64> {
        let mut lhs = self.unary()?;
        while let Some(Tok::Punct(op)) = self.t.get(self.i).map(|t| &t.tok) {
            let prec = match *op {
                "||" => 1,
                "&&" => 2,
                "|" => 3,
                "^" => 4,
                "&" => 5,
                "==" | "!=" => 6,
                "<" | ">" | "<=" | ">=" => 7,
                "<<" | ">>" => 8,
                "+" | "-" => 9,
                "*" | "/" | "%" => 10,
                _ => break,
            };
            if prec <= min && min > 0 || prec < min {
                break;
            }
            let op = *op;
            let at = self.pos();
            self.i += 1;
            let rhs = self.binary(prec)?;
            lhs = match op {
                "||" => ((lhs != 0) || (rhs != 0)) as i64,
                "&&" => ((lhs != 0) && (rhs != 0)) as i64,
                "|" => lhs | rhs,
                "^" => lhs ^ rhs,
                "&" => lhs & rhs,
                "==" => (lhs == rhs) as i64,
                "!=" => (lhs != rhs) as i64,
                "<" => (lhs < rhs) as i64,
                ">" => (lhs > rhs) as i64,
                "<=" => (lhs <= rhs) as i64,
                ">=" => (lhs >= rhs) as i64,
                "<<" => lhs.wrapping_shl(rhs as u32),
                ">>" => lhs.wrapping_shr(rhs as u32),
                "+" => lhs.wrapping_add(rhs),
                "-" => lhs.wrapping_sub(rhs),
                "*" => lhs.wrapping_mul(rhs),
                "/" | "%" => {
                    if rhs == 0 {
                        return Err(Error::new(at, "division by zero in #if expression"));
                    }
                    if op == "/" {
                        lhs.wrapping_div(rhs)
                    } else {
                        lhs.wrapping_rem(rhs)
                    }
                }
                _ => unreachable!(),
            };
        }
        Ok(lhs)
    }
    fn unary(&mut self) -> Result<i64> {
        let Some(t) = self.t.get(self.i) else {
            return Err(Error::new(self.pos(), "#if expression ends early"));
        };
        self.i += 1;
        match &t.tok {
            Tok::Int(v, _) | Tok::Long(v, _) => Ok(*v as i64),
            // Identifiers left after expansion are 0, as in C.
            Tok::Ident(_) => Ok(0),
            Tok::Punct("!") => Ok((self.unary()? == 0) as i64),
            Tok::Punct("~") => Ok(!self.unary()?),
            Tok::Punct("-") => Ok(self.unary()?.wrapping_neg()),
            Tok::Punct("+") => self.unary(),
            Tok::Punct("(") => {
                let v = self.ternary()?;
                if !self.peek(")") {
                    return Err(Error::new(self.pos(), "expected `)` in #if expression"));
                }
                self.i += 1;
                Ok(v)
            }
            _ => Err(Error::new(
                t.pos,
                format!("unexpected `{}` in #if expression", t.spelling()),
            )),
        }
    }
}

impl Preprocessor<'_> {
    /// Evaluates the condition of `#if`/`#elif`.
    pub(super) fn eval_if(&mut self, line: &[Token], pos: Pos) -> Result<i64> {
        // `defined X` / `defined(X)` is resolved before expansion.
        let mut toks = Vec::new();
        let mut k = 0;
        while k < line.len() {
            let t = &line[k];
            if t.ident() == Some("defined") {
                let (name, next) = if line.get(k + 1).is_some_and(|t| t.is("(")) {
                    let n = line.get(k + 2).and_then(Token::ident);
                    if !line.get(k + 3).is_some_and(|t| t.is(")")) {
                        return Err(Error::new(t.pos, "expected `defined(NAME)`"));
                    }
                    (n, k + 4)
                } else {
                    (line.get(k + 1).and_then(Token::ident), k + 2)
                };
                let name = name.ok_or_else(|| Error::new(t.pos, "`defined` needs a name"))?;
                let mut d = t.clone();
                d.tok = Tok::Int(self.macros.contains_key(name) as u64, false);
                toks.push(d);
                k = next;
            } else {
                toks.push(t.clone());
                k += 1;
            }
        }
        let toks = self.expand(toks)?;
        if toks.is_empty() {
            return Err(Error::new(pos, "#if needs an expression"));
        }
        let mut e = CondExpr { t: &toks, i: 0 };
        let v = e.ternary()?;
        if let Some(t) = toks.get(e.i) {
            return Err(Error::new(
                t.pos,
                format!("unexpected `{}` in #if expression", t.spelling()),
            ));
        }
        Ok(v)
    }
}
