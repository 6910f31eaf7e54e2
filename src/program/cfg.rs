//! Control-flow utilities over a Program's functions: dominators, natural
//! loops, strongly connected components and call chains. Analyses share them.

use super::{Function, Id, Program};
use std::collections::{HashMap, HashSet};

/// Immediate dominators by block index (Cooper, Harvey, Kennedy).
pub fn dominators(f: &Function) -> Vec<Option<usize>> {
    let n = f.blocks.len();
    if n == 0 {
        return Vec::new();
    }
    // Post-order by an explicit stack: shader CFGs can be large.
    let mut order = Vec::new();
    let mut seen = vec![false; n];
    let mut stack = vec![(0usize, 0usize)];
    seen[0] = true;
    while let Some((b, k)) = stack.pop() {
        match f.blocks[b].succs.get(k) {
            Some(&s) => {
                stack.push((b, k + 1));
                if !seen[s] {
                    seen[s] = true;
                    stack.push((s, 0));
                }
            }
            None => order.push(b),
        }
    }
    order.reverse();
    let mut rpo = vec![usize::MAX; n];
    for (i, &b) in order.iter().enumerate() {
        rpo[b] = i;
    }
    let mut preds = vec![Vec::new(); n];
    for (b, block) in f.blocks.iter().enumerate() {
        for &s in &block.succs {
            preds[s].push(b);
        }
    }
    let mut idom: Vec<Option<usize>> = vec![None; n];
    idom[0] = Some(0);
    let mut changed = true;
    while changed {
        changed = false;
        for &b in order.iter().skip(1) {
            let mut new: Option<usize> = None;
            for &p in &preds[b] {
                if idom[p].is_none() {
                    continue;
                }
                new = Some(match new {
                    None => p,
                    Some(mut x) => {
                        let mut y = p;
                        while x != y {
                            while rpo[x] > rpo[y] {
                                x = idom[x].unwrap_or(0);
                            }
                            while rpo[y] > rpo[x] {
                                y = idom[y].unwrap_or(0);
                            }
                        }
                        x
                    }
                });
            }
            if new.is_some() && idom[b] != new {
                idom[b] = new;
                changed = true;
            }
        }
    }
    idom
}

/// Whether block `a` dominates block `b`.
pub fn dominates(idom: &[Option<usize>], a: usize, mut b: usize) -> bool {
    for _ in 0..=idom.len() {
        if a == b {
            return true;
        }
        match idom.get(b).copied().flatten() {
            Some(p) if p != b => b = p,
            _ => return false,
        }
    }
    false
}

/// Natural loops of a function: header block and body blocks, one per back
/// edge target, by header.
pub fn natural_loops(f: &Function) -> Vec<(usize, HashSet<usize>)> {
    let idom = dominators(f);
    let mut preds = vec![Vec::new(); f.blocks.len()];
    for (b, block) in f.blocks.iter().enumerate() {
        for &s in &block.succs {
            preds[s].push(b);
        }
    }
    let mut loops: HashMap<usize, HashSet<usize>> = HashMap::new();
    for (b, block) in f.blocks.iter().enumerate() {
        for &h in &block.succs {
            if !dominates(&idom, h, b) {
                continue;
            }
            let body = loops.entry(h).or_insert_with(|| HashSet::from([h]));
            let mut work = vec![b];
            while let Some(x) = work.pop() {
                if body.insert(x) {
                    work.extend(preds[x].iter().copied());
                }
            }
        }
    }
    let mut v: Vec<_> = loops.into_iter().collect();
    v.sort_by_key(|(h, _)| *h);
    v
}

/// Strongly connected components, sinks first.
pub fn strongly_connected(adj: &[Vec<usize>]) -> Vec<Vec<usize>> {
    struct T<'a> {
        adj: &'a [Vec<usize>],
        index: Vec<Option<usize>>,
        low: Vec<usize>,
        on: Vec<bool>,
        stack: Vec<usize>,
        next: usize,
        out: Vec<Vec<usize>>,
    }
    impl T<'_> {
        fn visit(&mut self, v: usize) {
            self.index[v] = Some(self.next);
            self.low[v] = self.next;
            self.next += 1;
            self.stack.push(v);
            self.on[v] = true;
            for &w in &self.adj[v] {
                match self.index[w] {
                    None => {
                        self.visit(w);
                        self.low[v] = self.low[v].min(self.low[w]);
                    }
                    Some(i) if self.on[w] => self.low[v] = self.low[v].min(i),
                    _ => {}
                }
            }
            if Some(self.low[v]) == self.index[v] {
                let mut c = Vec::new();
                while let Some(w) = self.stack.pop() {
                    self.on[w] = false;
                    c.push(w);
                    if w == v {
                        break;
                    }
                }
                c.sort_unstable();
                self.out.push(c);
            }
        }
    }
    let n = adj.len();
    let mut t = T {
        adj,
        index: vec![None; n],
        low: vec![0; n],
        on: vec![false; n],
        stack: Vec::new(),
        next: 0,
        out: Vec::new(),
    };
    for v in 0..n {
        if t.index[v].is_none() {
            t.visit(v);
        }
    }
    t.out
}

/// Every chain of `OpFunctionCall` instructions (outermost first) from
/// function `root` to function `target`; `[[]]` when they are the same.
///
/// At most `max` chains are returned (call graphs can have exponentially many).
pub fn call_chains(program: &Program, root: Id, target: Id, max: usize) -> Vec<Vec<usize>> {
    #[allow(clippy::too_many_arguments)]
    fn up(
        program: &Program,
        max: usize,
        root: Id,
        f: Id,
        suffix: &mut Vec<usize>,
        out: &mut Vec<Vec<usize>>,
        visiting: &mut Vec<Id>,
    ) {
        if out.len() >= max {
            return;
        }
        if f == root {
            out.push(suffix.iter().rev().copied().collect());
            return;
        }
        if visiting.contains(&f) {
            return;
        }
        visiting.push(f);
        for call in program.callers(f) {
            let Some(caller) = program
                .function_of(call)
                .and_then(|i| program.functions.get(i))
            else {
                continue;
            };
            suffix.push(call);
            up(program, max, root, caller.id, suffix, out, visiting);
            suffix.pop();
        }
        visiting.pop();
    }
    let mut out = Vec::new();
    up(
        program,
        max,
        root,
        target,
        &mut Vec::new(),
        &mut out,
        &mut Vec::new(),
    );
    out
}
