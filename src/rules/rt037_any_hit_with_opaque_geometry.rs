use super::PipelineContext;
use crate::analysis::callgraph::{EdgeKind, Slot};
use crate::analysis::rays::{self, flags};
use crate::diag::Diagnostic;
use crate::shader::Stage;

super::declare_rule! {
    /// ## What it does
    ///
    /// Finds any-hit shaders that can never run: in a pipeline whose description
    /// says `all_geometry_opaque = true`, an any-hit shader that no trace
    /// reaches (only a trace with `NoOpaque`, or with flags not known at compile
    /// time, would run it); and traces with `Opaque` (`gl_RayFlagsOpaqueEXT`,
    /// `RAY_FLAG_FORCE_OPAQUE`) whose every reachable hit group has an any-hit
    /// shader, so the ray ignores them all.
    ///
    /// ## Why is this bad?
    ///
    /// An any-hit shader usually implements alpha testing or transparency. When
    /// the geometry or the ray is opaque the shader is skipped, so cut-out
    /// foliage casts solid shadows or is hit where it should be transparent; or
    /// the shader is dead code compiled into every pipeline.
    ///
    /// ## Example
    ///
    /// ```toml
    /// all_geometry_opaque = true
    /// [[hit_group]]
    /// closest_hit = { file = "shade.rchit.spv" }
    /// any_hit = { file = "alpha.rahit.spv" }
    /// ```
    ///
    /// Use instead: build the alpha-tested geometry without
    /// `VK_GEOMETRY_OPAQUE_BIT_KHR` (or trace it with `NoOpaque`), or drop the
    /// any-hit shader.
    ///
    /// ## How to fix
    ///
    /// Make the geometry that needs the any-hit shader non-opaque and drop
    /// `Opaque` from traces that should run it, or remove the any-hit shader.
    "RT037" "any-hit-with-opaque-geometry" {
        group: Suspicious,
        summary: "any-hit shader that opaque geometry or opaque rays never run",
        kind: super::Kind::Pipeline(check),
        analysis: Full,
    }
}

fn check(ctx: &PipelineContext) -> Vec<Diagnostic> {
    let p = ctx.pipeline;
    let g = &ctx.recursion.graph;
    let mut out: Vec<Diagnostic> = Vec::new();
    let mut reported = super::Reported::default();
    if p.described() && p.all_geometry_opaque {
        for (n, node) in g.nodes.iter().enumerate() {
            if node.shader.stage != Stage::AnyHit {
                continue;
            }
            if g.edges.iter().any(|e| e.kind == EdgeKind::Trace && e.to == n) {
                continue;
            }
            let Slot::HitGroup(gi) = node.slot else { continue };
            let location = p
                .hit_groups
                .get(gi)
                .and_then(|h| h.any_hit.as_ref())
                .and_then(|s| s.location.clone());
            out.push(
                Diagnostic::new(
                    LEVEL,
                    NAME,
                    &p.file(),
                    format!(
                        "any-hit shader `{}` of hit group {gi} never runs: all geometry is opaque",
                        node.shader.entry
                    ),
                )
                .with_code(CODE)
                .with_primary(location, "any-hit shader of opaque geometry")
                .with_note("the description sets `all_geometry_opaque` and no trace sets `NoOpaque`")
                .with_help("build the geometry that needs this shader without the opaque flag, or remove the shader"),
            );
        }
    }
    for t in rays::trace_targets(g) {
        let Some(f) = rays::trace_flags(p, g, &t) else {
            continue;
        };
        if f & flags::OPAQUE == 0 {
            continue;
        }
        let groups = rays::reached_groups(g, &t);
        let all_any_hit = !groups.is_empty()
            && groups
                .iter()
                .all(|&gi| p.hit_groups.get(gi).is_some_and(|h| h.any_hit.is_some()));
        if !all_any_hit {
            continue;
        }
        let Some(program) = p.programs.get(t.program) else {
            continue;
        };
        let list = groups
            .iter()
            .map(|g| g.to_string())
            .collect::<Vec<_>>()
            .join(", ");
        let d = Diagnostic::new(
            LEVEL,
            NAME,
            &program.path,
            "opaque trace reaches only hit groups with any-hit shaders",
        )
        .with_code(CODE)
        .with_primary(t.location.clone(), "`Opaque` ray flag")
        .with_note(format!("hit groups it can reach: {list}; their any-hit shaders never run for this ray"))
        .with_help("drop the `Opaque` flag if the any-hit shaders must run for this ray");
        if reported.first(t.program, t.inst, &t.location) {
            out.push(d);
        }
    }
    out
}
