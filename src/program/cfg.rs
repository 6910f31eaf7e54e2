//! Control-flow utilities over a Program's functions: dominators, natural
//! loops, strongly connected components and call chains. Analyses share them.

use super::{Function, Id, Program};
use std::collections::{HashMap, HashSet};
use std::sync::{Arc, OnceLock};

/// Each block's predecessors in block order, as one flat list: a `Vec`
/// per block cost an allocation each, and the analyses ask for many small
/// functions.
pub struct Preds {
    start: Vec<usize>,
    list: Vec<usize>,
}

impl Preds {
    pub fn of(f: &Function) -> Preds {
        let n = f.blocks.len();
        // A successor outside the function (which the builder refuses) is
        // no edge.
        fn succs(block: &crate::program::Block, n: usize) -> impl Iterator<Item = usize> + '_ {
            block.succs.iter().copied().filter(move |&s| s < n)
        }
        let mut start = vec![0usize; n + 1];
        for block in &f.blocks {
            for s in succs(block, n) {
                start[s + 1] += 1;
            }
        }
        for b in 0..n {
            start[b + 1] += start[b];
        }
        let mut list = vec![0usize; start[n]];
        let mut next = start.clone();
        for (b, block) in f.blocks.iter().enumerate() {
            for s in succs(block, n) {
                list[next[s]] = b;
                next[s] += 1;
            }
        }
        Preds { start, list }
    }

    /// The predecessors of block `b`.
    pub fn of_block(&self, b: usize) -> &[usize] {
        &self[b]
    }
}

impl std::ops::Index<usize> for Preds {
    type Output = [usize];
    #[inline]
    fn index(&self, b: usize) -> &[usize] {
        &self.list[self.start[b]..self.start[b + 1]]
    }
}

/// Immediate dominators by block index (Cooper, Harvey, Kennedy).
pub fn dominators(f: &Function) -> Vec<Option<usize>> {
    dominators_with(f, &Preds::of(f))
}

/// [`dominators`] with the function's predecessors already listed.
pub fn dominators_with(f: &Function, preds: &Preds) -> Vec<Option<usize>> {
    let n = f.blocks.len();
    if n == 0 {
        return Vec::new();
    }
    // Post-order by an explicit stack: shader CFGs can be large.
    let mut order = Vec::with_capacity(n);
    let mut seen = vec![false; n];
    let mut stack = Vec::with_capacity(n);
    stack.push((0usize, 0usize));
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
    let mut idom: Vec<Option<usize>> = vec![None; n];
    idom[0] = Some(0);
    let mut changed = true;
    while changed {
        changed = false;
        for &b in order.iter().skip(1) {
            let mut new: Option<usize> = None;
            for &p in preds.of_block(b) {
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
    let preds = Preds::of(f);
    let idom = dominators_with(f, &preds);
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
                    work.extend_from_slice(preds.of_block(x));
                }
            }
        }
    }
    let mut v: Vec<_> = loops.into_iter().collect();
    v.sort_by_key(|(h, _)| *h);
    v
}

/// Each function's dominator tree and which of its blocks lie in a loop,
/// worked out on first use and kept in the Program's memo: the stack model
/// asks per site and per entry point, the depth guards per trace, and a
/// helper shared by several shaders was analysed once per shader.
pub struct FunctionCfgs {
    preds: Vec<OnceLock<Preds>>,
    idom: Vec<OnceLock<Vec<Option<usize>>>>,
    looped: Vec<OnceLock<Vec<bool>>>,
}

/// The memo of [`FunctionCfgs`] of a program.
pub fn function_cfgs(program: &Program) -> Arc<FunctionCfgs> {
    program.memo.get_or(|| FunctionCfgs {
        preds: program.functions.iter().map(|_| OnceLock::new()).collect(),
        idom: program.functions.iter().map(|_| OnceLock::new()).collect(),
        looped: program.functions.iter().map(|_| OnceLock::new()).collect(),
    })
}

impl FunctionCfgs {
    /// [`dominators`] of function `fi` (an index into `program.functions`).
    pub fn idom(&self, program: &Program, fi: usize) -> &[Option<usize>] {
        match (self.idom.get(fi), program.functions.get(fi)) {
            (Some(cell), Some(f)) => {
                cell.get_or_init(|| dominators_with(f, self.preds[fi].get_or_init(|| Preds::of(f))))
            }
            _ => &[],
        }
    }

    /// Per block of function `fi`: whether it lies in one of the function's
    /// [`natural_loops`] (their union, without building each body as a set).
    pub fn looped(&self, program: &Program, fi: usize) -> &[bool] {
        let (Some(cell), Some(f)) = (self.looped.get(fi), program.functions.get(fi)) else {
            return &[];
        };
        cell.get_or_init(|| {
            let n = f.blocks.len();
            let mut looped = vec![false; n];
            // Every edge forward in block order: no cycle, so no back edge
            // (and no dominator tree needed to find none).
            if f.blocks
                .iter()
                .enumerate()
                .all(|(b, block)| block.succs.iter().all(|&s| s > b))
            {
                return looped;
            }
            let idom = self.idom(program, fi);
            let preds = self.preds[fi].get_or_init(|| Preds::of(f));
            // Which back edge last visited a block: each loop's body is
            // walked on its own (a body already marked may lead further).
            let mut visit = vec![usize::MAX; n];
            let mut edge = 0;
            let mut work = Vec::new();
            for (b, block) in f.blocks.iter().enumerate() {
                for &h in &block.succs {
                    if !dominates(idom, h, b) {
                        continue;
                    }
                    edge += 1;
                    looped[h] = true;
                    visit[h] = edge;
                    work.push(b);
                    while let Some(x) = work.pop() {
                        if visit[x] != edge {
                            visit[x] = edge;
                            looped[x] = true;
                            work.extend_from_slice(preds.of_block(x));
                        }
                    }
                }
            }
            looped
        })
    }
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
        calls: &super::CallIndex,
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
        // The index itself, not `Program::callers`' copy per step.
        for &(_, call) in calls.calls_to(f) {
            let Some(caller) = program
                .function_of(call)
                .and_then(|i| program.functions.get(i))
            else {
                continue;
            };
            suffix.push(call);
            up(program, calls, max, root, caller.id, suffix, out, visiting);
            suffix.pop();
        }
        visiting.pop();
    }
    let mut out = Vec::new();
    if target == root {
        // `[[]]` without the index.
        if max > 0 {
            out.push(Vec::new());
        }
        return out;
    }
    up(
        program,
        &program.call_index(),
        max,
        root,
        target,
        &mut Vec::new(),
        &mut out,
        &mut Vec::new(),
    );
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    /// The memo's dominators and loop blocks are `dominators` and the union
    /// of `natural_loops`, function by function: loops in GLSL, HLSL and
    /// WGSL output, helpers without one.
    #[test]
    fn memo_matches_dominators_and_natural_loops() {
        let mut loops = 0;
        for rel in [
            "fixtures/guards/loop.rgen.g.spv",
            "fixtures/guards/fresh.hlsl",
            "fixtures/guards/constructed.wgsl",
        ] {
            let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(rel);
            let lang = crate::shader::Language::from_path(&path).unwrap();
            let p = crate::front::load(&path, lang).unwrap();
            let cfgs = function_cfgs(&p);
            for (fi, f) in p.functions.iter().enumerate() {
                assert_eq!(cfgs.idom(&p, fi), dominators(f).as_slice(), "{rel} {fi}");
                let mut want = vec![false; f.blocks.len()];
                for (_, body) in natural_loops(f) {
                    loops += 1;
                    for b in body {
                        want[b] = true;
                    }
                }
                assert_eq!(cfgs.looped(&p, fi), want.as_slice(), "{rel} {fi}");
            }
        }
        assert!(loops >= 3, "{loops}");
    }
}
