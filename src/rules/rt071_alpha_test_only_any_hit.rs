//! RT071 `alpha-test-only-any-hit`: an any-hit shader whose only work is an
//! alpha test from a texture.

use super::Context;
use crate::analysis::payload_use;
use crate::diag::Diagnostic;
use crate::program::{Decl, SiteKind, Type};
use crate::shader::Stage;
use rspirv::dr::Operand;
use spirv::{Op, StorageClass};

super::declare_rule! {
    /// ## What it does
    ///
    /// Reports an any-hit shader that samples a texture and ignores the
    /// intersection (`ignoreIntersectionEXT`, `IgnoreHit`) and does nothing else
    /// that outlives it: it writes no payload member, no buffer or image, and
    /// traces no ray. That is an alpha test, and nothing more.
    ///
    /// This is advice (pedantic): whether the cut-out can be baked depends on the
    /// assets and on the target (opacity micromaps need
    /// `VK_EXT_opacity_micromap` or DXR 1.2).
    ///
    /// ## Why is this bad?
    ///
    /// Every candidate hit on non-opaque geometry leaves the traversal hardware,
    /// runs the shader, samples a texture and returns. An opacity micromap bakes
    /// the same mask into the acceleration structure, so the hardware resolves most
    /// candidates (fully opaque or fully transparent micro-triangles) itself and
    /// calls the any-hit shader only for the rest. Geometry with no cut-outs at all
    /// needs no any-hit shader: mark it opaque (`VK_GEOMETRY_OPAQUE_BIT_KHR`,
    /// `RAY_FLAG_FORCE_OPAQUE`).
    ///
    /// ## Example
    ///
    /// ```glsl
    /// void main() {
    ///     vec2 uv = interpolateUv(gl_PrimitiveID, attribs);
    ///     if (texture(alphaMap, uv).a < 0.5)
    ///         ignoreIntersectionEXT;
    /// }
    /// ```
    ///
    /// Use instead: an opacity micromap built from `alphaMap` on the geometry
    /// (the any-hit shader stays for the unknown micro-triangles), or opaque
    /// geometry where nothing is cut out.
    ///
    /// ## How to fix
    ///
    /// Bake the alpha mask into an opacity micromap where the target supports it;
    /// mark geometry without cut-outs opaque.
    ///
    /// Fixtures: `fixtures/RT071/`.
    ///
    /// ## References
    ///
    /// - Vulkan, `VK_EXT_opacity_micromap`.
    /// - Microsoft, DirectX Raytracing 1.2, "Opacity micromaps".
    "RT071" "alpha-test-only-any-hit" {
        group: Pedantic,
        summary: "any-hit shader whose only work is a texture alpha test",
        kind: super::Kind::Module(check),
        analysis: Full,
    }
}

fn check(ctx: &Context) -> Vec<Diagnostic> {
    let program = ctx.program;
    let mut out = Vec::new();
    for e in program
        .entry_points
        .iter()
        .filter(|e| e.stage == Stage::AnyHit)
    {
        let functions = program.reachable_functions(e.function);
        let ignores = program.sites.iter().any(|s| {
            s.kind == SiteKind::IgnoreIntersection
                && program
                    .functions
                    .get(s.function)
                    .is_some_and(|f| functions.contains(&f.id))
        });
        if !ignores {
            continue;
        }
        let mut samples = 0;
        let mut side_effect = false;
        for f in functions.iter().filter_map(|f| program.function(*f)) {
            for inst in &program.insts[f.start..=f.end] {
                let op = inst.class.opcode;
                if crate::program::is_texture_read(op) {
                    samples += 1;
                }
                let name = format!("{op:?}");
                if op == Op::ImageWrite
                    || name.starts_with("Atomic")
                    || name.starts_with("TraceRay")
                    || name.starts_with("ExecuteCallable")
                    || name.starts_with("ReportIntersection")
                {
                    side_effect = true;
                }
                if op == Op::Store {
                    let storage = match inst.operands.first() {
                        Some(Operand::IdRef(p)) => program
                            .def(*p)
                            .and_then(|d| d.result_type)
                            .and_then(|t| match program.ty(t) {
                                Some(Type::Pointer { storage, .. }) => Some(*storage),
                                _ => None,
                            }),
                        _ => None,
                    };
                    // Payload stores are judged by the payload analysis below.
                    if !matches!(
                        storage,
                        Some(
                            StorageClass::Function
                                | StorageClass::Private
                                | StorageClass::IncomingRayPayloadKHR
                        )
                    ) {
                        side_effect = true;
                    }
                }
            }
        }
        if samples == 0 || side_effect {
            continue;
        }
        let writes_payload =
            payload_use::globals_used(program, e.function, StorageClass::IncomingRayPayloadKHR)
                .into_iter()
                .any(|v| {
                    payload_use::variable_use(program, e.function, v)
                        .iter()
                        .any(|u| u.written)
                });
        if writes_payload {
            continue;
        }
        let at = program
            .sites
            .iter()
            .find_map(|s| {
                (s.kind == SiteKind::IgnoreIntersection
                    && program
                        .functions
                        .get(s.function)
                        .is_some_and(|f| functions.contains(&f.id)))
                .then(|| program.site_location(s.inst))
                .flatten()
            })
            .or_else(|| program.decl_location(Decl::Func(e.function)));
        out.push(
            ctx.diagnostic(
                &RULE,
                format!(
                    "any-hit shader `{}` only alpha-tests a texture ({samples} sample{})",
                    e.name,
                    if samples == 1 { "" } else { "s" }
                ),
            )
            .with_primary(at, "ignores the hit on the alpha test")
            .with_subject(format!("any-hit shader `{}`", e.name))
            .with_note("opacity micromaps resolve such tests in traversal; they need `VK_EXT_opacity_micromap` or DXR 1.2")
            .with_help("bake the alpha mask into an opacity micromap, or mark geometry without cut-outs opaque"),
        );
    }
    out
}
