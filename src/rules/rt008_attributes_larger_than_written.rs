//! RT008 `attributes-larger-than-written`: hit attributes declared larger
//! than what the intersection shaders write.

use super::Context;
use crate::analysis::layout;
use crate::analysis::payload_use::{self, Access};
use crate::diag::Diagnostic;
use crate::program::Decl;
use crate::shader::Stage;
use spirv::StorageClass;

super::declare_rule! {
    /// ## What it does
    ///
    /// Follows what each intersection shader writes into its hit attributes (the
    /// `hitAttributeEXT` variable, or the struct handed to `ReportHit`) and reports
    /// an attribute type whose members are not all written: the block is declared
    /// larger than what the intersection shaders of the module report. A member is
    /// written where a store reaches it through an access chain from the attribute
    /// variable, or from a local copied into it whole; a whole-struct store writes
    /// every member. Any use the analysis cannot follow counts as a write.
    ///
    /// ## Why is this bad?
    ///
    /// Hit attributes are limited to 32 bytes (`maxRayHitAttributeSize`) and are
    /// kept for every candidate hit the intersection shader reports. Bytes the
    /// intersection shader never writes are carried for nothing, and a closest-hit
    /// or any-hit shader that reads them reads undefined values.
    ///
    /// ## Example
    ///
    /// ```glsl
    /// struct Attribs { vec3 normal; float u; float v; };
    /// hitAttributeEXT Attribs attribs;
    /// void main() {
    ///     attribs.normal = sphereNormal();   // `u` and `v` never written
    ///     reportIntersectionEXT(t, 0);
    /// }
    /// ```
    ///
    /// Use instead:
    ///
    /// ```glsl
    /// struct Attribs { vec3 normal; };
    /// hitAttributeEXT Attribs attribs;
    /// ```
    ///
    /// ## How to fix
    ///
    /// Remove the members no intersection shader writes, or write them before
    /// reporting the hit.
    ///
    /// Fixtures: `fixtures/RT008/`.
    ///
    /// ## References
    ///
    /// - Vulkan specification, `maxRayHitAttributeSize` and the `HitAttributeKHR`
    ///   storage class.
    /// - DirectX Raytracing functional spec, `ReportHit`.
    "RT008" "attributes-larger-than-written" {
        group: Perf,
        summary: "hit attribute members no intersection shader writes",
        kind: super::Kind::Module(check),
        analysis: Full,
    }
}

fn check(ctx: &Context) -> Vec<Diagnostic> {
    let program = ctx.program;
    // Per attribute variable: the union of what every intersection shader
    // of the module writes into it.
    let mut vars: Vec<(u32, Vec<Access>)> = Vec::new();
    for e in program
        .entry_points
        .iter()
        .filter(|e| e.stage == Stage::Intersection)
    {
        for var in payload_use::globals_used(program, e.function, StorageClass::HitAttributeKHR) {
            let uses = payload_use::variable_use(program, e.function, var);
            match vars.iter_mut().find(|(v, _)| *v == var) {
                Some((_, u)) => {
                    for (a, b) in u.iter_mut().zip(uses) {
                        a.merge(b);
                    }
                }
                None => vars.push((var, uses)),
            }
        }
    }
    let mut out = Vec::new();
    for (var, uses) in vars {
        if uses.iter().all(|u| u.written) {
            continue;
        }
        let Some(ty) = program.globals.iter().find(|g| g.id == var).map(|g| g.ty) else {
            continue;
        };
        let Some(l) = layout::layout_type(program, ty, &program.display_name(var)) else {
            continue;
        };
        // Bytes the written members need, each at its own scalar size.
        let written: u64 = if l.is_struct {
            l.members
                .iter()
                .zip(&uses)
                .filter(|(_, u)| u.written)
                .map(|(m, _)| m.size)
                .sum()
        } else {
            // A vector or array: the components written.
            let n = uses.len() as u64;
            let each = l.scalar_size.checked_div(n).unwrap_or(0);
            each * uses.iter().filter(|u| u.written).count() as u64
        };
        if written >= l.scalar_size {
            continue;
        }
        let unwritten: Vec<String> = if l.is_struct {
            l.members
                .iter()
                .zip(&uses)
                .filter(|(_, u)| !u.written)
                .map(|(m, _)| format!("`{}`", m.name))
                .collect()
        } else {
            let names = ["x", "y", "z", "w"];
            uses.iter()
                .enumerate()
                .filter(|(_, u)| !u.written)
                .map(|(k, _)| match names.get(k) {
                    Some(c) if uses.len() <= 4 => format!("`.{c}`"),
                    _ => format!("`[{k}]`"),
                })
                .collect()
        };
        let at = if l.is_struct {
            program
                .decl_location(Decl::Type(ty))
                .or_else(|| program.var_location(var))
        } else {
            program.var_location(var)
        };
        let mut d = ctx
            .diagnostic(
                &RULE,
                format!(
                    "hit attributes `{}` are {} bytes; the intersection shader writes {}",
                    l.name, l.scalar_size, written
                ),
            )
            .with_primary(at, "declared here")
            .with_subject(format!("hit attributes `{}`", l.name))
            .with_note(format!("never written: {}", unwritten.join(", ")));
        if l.is_struct {
            for (k, _) in uses.iter().enumerate().filter(|(_, u)| !u.written) {
                if let Some(m) = program.decl_location(Decl::Member(ty, k as u32)) {
                    d = d.with_secondary(Some(m), "never written");
                }
            }
        }
        out.push(d.with_help("remove the members no intersection shader writes"));
    }
    out
}
