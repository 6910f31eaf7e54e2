//! RT006 `payload-member-unused`: a payload member that no shader of the
//! pipeline reads, or that none writes.

use crate::analysis::callgraph::EdgeKind;
use crate::analysis::layout::{self, Shape};
use crate::analysis::payload_use::{self, Access};
use crate::diag::Diagnostic;
use crate::program::{Decl, Id, SiteKind};
use crate::shader::Stage;
use spirv::StorageClass;

/// `SkipClosestHitShaderKHR`.
const SKIP_CLOSEST_HIT: u64 = 0x8;

super::declare_rule! {
    /// ## What it does
    ///
    /// For each ray payload the pipeline traces, follows every member through the
    /// shaders that exchange it: the shaders that trace with it, and the
    /// closest-hit, any-hit and miss shaders its traces reach whose incoming
    /// payload has the same layout. It reports a member that no shader reads, or
    /// that no shader writes. Only the shaders the pipeline uses are modelled:
    /// those of the description, or, without one, the shaders of a folder under
    /// the assumption that every trace reaches every shader whose incoming
    /// payload matches its own. A payload is not
    /// judged when its traces reach no shader with its layout, or when they can
    /// run a closest-hit shader and none with its layout is in the pipeline (a
    /// folder whose hit shader did not compile). A shader the trace's SBT
    /// operands select that declares another layout is not reached, but its
    /// members that sit at the same offset with the same shape still count as
    /// read and written (a shadow payload that starts like the main one, handed
    /// to the main payload's any-hit shader, as public code does).
    ///
    /// A member is read where a load reaches it through an access chain from the
    /// payload variable, written where a store does. Loading or storing the whole
    /// payload reads or writes every member, except a plain copy to or from a
    /// local variable (an HLSL `inout` parameter, a local handed to `TraceRay`):
    /// the local then stands for the payload. Any use the analysis cannot follow
    /// counts as reading and writing, so a member is reported only when no
    /// instruction can touch it.
    ///
    /// This rule also covers "payload larger than the ray type needs" (the code
    /// RT007 was set aside for it): members nobody reads after the trace are
    /// exactly the members no shader reads.
    ///
    /// ## Why is this bad?
    ///
    /// Every byte of the payload is copied into and out of each shader the ray
    /// reaches, held in registers or spilled to the ray stack at every recursion
    /// level, and counts toward `maxPipelineRayPayloadSize`. A member that no
    /// shader reads is that cost for nothing; a member that no shader writes is
    /// read uninitialised, or is dead too.
    ///
    /// ## Example
    ///
    /// ```glsl
    /// struct Payload {
    ///     vec3 color;
    ///     float hitT;     // written by the closest hit, read by nobody
    /// };
    /// ```
    ///
    /// Use instead:
    ///
    /// ```glsl
    /// struct Payload {
    ///     vec3 color;
    /// };
    /// ```
    ///
    /// ## How to fix
    ///
    /// Remove the member, or read it where it was meant to be used. A member
    /// that only the tracing shader writes and reads belongs in a local variable.
    ///
    /// Fixtures: `fixtures/RT006/`.
    ///
    /// ## References
    ///
    /// - Vulkan specification, "Ray generation shaders" and the
    ///   `IncomingRayPayloadKHR` storage class.
    /// - DirectX Raytracing functional spec, "Payload access qualifiers" (the
    ///   same read/write bookkeeping, declared by hand).
    "RT006" "payload-member-unused" {
        group: Perf,
        summary: "payload member no shader reads, or none writes",
        kind: super::Kind::Pipeline(run),
        analysis: Full,
    }
}

/// One shader's view of a payload: the shader, its program and the variable.
#[derive(Clone, Copy, PartialEq, Eq)]
struct View {
    program: usize,
    entry: Id,
    var: Id,
}

/// The shaders that exchange one payload layout.
struct RayType {
    shape: Shape,
    callers: Vec<View>,
    callees: Vec<View>,
    /// Shaders its traces reach whose incoming payload has another layout:
    /// their members that sit at the same offset with the same shape count.
    aliases: Vec<View>,
    /// Trace sites: program and instruction.
    sites: Vec<(usize, usize)>,
    /// Some trace may run a closest-hit shader (its flags do not skip it).
    may_hit: bool,
    /// A closest-hit shader with this layout is reached.
    hit_reached: bool,
}

/// The fields of a payload type: each struct member (or the whole value)
/// with its offset under the scalar rule and its shape.
/// Each (program, type)'s [`fields`], shared by the layouts that ask.
type FieldsMemo = std::collections::HashMap<(usize, Id), std::rc::Rc<[(u64, Shape)]>>;

/// [`fields`] of type `ty` in program `k`, worked out once per type (as
/// [`uses_of`], for a folder's many layouts).
fn fields_of(
    memo: &mut FieldsMemo,
    pipeline: &crate::pipeline::Pipeline,
    k: usize,
    ty: Id,
) -> std::rc::Rc<[(u64, Shape)]> {
    memo.entry((k, ty))
        .or_insert_with(|| fields(&pipeline.programs[k], ty).into())
        .clone()
}

fn fields(program: &crate::program::Program, ty: Id) -> Vec<(u64, Shape)> {
    match (program.ty(ty), layout::layout_type(program, ty, "")) {
        (Some(crate::program::Type::Struct { members }), Some(l)) => members
            .iter()
            .zip(&l.members)
            .map(|(m, ml)| (ml.scalar_offset, Shape::from_type(program, *m)))
            .collect(),
        _ => vec![(0, Shape::from_type(program, ty))],
    }
}

/// How `v` uses each member of its variable, asked once per view: in a
/// folder's loose pipeline the same shader is a caller, callee or alias of
/// many payload layouts.
fn uses_of<'m>(
    memo: &'m mut std::collections::HashMap<(usize, Id, Id), Vec<Access>>,
    pipeline: &crate::pipeline::Pipeline,
    v: &View,
) -> &'m [Access] {
    memo.entry((v.program, v.entry, v.var)).or_insert_with(|| {
        payload_use::variable_use(&pipeline.programs[v.program], v.entry, v.var)
    })
}

/// Per-field uses (`uses`, from [`uses_of`]) as a variable of type `ty`
/// sees them: struct members, or the whole.
fn field_uses(program: &crate::program::Program, uses: &[Access], ty: Id) -> Vec<Access> {
    if matches!(program.ty(ty), Some(crate::program::Type::Struct { .. })) {
        uses.to_vec()
    } else {
        let mut whole = Access::default();
        for &u in uses {
            whole.merge(u);
        }
        vec![whole]
    }
}

fn var_type(program: &crate::program::Program, var: Id) -> Option<Id> {
    program.globals.iter().find(|g| g.id == var).map(|g| g.ty)
}

fn run(ctx: &super::PipelineContext) -> Vec<Diagnostic> {
    let pipeline = ctx.pipeline;
    let graph = &ctx.recursion.graph;
    let mut types: Vec<RayType> = Vec::new();
    // Shaders the SBT selects whose payload differs count as aliases (code
    // that reads a shared prefix of two payloads).
    for e in graph
        .edges
        .iter()
        .chain(&graph.mismatched)
        .filter(|e| e.kind == EdgeKind::Trace)
    {
        let Some(program) = pipeline.programs.get(e.program) else {
            continue;
        };
        let Some(site) = program
            .sites
            .iter()
            .find(|s| s.inst == e.inst && s.kind == SiteKind::TraceRay)
        else {
            continue;
        };
        let Some(var) = site.payload else { continue };
        if !program
            .globals
            .iter()
            .any(|g| g.id == var && g.storage == StorageClass::RayPayloadKHR)
        {
            continue;
        }
        // The traced payload's shape as the reach analysis took it (sized).
        let Some(shape) = graph.payloads.traced_known(e.program, e.inst).cloned() else {
            continue;
        };
        let (Some(from), Some(to)) = (graph.nodes.get(e.from), graph.nodes.get(e.to)) else {
            continue;
        };
        let caller = View {
            program: e.program,
            entry: from.shader.function,
            var,
        };
        let i = match types.iter().position(|t| t.shape == shape) {
            Some(i) => i,
            None => {
                types.push(RayType {
                    shape: shape.clone(),
                    callers: Vec::new(),
                    callees: Vec::new(),
                    aliases: Vec::new(),
                    sites: Vec::new(),
                    may_hit: false,
                    hit_reached: false,
                });
                types.len() - 1
            }
        };
        let t = &mut types[i];
        if !t.callers.contains(&caller) {
            t.callers.push(caller);
        }
        if !t.sites.contains(&(e.program, e.inst)) {
            t.sites.push((e.program, e.inst));
        }
        let skips_hit = site
            .trace
            .and_then(|o| o.ray_flags.constant())
            .is_some_and(|f| f & SKIP_CLOSEST_HIT != 0);
        t.may_hit |= !skips_hit;
        if !matches!(
            to.shader.stage,
            Stage::ClosestHit | Stage::AnyHit | Stage::Miss
        ) {
            continue;
        }
        for w in graph
            .payloads
            .incoming_known(to.shader.program, to.shader.function)
        {
            let callee = View {
                program: to.shader.program,
                entry: to.shader.function,
                var: w.var,
            };
            let list = if w.shape == t.shape {
                t.hit_reached |= to.shader.stage == Stage::ClosestHit;
                &mut t.callees
            } else {
                &mut t.aliases
            };
            if !list.contains(&callee) {
                list.push(callee);
            }
        }
    }
    let mut var_uses = std::collections::HashMap::new();
    let mut type_fields = std::collections::HashMap::new();
    let mut out = Vec::new();
    for t in &types {
        // Not judged: no shader with this layout is reached, or the traces
        // can run a closest-hit shader and none with this layout is there
        // (a pipeline missing its hit shader, such as one that failed to
        // compile).
        if t.callees.is_empty() || (t.may_hit && !t.hit_reached) {
            continue;
        }
        let first = t.callers[0];
        let program = &pipeline.programs[first.program];
        let Some(ty) = program
            .globals
            .iter()
            .find(|g| g.id == first.var)
            .map(|g| g.ty)
        else {
            continue;
        };
        let n = payload_use::member_count(program, ty);
        let mut uses = vec![Access::default(); n];
        for v in t.callers.iter().chain(t.callees.iter()) {
            for (k, &a) in uses_of(&mut var_uses, pipeline, v).iter().enumerate() {
                if let Some(u) = uses.get_mut(k) {
                    u.merge(a);
                }
            }
        }
        // Shaders declaring another layout read and write the members that
        // sit where theirs do (a shadow payload that starts like the main
        // one, handed to the same any-hit shader).
        let own = fields_of(&mut type_fields, pipeline, first.program, ty);
        let is_struct_ty = matches!(program.ty(ty), Some(crate::program::Type::Struct { .. }));
        for v in &t.aliases {
            let p = &pipeline.programs[v.program];
            let Some(wty) = var_type(p, v.var) else {
                continue;
            };
            let theirs = fields_of(&mut type_fields, pipeline, v.program, wty);
            let theirs_uses = uses_of(&mut var_uses, pipeline, v);
            for (j, a) in field_uses(p, theirs_uses, wty).into_iter().enumerate() {
                let Some(f) = theirs.get(j) else { continue };
                if let Some(k) = own.iter().position(|o| *o == *f) {
                    if is_struct_ty {
                        if let Some(u) = uses.get_mut(k) {
                            u.merge(a);
                        }
                    } else {
                        for u in uses.iter_mut() {
                            u.merge(a);
                        }
                    }
                }
            }
        }
        let Some(layout) = layout::layout_type(program, ty, &program.display_name(first.var))
        else {
            continue;
        };
        let is_struct = layout.is_struct;
        // Vector components and array elements are judged as a whole.
        if !is_struct {
            let mut whole = Access::default();
            for u in &uses {
                whole.merge(*u);
            }
            uses = vec![whole];
        }
        if uses.iter().all(|u| u.read && u.written) {
            continue;
        }
        let unused: u64 = uses
            .iter()
            .enumerate()
            .filter(|(_, u)| !(u.read && u.written))
            .map(|(k, _)| layout.members.get(k).map_or(0, |m| m.size))
            .sum();
        let site = t
            .sites
            .first()
            .and_then(|&(p, i)| pipeline.programs[p].site_location(i));
        let plural = |n: usize, one: &str, many: &str| {
            format!("{n} {}", if n == 1 { one } else { many })
        };
        let stages = format!(
            "exchanged by {} and {} (closest-hit, any-hit, miss)",
            plural(t.callers.len(), "tracing shader", "tracing shaders"),
            plural(t.callees.len() + t.aliases.len(), "shader it reaches", "shaders it reaches"),
        );
        for (k, u) in uses.iter().enumerate() {
            if u.read && u.written {
                continue;
            }
            let (what, label) = match (u.read, u.written) {
                (false, true) => ("is written but no shader reads it", "read by no shader"),
                (true, false) => ("is read but no shader writes it", "written by no shader"),
                _ => ("is neither read nor written by any shader", "used by no shader"),
            };
            let member = if is_struct {
                format!(
                    "member `{}` of ray payload `{}`",
                    layout.members.get(k).map_or("?", |m| m.name.as_str()),
                    layout.name
                )
            } else {
                format!("ray payload `{}`", layout.name)
            };
            let at = if is_struct {
                program.decl_location(Decl::Member(ty, k as u32))
            } else {
                program.var_location(first.var)
            };
            let help = match (u.read, u.written) {
                (true, false) => "write the member before it is read, or remove it",
                _ => "remove the member from the payload",
            };
            let mut d = Diagnostic::new(
                LEVEL,
                NAME,
                &program.path,
                format!("{member} {what}"),
            )
            .with_code(CODE)
            .with_subject(member.clone())
            .with_primary(at.or_else(|| site.clone()), label)
            .with_secondary(site.clone(), "traced here")
            .with_note(stages.clone());
            if is_struct && unused > 0 && unused < layout.scalar_size {
                d = d.with_note(format!(
                    "the payload is {} bytes; without its unused members it needs {}",
                    layout.scalar_size,
                    layout.scalar_size - unused
                ));
            }
            out.push(d.with_help(help));
        }
    }
    out
}
