//! The trace graph of a pipeline: which shader each trace or callable site
//! can invoke.
//!
//! A trace selects its hit group by `instanceOffset + sbtOffset +
//! sbtStride × geometryIndex` and its miss shader by `missIndex`. When a
//! description gives the instances and the operands are constants, the
//! targets are resolved exactly; otherwise every group (or miss shader) is a
//! target and the graph says so. Constant ray flags prune targets: skipping
//! closest-hit shaders, opaque rays (no any-hit), culled triangles or AABBs.

use super::reach::{admit, Admit, Ambiguity, Payloads};
use crate::diag::Location;
pub use crate::pipeline::Slot;
use crate::pipeline::{HitGroupKind, Pipeline, ShaderRef};
use crate::program::{OperandValue, SiteKind};
use crate::shader::Stage;

/// `SkipClosestHitShaderKHR` and the flags that remove any-hit or geometry.
const FLAG_OPAQUE: u64 = 0x1;
const FLAG_NO_OPAQUE: u64 = 0x2;
const FLAG_SKIP_CLOSEST_HIT: u64 = 0x8;
const FLAG_SKIP_TRIANGLES: u64 = 0x100;
const FLAG_SKIP_AABBS: u64 = 0x200;

/// Something the analysis had to assume, said in the report.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Assumption {
    /// No pipeline description: every trace may reach every hit group and
    /// miss shader.
    Undescribed,
    /// The pipeline comes from an HLSL library's DXR subobjects, which do
    /// not give the shader table's order: every trace may reach every hit
    /// group and miss shader they declare.
    FromSubobjects,
    /// A trace whose SBT offset or stride is not a compile-time constant may
    /// reach every hit group.
    DynamicSbtOffset { at: Option<Location> },
    /// A trace whose miss index is not a compile-time constant may reach
    /// every miss shader.
    DynamicMissIndex { at: Option<Location> },
    /// No declared depth: the default formulas use the required depth only.
    NoDeclaredDepth,
    /// Recursion with no bound known at compile time, and why.
    UnboundedRecursion {
        why: super::recursion::NoGuard,
        /// The trace that closes the cycle without a bound.
        at: Option<Location>,
    },
    /// A depth counter with no constant initial value: 0 was assumed.
    InitialValueAssumed { counter: String },
    /// A trace or callable taken to reach a shader whose incoming payload
    /// could not be compared with its own.
    PayloadUnmatched {
        at: Option<Location>,
        why: super::reach::Ambiguity,
    },
    /// The driver's numbers come from this device.
    Driver { device: String, driver: String },
    /// The recommended stack was below what the driver's own numbers need
    /// and was raised to it.
    RecommendationRaised { from: u64, to: u64 },
}

impl Assumption {
    /// The order reports list them in: undescribed pipelines first, then
    /// traces by position.
    fn sort_key(&self) -> (u8, bool, String, u8) {
        match self {
            Assumption::Undescribed | Assumption::FromSubobjects => (0, false, String::new(), 0),
            Assumption::DynamicSbtOffset { at } => (
                1,
                at.is_none(),
                at.as_ref().map(|l| l.to_string()).unwrap_or_default(),
                0,
            ),
            Assumption::DynamicMissIndex { at } => (
                1,
                at.is_none(),
                at.as_ref().map(|l| l.to_string()).unwrap_or_default(),
                1,
            ),
            Assumption::PayloadUnmatched { at, .. } => (
                1,
                at.is_none(),
                at.as_ref().map(|l| l.to_string()).unwrap_or_default(),
                2,
            ),
            _ => (2, false, String::new(), 0),
        }
    }
}

/// A trace that selects a hit group or miss shader the pipeline lacks.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum OutOfRange {
    HitGroup { index: u64, count: usize },
    Miss { index: u64, count: usize },
}

#[derive(Clone, Debug)]
pub struct Node {
    pub shader: ShaderRef,
    pub slot: Slot,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EdgeKind {
    Trace,
    Callable,
}

#[derive(Clone, Debug)]
pub struct Edge {
    pub from: usize,
    pub to: usize,
    pub kind: EdgeKind,
    /// The site: index of the program and of the instruction.
    pub program: usize,
    pub inst: usize,
    pub location: Option<Location>,
    /// Kept only so that the trace's level counts: no miss shader given
    /// takes the trace's payload, this one included. Rules that judge what
    /// the reached shaders do leave it out.
    pub fallback: bool,
}

#[derive(Clone, Debug, Default)]
pub struct TraceGraph {
    pub nodes: Vec<Node>,
    pub edges: Vec<Edge>,
    /// What the graph had to assume (unresolved SBT operands, no description).
    pub assumptions: Vec<Assumption>,
    /// Sites selecting a group or miss shader the pipeline does not have.
    pub out_of_range: Vec<(Option<Location>, OutOfRange)>,
    /// The traced and incoming payloads reach was decided by.
    pub payloads: Payloads,
    /// Sites and the shaders their SBT operands and flags select but whose
    /// incoming payload differs from theirs: not reached (the languages
    /// require the same type), kept for rules about mismatched payloads and
    /// for code that reads a shared prefix of two payloads.
    pub mismatched: Vec<Edge>,
}

impl TraceGraph {
    pub fn edges_from(&self, n: usize) -> impl Iterator<Item = &Edge> {
        self.edges.iter().filter(move |e| e.from == n)
    }

    pub fn traces(&self) -> impl Iterator<Item = &Edge> {
        self.edges.iter().filter(|e| e.kind == EdgeKind::Trace)
    }
}

/// Builds the trace graph of a pipeline.
pub fn trace_graph(pipeline: &Pipeline) -> TraceGraph {
    let mut g = TraceGraph::default();
    g.nodes.reserve(pipeline.shaders().count());
    for (i, s) in pipeline.raygen.iter().enumerate() {
        g.nodes.push(Node {
            shader: s.clone(),
            slot: Slot::Raygen(i),
        });
    }
    for (i, s) in pipeline.miss.iter().enumerate() {
        g.nodes.push(Node {
            shader: s.clone(),
            slot: Slot::Miss(i),
        });
    }
    for (i, group) in pipeline.hit_groups.iter().enumerate() {
        for s in group.shaders() {
            g.nodes.push(Node {
                shader: s.clone(),
                slot: Slot::HitGroup(i),
            });
        }
    }
    for (i, s) in pipeline.callable.iter().enumerate() {
        g.nodes.push(Node {
            shader: s.clone(),
            slot: Slot::Callable(i),
        });
    }
    if pipeline.subobject_library.is_some() {
        g.assumptions.push(Assumption::FromSubobjects);
    } else if !pipeline.described() {
        g.assumptions.push(Assumption::Undescribed);
    }
    let described = pipeline.described();
    let mut payloads = Payloads::default();
    for from in 0..g.nodes.len() {
        let (program_index, entry_function) = {
            let s = &g.nodes[from].shader;
            (s.program, s.function)
        };
        let Some(program) = pipeline.programs.get(program_index) else {
            continue;
        };
        let reach = program.reached_functions(entry_function);
        for site in &program.sites {
            let Some(f) = program.functions.get(site.function) else {
                continue;
            };
            if !reach[site.function] {
                continue;
            }
            let kind = match site.kind {
                SiteKind::TraceRay => EdgeKind::Trace,
                SiteKind::ExecuteCallable => EdgeKind::Callable,
                _ => continue,
            };
            // A site in a helper (naga wraps every `traceRay` in one per
            // payload, called from several shaders) is placed and its
            // operands folded at this shader's call; one in the shader's
            // own function has the empty chain (as `call_chains` gives it,
            // without a vector for it).
            static OWN: [Vec<usize>; 1] = [Vec::new()];
            let helper;
            let chains: &[Vec<usize>] = if f.id == entry_function {
                &OWN
            } else {
                helper = crate::program::cfg::call_chains(
                    program,
                    entry_function,
                    f.id,
                    super::liveness::MAX_CHAINS,
                );
                &helper
            };
            let chain: &[usize] = chains.first().map_or(&[], Vec::as_slice);
            let location = program
                .location_in(site.inst, chain)
                .or_else(|| program.site_location(site.inst));
            let mut targets: Vec<usize> = Vec::new();
            // Selected by the SBT but not taking this payload.
            let mut mismatched: Vec<usize> = Vec::new();
            let mut fallback: Vec<usize> = Vec::new();
            // Operands the shader's calls agree on; else as the site has them.
            let mut per_chain = chains.iter().map(|c| program.trace_operands_in(site, c));
            let operands = match per_chain.next() {
                Some(first) if per_chain.all(|o| o == first) => first.or(site.trace),
                _ => site.trace,
            };
            if let (EdgeKind::Trace, Some(t)) = (kind, operands) {
                let flags = t.ray_flags.constant().unwrap_or(0);
                let dynamic_flags = t.ray_flags.constant().is_none();
                // Flags that are set whatever the dynamic part holds
                // (`SKIP_CLOSEST_HIT | extraFlags`) prune as constants do.
                let set = match t.ray_flags {
                    OperandValue::Const(v) => v,
                    // Set on every call chain that reaches the site.
                    OperandValue::Dynamic(id) if chains.is_empty() => {
                        program.known_ones_in(id, &[])
                    }
                    OperandValue::Dynamic(id) => chains
                        .iter()
                        .map(|c| program.known_ones_in(id, c))
                        .fold(u64::MAX, |a, b| a & b),
                    OperandValue::Spec { .. } => 0,
                };
                let opaque = set & FLAG_OPAQUE != 0
                    || (!dynamic_flags
                        && pipeline.all_geometry_opaque
                        && flags & FLAG_NO_OPAQUE == 0);
                let skip_ch = set & FLAG_SKIP_CLOSEST_HIT != 0;
                let skip_tri = set & FLAG_SKIP_TRIANGLES != 0;
                let skip_aabb = set & FLAG_SKIP_AABBS != 0;
                // The groups reached (`None`: all of them).
                let groups: Option<Vec<usize>> =
                    match (described, const_of(t.sbt_offset), const_of(t.sbt_stride)) {
                        (true, Some(off), Some(stride)) => {
                            let mut v = Vec::new();
                            for &inst in &pipeline.instance_sbt_offsets {
                                for geo in 0..u64::from(pipeline.geometries_per_instance) {
                                    let idx = u64::from(inst) + off + stride * geo;
                                    if (idx as usize) < pipeline.hit_groups.len() {
                                        if !v.contains(&(idx as usize)) {
                                            v.push(idx as usize);
                                        }
                                    } else {
                                        g.out_of_range.push((
                                            location.clone(),
                                            OutOfRange::HitGroup {
                                                index: idx,
                                                count: pipeline.hit_groups.len(),
                                            },
                                        ));
                                    }
                                }
                            }
                            Some(v)
                        }
                        (true, _, _) => {
                            g.assumptions.push(Assumption::DynamicSbtOffset {
                                at: location.clone(),
                            });
                            None
                        }
                        _ => None,
                    };
                for (n, node) in g.nodes.iter().enumerate() {
                    let Slot::HitGroup(gi) = node.slot else {
                        continue;
                    };
                    let reached = match &groups {
                        Some(v) => v.contains(&gi),
                        None => gi < pipeline.hit_groups.len(),
                    };
                    if !reached {
                        continue;
                    }
                    let group_kind = pipeline.hit_groups.get(gi).map(|h| h.kind);
                    let culled = match group_kind {
                        Some(HitGroupKind::Triangles) => skip_tri,
                        Some(HitGroupKind::Procedural) => skip_aabb,
                        None => true,
                    };
                    let wanted = match node.shader.stage {
                        Stage::ClosestHit => !skip_ch,
                        Stage::AnyHit => !opaque,
                        _ => true,
                    };
                    if wanted && !culled {
                        targets.push(n);
                    }
                }
                // Of those, the groups whose shaders take this payload.
                let traced = payloads.traced(&pipeline.programs, program_index, site.inst);
                let mut admitted: Vec<(usize, Admit)> = Vec::new();
                targets.retain(|&n| {
                    let Slot::HitGroup(gi) = g.nodes[n].slot else {
                        return true;
                    };
                    let a = match admitted.iter().find(|(k, _)| *k == gi) {
                        Some(&(_, a)) => a,
                        None => {
                            let a = group_admits(pipeline, &mut payloads, gi, &traced);
                            admitted.push((gi, a));
                            a
                        }
                    };
                    if !a.reaches() {
                        mismatched.push(n);
                    }
                    a.reaches()
                });
                // Groups the description and constant SBT operands select
                // exactly run whatever their payload (a mismatch is RT009's
                // finding, undefined behaviour that real samples ship): the
                // level counts, on the safe side. Payload shape prunes only
                // where the selection is not known.
                if groups.is_some() {
                    fallback.extend_from_slice(&mismatched);
                    targets.append(&mut mismatched);
                }
                let mut why = admitted.iter().find_map(|(_, a)| match a {
                    Admit::Assumed(w) => Some(*w),
                    _ => None,
                });
                // The miss shader reached (`None`: all of them).
                let miss: Option<usize> = match (described, const_of(t.miss_index)) {
                    (true, Some(m)) => {
                        if (m as usize) >= pipeline.miss.len() {
                            g.out_of_range.push((
                                location.clone(),
                                OutOfRange::Miss {
                                    index: m,
                                    count: pipeline.miss.len(),
                                },
                            ));
                        }
                        Some(m as usize)
                    }
                    (true, None) => {
                        g.assumptions.push(Assumption::DynamicMissIndex {
                            at: location.clone(),
                        });
                        None
                    }
                    _ => None,
                };
                let mut refused = Vec::new();
                for (n, node) in g.nodes.iter().enumerate() {
                    let Slot::Miss(m) = node.slot else {
                        continue;
                    };
                    if !miss.map_or(m < pipeline.miss.len(), |x| x == m) {
                        continue;
                    }
                    let s = &node.shader;
                    match admit(
                        &traced,
                        payloads.incoming(&pipeline.programs, s.program, s.function, s.stage),
                    ) {
                        Admit::No => refused.push(n),
                        a => {
                            if let Admit::Assumed(w) = a {
                                why.get_or_insert(w);
                            }
                            targets.push(n);
                        }
                    }
                }
                // A trace runs a hit group or a miss shader; the trace itself
                // takes a recursion level whatever it runs. When no miss
                // shader given takes its payload, the one it runs is missing
                // (a folder without the shadow miss) or mismatched: keep the
                // candidates so the level counts, and say so.
                // The same for a miss shader the index selects exactly.
                let no_miss_takes = !targets
                    .iter()
                    .any(|&n| matches!(g.nodes[n].slot, Slot::Miss(_)));
                if !refused.is_empty() && (no_miss_takes || miss.is_some()) {
                    fallback.extend_from_slice(&refused);
                    targets.extend(refused);
                    if no_miss_takes {
                        why.get_or_insert(Ambiguity::NoMissTakesPayload);
                    }
                } else {
                    mismatched.extend(refused);
                }
                if let Some(why) = why {
                    g.assumptions.push(Assumption::PayloadUnmatched {
                        at: location.clone(),
                        why,
                    });
                }
            } else {
                let traced = payloads.traced(&pipeline.programs, program_index, site.inst);
                let mut why = None;
                // The callable reached (`None`: all of them).
                let callable: Option<usize> = match (
                    described,
                    site.sbt_index.as_ref().and_then(|o| const_of(*o)),
                ) {
                    (true, Some(c)) => Some(c as usize),
                    _ => None,
                };
                for (n, node) in g.nodes.iter().enumerate() {
                    let Slot::Callable(c) = node.slot else {
                        continue;
                    };
                    if !callable.map_or(c < pipeline.callable.len(), |x| x == c) {
                        continue;
                    }
                    let s = &node.shader;
                    match admit(
                        &traced,
                        payloads.incoming(&pipeline.programs, s.program, s.function, s.stage),
                    ) {
                        Admit::No => mismatched.push(n),
                        a => {
                            if let Admit::Assumed(w) = a {
                                why.get_or_insert(w);
                            }
                            targets.push(n);
                        }
                    }
                }
                if let Some(why) = why {
                    g.assumptions.push(Assumption::PayloadUnmatched {
                        at: location.clone(),
                        why,
                    });
                }
            }
            for to in targets {
                g.edges.push(Edge {
                    from,
                    to,
                    kind,
                    program: program_index,
                    inst: site.inst,
                    location: location.clone(),
                    fallback: fallback.contains(&to),
                });
            }
            for to in mismatched {
                g.mismatched.push(Edge {
                    from,
                    to,
                    kind,
                    program: program_index,
                    inst: site.inst,
                    location: location.clone(),
                    fallback: false,
                });
            }
        }
    }
    g.assumptions.sort_by_key(Assumption::sort_key);
    g.assumptions.dedup();
    g.payloads = payloads;
    g
}

/// Whether hit group `gi` takes payload `traced`: one of its closest-hit
/// and any-hit shaders declares a matching incoming payload, or none
/// declares one (an intersection shader alone takes no payload).
fn group_admits(
    pipeline: &Pipeline,
    payloads: &mut Payloads,
    gi: usize,
    traced: &Result<super::layout::Shape, super::reach::Ambiguity>,
) -> Admit {
    let Some(group) = pipeline.hit_groups.get(gi) else {
        return Admit::Yes;
    };
    let shaders = [&group.closest_hit, &group.any_hit];
    for s in shaders.into_iter().flatten() {
        payloads.incoming(&pipeline.programs, s.program, s.function, s.stage);
    }
    // Borrowed, not copied: a folder's loose pipeline asks once per trace
    // and group.
    let payloads = &*payloads;
    admit(
        traced,
        shaders
            .into_iter()
            .flatten()
            .flat_map(|s| payloads.incoming_known(s.program, s.function)),
    )
}

/// A constant operand; a specialization constant counts with its default.
fn const_of(o: OperandValue) -> Option<u64> {
    match o {
        OperandValue::Const(v) => Some(v),
        OperandValue::Spec { default, .. } => Some(default),
        OperandValue::Dynamic(_) => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipeline::load;
    use std::path::Path;

    fn pipeline(rel: &str) -> Pipeline {
        load(&Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)).unwrap()
    }

    fn edges(g: &TraceGraph) -> Vec<(String, String)> {
        let mut v: Vec<_> = g
            .edges
            .iter()
            .map(|e| {
                (
                    crate::explain::node(&g.nodes[e.from]),
                    crate::explain::node(&g.nodes[e.to]),
                )
            })
            .collect();
        v.sort();
        v
    }

    #[test]
    fn recursive_reflection_edges() {
        let g = trace_graph(&pipeline(
            "fixtures/pipelines/reflect_recursive.pipeline.toml",
        ));
        // The shadow ray skips closest-hit shaders and goes to miss 1; the
        // reflection ray reaches the group and miss 0.
        assert_eq!(
            edges(&g),
            [
                (
                    "closesthit `main` (hit group 0)",
                    "closesthit `main` (hit group 0)"
                ),
                ("closesthit `main` (hit group 0)", "miss `main` (miss 0)"),
                ("closesthit `main` (hit group 0)", "miss `main` (miss 1)"),
                (
                    "raygeneration `main` (raygen 0)",
                    "closesthit `main` (hit group 0)"
                ),
                ("raygeneration `main` (raygen 0)", "miss `main` (miss 0)"),
            ]
            .map(|(a, b)| (a.to_string(), b.to_string()))
        );
        assert!(g.assumptions.is_empty());
    }

    #[test]
    fn without_description_all_targets() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/pipelines/iterative");
        let programs = ["reflect.rgen.spv", "reflect.rchit.spv", "shadow.rmiss.spv"]
            .iter()
            .map(|f| crate::front::load(&dir.join(f), crate::shader::Language::Spirv).unwrap())
            .collect();
        let g = trace_graph(&Pipeline::from_programs(programs));
        // The shadow ray still skips the closest hit; the miss index is not
        // resolved without a description. The folder lacks the radiance
        // miss shader: the raygen's trace keeps the shadow miss as its
        // candidate (its level counts) and says so.
        assert_eq!(g.edges.len(), 3);
        assert_eq!(g.assumptions.len(), 2);
        assert!(matches!(
            g.assumptions[1],
            Assumption::PayloadUnmatched {
                why: crate::analysis::reach::Ambiguity::NoMissTakesPayload,
                ..
            }
        ));
    }

    /// With a description and constant SBT operands, a record that selects a
    /// shader taking another payload still runs it: the edge stays, marked
    /// as one that only counts the level (rules that judge what the shader
    /// does leave it out; RT009 reports the mismatch). Here the shadow
    /// trace's record (hit group 1), made a copy of the radiance group,
    /// selects a closest hit that takes another payload.
    #[test]
    fn description_edges_with_another_payload_count_the_level() {
        let mut p = pipeline("fixtures/reach/scene.pipeline.toml");
        p.hit_groups[1] = p.hit_groups[0].clone();
        let g = trace_graph(&p);
        let shadow_hit = |e: &Edge| {
            g.nodes[e.from].shader.stage == Stage::ClosestHit
                && g.nodes[e.to].shader.stage == Stage::ClosestHit
                && g.nodes[e.to].slot == Slot::HitGroup(1)
        };
        // Once from each of the two nodes of the closest hit (groups 0, 1),
        // and only as level-counting edges.
        let kept: Vec<&Edge> = g.edges.iter().filter(|e| shadow_hit(e)).collect();
        assert_eq!(kept.len(), 2, "{:?}", g.edges);
        assert!(kept.iter().all(|e| e.fallback), "{kept:?}");
        assert!(!g.mismatched.iter().any(shadow_hit), "{:?}", g.mismatched);
        // The reflection still reaches group 0 as a real edge, and nothing
        // had to be assumed.
        assert!(g.edges.iter().any(|e| !e.fallback
            && g.nodes[e.from].shader.stage == Stage::ClosestHit
            && g.nodes[e.to].slot == Slot::HitGroup(0)));
        assert!(g.assumptions.is_empty(), "{:?}", g.assumptions);
    }

    /// A callable reaches only the callables whose incoming data has its
    /// data's type; the other is selected by nothing (no edge, no
    /// assumption) and kept as a mismatched edge.
    #[test]
    fn callables_by_data_type() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/reach/callable");
        let programs = ["caller.rgen.spv", "sky.rcall.spv", "counter.rcall.spv"]
            .iter()
            .map(|f| crate::front::load(&dir.join(f), crate::shader::Language::Spirv).unwrap())
            .collect();
        let g = trace_graph(&Pipeline::from_programs(programs));
        let to: Vec<_> = g
            .edges
            .iter()
            .map(|e| g.nodes[e.to].shader.file.clone())
            .collect();
        assert_eq!(to, [dir.join("sky.rcall.spv")], "{:?}", g.edges);
        assert_eq!(g.mismatched.len(), 1);
        assert_eq!(
            g.nodes[g.mismatched[0].to].shader.file,
            dir.join("counter.rcall.spv")
        );
        assert_eq!(g.assumptions, [Assumption::Undescribed]);
    }

    #[test]
    fn instances_any_hit_and_opaque_geometry() {
        let mut p = pipeline("fixtures/pipelines/procedural.pipeline.toml");
        // Instance offsets 0 and 1 with stride 1 reach both groups; the ray
        // is not opaque, so the alpha test runs.
        let stages = |g: &TraceGraph| {
            let mut v: Vec<&str> = g
                .edges
                .iter()
                .map(|e| g.nodes[e.to].shader.stage.as_str())
                .collect();
            v.sort();
            v
        };
        let g = trace_graph(&p);
        assert_eq!(
            stages(&g),
            ["anyhit", "closesthit", "closesthit", "intersection", "miss"]
        );
        p.all_geometry_opaque = true;
        assert_eq!(
            stages(&trace_graph(&p)),
            ["closesthit", "closesthit", "intersection", "miss"]
        );
        p.instance_sbt_offsets = vec![0];
        assert_eq!(stages(&trace_graph(&p)), ["closesthit", "miss"]);
        p.instance_sbt_offsets = vec![5];
        let g = trace_graph(&p);
        assert_eq!(stages(&g), ["miss"]);
        assert_eq!(g.out_of_range.len(), 1);
    }
}
