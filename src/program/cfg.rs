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
    /// Per function, in one vector.
    cells: Vec<FunctionCfg>,
}

#[derive(Default)]
struct FunctionCfg {
    preds: OnceLock<Preds>,
    idom: OnceLock<Vec<Option<usize>>>,
    looped: OnceLock<Vec<bool>>,
}

/// The memo of [`FunctionCfgs`] of a program.
pub fn function_cfgs(program: &Program) -> Arc<FunctionCfgs> {
    program.memo.get_or(|| FunctionCfgs {
        cells: program
            .functions
            .iter()
            .map(|_| FunctionCfg::default())
            .collect(),
    })
}

impl FunctionCfgs {
    /// [`dominators`] of function `fi` (an index into `program.functions`).
    pub fn idom(&self, program: &Program, fi: usize) -> &[Option<usize>] {
        match (self.cells.get(fi), program.functions.get(fi)) {
            (Some(cell), Some(f)) => cell
                .idom
                .get_or_init(|| dominators_with(f, cell.preds.get_or_init(|| Preds::of(f)))),
            _ => &[],
        }
    }

    /// Per block of function `fi`: whether it lies in one of the function's
    /// [`natural_loops`] (their union, without building each body as a set).
    pub fn looped(&self, program: &Program, fi: usize) -> &[bool] {
        let (Some(cell), Some(f)) = (self.cells.get(fi), program.functions.get(fi)) else {
            return &[];
        };
        cell.looped.get_or_init(|| {
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
            let preds = cell.preds.get_or_init(|| Preds::of(f));
            // Each block's depth in the dominator tree: an edge is a back
            // edge when its target is its source's ancestor at the target's
            // depth, so the walk up stops there, and a target no shallower
            // than its source (every forward edge of structured code) needs
            // none. Unreachable blocks have no depth and dominate nothing.
            const NO_DEPTH: usize = usize::MAX;
            let mut depth = vec![NO_DEPTH; n];
            depth[0] = 0;
            let mut path = Vec::new();
            for b in 0..n {
                let mut x = b;
                while depth[x] == NO_DEPTH && path.len() <= n {
                    match idom[x] {
                        Some(p) if p != x => {
                            path.push(x);
                            x = p;
                        }
                        _ => break,
                    }
                }
                let mut d = depth[x];
                while let Some(y) = path.pop() {
                    d = d.saturating_add(1);
                    depth[y] = d;
                }
            }
            let dominates = |h: usize, b: usize| {
                if h == b {
                    return true;
                }
                let (dh, db) = (depth[h], depth[b]);
                if dh == NO_DEPTH || db == NO_DEPTH || dh >= db {
                    return false;
                }
                let mut x = b;
                for _ in dh..db {
                    x = idom[x].unwrap_or(x);
                }
                x == h
            };
            // Which back edge last visited a block: each loop's body is
            // walked on its own (a body already marked may lead further).
            let mut visit = vec![usize::MAX; n];
            let mut edge = 0;
            let mut work = Vec::new();
            for (b, block) in f.blocks.iter().enumerate() {
                for &h in &block.succs {
                    if !dominates(h, b) {
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
    let edges: Vec<(usize, usize)> = adj
        .iter()
        .enumerate()
        .flat_map(|(v, ws)| ws.iter().map(move |&w| (v, w)))
        .collect();
    let c = components(adj.len(), &edges);
    (0..c.len()).map(|k| c.get(k).to_vec()).collect()
}

/// [`strongly_connected`] over `(from, to)` edges sorted by `from` (each
/// node's edges in visiting order), in flat vectors: component `c` is
/// `members[start[c]..start[c + 1]]`, sorted, sinks first.
pub struct Components {
    pub members: Vec<usize>,
    pub start: Vec<usize>,
}

impl Components {
    pub fn len(&self) -> usize {
        self.start.len() - 1
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    pub fn get(&self, c: usize) -> &[usize] {
        &self.members[self.start[c]..self.start[c + 1]]
    }
}

/// Tarjan's components in the order [`strongly_connected`] gives them,
/// without a vector per node or per component.
pub fn components(n: usize, edges: &[(usize, usize)]) -> Components {
    const NONE: usize = usize::MAX;
    struct T<'a> {
        edges: &'a [(usize, usize)],
        /// Per node: its index, low link and whether it is on the stack.
        state: Vec<(usize, usize, bool)>,
        stack: Vec<usize>,
        next: usize,
        out: Components,
    }
    impl T<'_> {
        fn visit(&mut self, v: usize) {
            self.state[v] = (self.next, self.next, true);
            self.next += 1;
            self.stack.push(v);
            let from = self.edges.partition_point(|&(u, _)| u < v);
            let mut k = from;
            while let Some(&(u, w)) = self.edges.get(k) {
                if u != v {
                    break;
                }
                k += 1;
                let (index, _, on) = self.state[w];
                if index == NONE {
                    self.visit(w);
                    self.state[v].1 = self.state[v].1.min(self.state[w].1);
                } else if on {
                    self.state[v].1 = self.state[v].1.min(index);
                }
            }
            if self.state[v].1 == self.state[v].0 {
                let first = self.out.members.len();
                while let Some(w) = self.stack.pop() {
                    self.state[w].2 = false;
                    self.out.members.push(w);
                    if w == v {
                        break;
                    }
                }
                self.out.members[first..].sort_unstable();
                self.out.start.push(self.out.members.len());
            }
        }
    }
    let mut t = T {
        edges,
        state: vec![(NONE, 0, false); n],
        stack: Vec::new(),
        next: 0,
        out: Components {
            members: Vec::with_capacity(n),
            start: vec![0],
        },
    };
    for v in 0..n {
        if t.state[v].0 == NONE {
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

    /// Tarjan's components, sinks first, each sorted, in both forms.
    #[test]
    fn components_sinks_first() {
        let adj = vec![vec![1], vec![2], vec![1, 3], vec![], vec![4, 0]];
        let expected = vec![vec![3], vec![1, 2], vec![0], vec![4]];
        assert_eq!(strongly_connected(&adj), expected);
        let edges = [(0, 1), (1, 2), (2, 1), (2, 3), (4, 4), (4, 0)];
        let c = components(5, &edges);
        let got: Vec<Vec<usize>> = (0..c.len()).map(|k| c.get(k).to_vec()).collect();
        assert_eq!(got, expected);
    }

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
