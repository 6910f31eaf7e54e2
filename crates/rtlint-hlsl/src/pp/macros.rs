//! Macro expansion: object and function macros, arguments, `#`, `##` and
//! `__VA_ARGS__`, with the hide sets that stop recursion.

use super::*;

/// Reads a macro's arguments after its `(`: top-level commas split them.
fn collect_args(
    queue: &mut std::collections::VecDeque<Token>,
    at: &Token,
) -> Result<Vec<Vec<Token>>> {
    let mut args = vec![Vec::new()];
    let mut depth = 0usize;
    loop {
        let Some(t) = queue.pop_front() else {
            return Err(Error::new(at.pos, "unterminated macro invocation")
                .label("this macro's `(` is never closed"));
        };
        if t.is("(") {
            depth += 1;
        } else if t.is(")") {
            if depth == 0 {
                break;
            }
            depth -= 1;
        } else if t.is(",") && depth == 0 {
            args.push(Vec::new());
            continue;
        }
        args.last_mut().unwrap_or_else(|| unreachable!()).push(t);
    }
    Ok(args)
}

/// Joins the arguments past the named ones into `__VA_ARGS__`, commas kept.
fn fold_variadic(mut args: Vec<Vec<Token>>, nparams: usize) -> Vec<Vec<Token>> {
    if args.len() <= nparams {
        return args;
    }
    let extra = args.split_off(nparams - 1);
    let mut va = Vec::new();
    for (n, a) in extra.into_iter().enumerate() {
        if n > 0 {
            let mut comma = a.first().cloned().unwrap_or_else(|| va_comma(&va));
            comma.tok = Tok::Punct(",");
            va.push(comma);
        }
        va.extend(a);
    }
    args.push(va);
    args
}

fn va_comma(prev: &[Token]) -> Token {
    let mut t = prev.last().cloned().unwrap_or(Token {
        tok: Tok::Punct(","),
        pos: Pos::default(),
        space: false,
        bol: false,
        hide: Rc::new(Vec::new()),
    });
    t.tok = Tok::Punct(",");
    t
}

impl Preprocessor<'_> {
    /// Expands macros in `input` (rescanning results together with what follows).
    pub(super) fn expand(&mut self, input: Vec<Token>) -> Result<Vec<Token>> {
        let mut queue: std::collections::VecDeque<Token> = input.into();
        let mut out = Vec::new();
        while let Some(t) = queue.pop_front() {
            let Some(name) = t.ident() else {
                out.push(t);
                continue;
            };
            if name == "__LINE__" {
                let mut n = t.clone();
                n.tok = Tok::Int(t.pos.line as u64, false);
                out.push(n);
                continue;
            }
            let Some(m) = self.macros.get(name) else {
                out.push(t);
                continue;
            };
            if t.hide.iter().any(|h| &**h == name) {
                out.push(t);
                continue;
            }
            let m = m.clone();
            let mut hide = (*t.hide).clone();
            hide.push(Rc::from(name));
            let hide = Rc::new(hide);
            let result = match &m.params {
                None => self.substitute(&m, &[], &t, &hide)?,
                Some(params) => {
                    if !queue.front().is_some_and(|n| n.is("(")) {
                        out.push(t);
                        continue;
                    }
                    queue.pop_front();
                    let args = collect_args(&mut queue, &t)?;
                    let args = if params.is_empty() && args.len() == 1 && args[0].is_empty() {
                        Vec::new()
                    } else {
                        args
                    };
                    let args = if m.variadic {
                        fold_variadic(args, params.len())
                    } else {
                        args
                    };
                    if args.len() != params.len() && !(m.variadic && args.len() + 1 == params.len())
                    {
                        return Err(Error::new(
                            t.pos,
                            format!(
                                "macro `{name}` takes {} argument(s), {} given",
                                params.len(),
                                args.len()
                            ),
                        )
                        .len(name.len() as u32));
                    }
                    let mut args = args;
                    while args.len() < params.len() {
                        args.push(Vec::new());
                    }
                    self.substitute(&m, &args, &t, &hide)?
                }
            };
            // Only what macros produce counts: a big file of plain code is
            // not an expansion that does not terminate.
            self.budget += result.len().max(1);
            if self.budget > EXPANSION_BUDGET {
                return Err(Error::new(t.pos, "macro expansion does not terminate"));
            }
            for r in result.into_iter().rev() {
                queue.push_front(r);
            }
        }
        Ok(out)
    }

    /// The macro body with parameters replaced, `#` and `##` applied; every
    /// token takes the invocation's position.
    fn substitute(
        &mut self,
        m: &Macro,
        args: &[Vec<Token>],
        at: &Token,
        hide: &Rc<Vec<Rc<str>>>,
    ) -> Result<Vec<Token>> {
        let params = m.params.as_deref().unwrap_or(&[]);
        let param = |t: &Token| -> Option<usize> {
            let id = t.ident()?;
            params.iter().position(|p| &**p == id)
        };
        let body = &m.body;
        // Pieces: Some(tokens) for real tokens; pasting works on the spelling.
        let mut out: Vec<Token> = Vec::new();
        let mut k = 0;
        // Whether the last pushed piece may be the left side of `##` (a placemarker
        // is represented by pushing nothing and remembering it).
        let mut last_was_empty_arg = false;
        while k < body.len() {
            let t = &body[k];
            if t.is("#") && m.params.is_some() {
                let idx = body.get(k + 1).and_then(&param).ok_or_else(|| {
                    Error::new(at.pos, "`#` must be followed by a macro parameter")
                })?;
                let mut s = String::new();
                for (n, a) in args[idx].iter().enumerate() {
                    if n > 0 && a.space {
                        s.push(' ');
                    }
                    s.push_str(&a.spelling());
                }
                let mut st = at.clone();
                st.tok = Tok::Str(Rc::from(s.as_str()));
                st.hide = hide.clone();
                out.push(st);
                k += 2;
                last_was_empty_arg = false;
                continue;
            }
            if t.is("##") {
                k += 1;
                let Some(rhs) = body.get(k) else { break };
                let rhs_toks: Vec<Token> = match param(rhs) {
                    Some(idx) => args[idx].clone(),
                    None => vec![rhs.clone()],
                };
                k += 1;
                if last_was_empty_arg || out.is_empty() {
                    out.extend(rhs_toks.into_iter().map(|mut r| {
                        r.pos = at.pos;
                        r.hide = hide.clone();
                        r
                    }));
                    last_was_empty_arg = false;
                    continue;
                }
                let mut rest = rhs_toks.into_iter();
                if let Some(first) = rest.next() {
                    let left = out.pop().unwrap_or_else(|| unreachable!());
                    let text = format!("{}{}", left.spelling(), first.spelling());
                    let pasted = lex(&text, at.pos.file).ok().filter(|v| v.len() == 1);
                    let Some(mut p) = pasted.and_then(|mut v| v.pop()) else {
                        return Err(Error::new(
                            at.pos,
                            format!(
                                "pasting `{}` and `{}` does not give one token",
                                left.spelling(),
                                first.spelling()
                            ),
                        ));
                    };
                    p.pos = at.pos;
                    p.space = left.space;
                    p.bol = false;
                    p.hide = hide.clone();
                    out.push(p);
                }
                out.extend(rest.map(|mut r| {
                    r.pos = at.pos;
                    r.hide = hide.clone();
                    r
                }));
                continue;
            }
            if let Some(idx) = param(t) {
                let next_is_paste = body.get(k + 1).is_some_and(|n| n.is("##"));
                let toks = if next_is_paste {
                    args[idx].clone()
                } else {
                    self.expand(args[idx].clone())?
                };
                last_was_empty_arg = toks.is_empty();
                let first = out.len();
                // Argument tokens keep their own (real) positions.
                out.extend(toks.into_iter().map(|mut r| {
                    r.bol = false;
                    r
                }));
                if let Some(f) = out.get_mut(first) {
                    f.space = t.space;
                }
                k += 1;
                continue;
            }
            let mut c = t.clone();
            c.pos = at.pos;
            c.bol = false;
            c.hide = hide.clone();
            out.push(c);
            last_was_empty_arg = false;
            k += 1;
        }
        if let Some(f) = out.first_mut() {
            f.space = at.space;
            f.bol = at.bol;
        }
        Ok(out)
    }
}
