use super::Context;
use crate::diag::Diagnostic;
use crate::program::{Id, Program};
use rspirv::dr::Operand;
use spirv::StorageClass;

super::declare_rule! {
    /// ## What it does
    ///
    /// Reports a hit or miss shader with more than one incoming ray payload
    /// (`rayPayloadInEXT`, SPIR-V `IncomingRayPayloadKHR`) among the globals
    /// its entry point uses.
    ///
    /// ## Why is this bad?
    ///
    /// The Vulkan specification allows one incoming payload per entry point
    /// (VUID-StandaloneSpirv-IncomingRayPayloadKHR-04700): a shader is
    /// invoked with the payload of the trace that reached it, and has no way
    /// to receive two. glslang 12 compiles such a shader without a word; the
    /// 2025 spirv-val rejects the module, and a driver may reject the
    /// pipeline or give both variables the same memory. It usually means a
    /// shader written for two kinds of ray (radiance and shadow) at once,
    /// where the second variable was meant as an outgoing `rayPayloadEXT`.
    ///
    /// ## Example
    ///
    /// ```glsl
    /// layout(location = 0) rayPayloadInEXT vec3 radiance;
    /// layout(location = 1) rayPayloadInEXT bool shadowed;
    /// ```
    ///
    /// Use instead:
    ///
    /// ```glsl
    /// layout(location = 0) rayPayloadInEXT vec3 radiance;
    /// layout(location = 1) rayPayloadEXT bool shadowed; // traced from here
    /// ```
    ///
    /// ## How to fix
    ///
    /// Keep one incoming payload per shader: declare the payload of the rays
    /// this shader traces as `rayPayloadEXT`, or split the shader into one per
    /// ray type (one hit group each).
    ///
    /// ## Options
    ///
    /// None.
    ///
    /// ## References
    ///
    /// - Vulkan specification, VUID-StandaloneSpirv-IncomingRayPayloadKHR-04700.
    "RT007" "two-incoming-payloads" {
        group: Correctness,
        summary: "more than one incoming ray payload in one shader",
        kind: super::Kind::Module(check),
        analysis: Fast,
    }
}

fn check(ctx: &Context) -> Vec<Diagnostic> {
    let program = ctx.program;
    let mut out = Vec::new();
    for entry in &program.entry_points {
        let used = incoming_payloads(program, entry.function, &entry.interface);
        let [first, rest @ ..] = used.as_slice() else {
            continue;
        };
        for &other in rest {
            let name = |v: Id| format!("`{}`", program.display_name(v));
            out.push(
                ctx.diagnostic(
                    &RULE,
                    format!(
                        "entry point `{}` has {} incoming ray payloads; Vulkan allows one",
                        entry.name,
                        used.len()
                    ),
                )
                .with_primary(
                    declared_at(program, other),
                    format!("{} is a second incoming payload", name(other)),
                )
                .with_secondary(
                    declared_at(program, *first),
                    format!("{} is the first", name(*first)),
                )
                .with_note("VUID-StandaloneSpirv-IncomingRayPayloadKHR-04700: one IncomingRayPayloadKHR variable per entry point")
                .with_help("declare the payload this shader traces with as `rayPayloadEXT`, or split the shader per ray type"),
            );
        }
    }
    out
}

/// Where payload variable `var` is declared: the one source line declaring
/// it `rayPayloadInEXT` (glslang's `-g` has no position for globals, and
/// its `-gV` gives them the line of their first use), else debug info's
/// declaration, else its first use.
fn declared_at(program: &Program, var: Id) -> Option<crate::diag::Location> {
    let name = program.name(var).filter(|n| !n.is_empty());
    let found = name.and_then(|name| {
        // (`-gV` names the file without embedding it: read as the
        // Program's own declaration positions are.)
        let texts: Vec<(&std::path::Path, String)> = program
            .files
            .iter()
            .filter_map(|f| {
                let t = f.text.clone().or_else(|| std::fs::read_to_string(&f.path).ok())?;
                Some((f.path.as_path(), t))
            })
            .collect();
        let mut hits = texts.into_iter().flat_map(|(path, text)| {
            let lines: Vec<String> = text.lines().map(str::to_string).collect();
            lines.into_iter().enumerate().filter_map(move |(i, line)| {
                let code = line.split("//").next().unwrap_or("");
                code.find("rayPayloadIn")?;
                let word = code.match_indices(name).find(|(k, _)| {
                    let before = code[..*k].chars().last();
                    let after = code[k + name.len()..].chars().next();
                    !before.is_some_and(|c| c.is_alphanumeric() || c == '_')
                        && !after.is_some_and(|c| c.is_alphanumeric() || c == '_')
                })?;
                Some(crate::diag::Location::point(
                    path.to_path_buf(),
                    i as u32 + 1,
                    word.0 as u32 + 1,
                ))
            })
        });
        let first = hits.next()?;
        hits.next().is_none().then_some(first)
    });
    found
        .or_else(|| program.decl_location(crate::program::Decl::Var(var)))
        .or_else(|| program.var_location(var))
}

/// The `IncomingRayPayloadKHR` variables an entry point uses: in its
/// interface (SPIR-V 1.4 lists every global), or named by a function it
/// reaches (before 1.4 only inputs and outputs are listed), in the order
/// declared.
fn incoming_payloads(program: &Program, function: Id, interface: &[Id]) -> Vec<Id> {
    let incoming: Vec<Id> = program
        .globals_in(StorageClass::IncomingRayPayloadKHR)
        .map(|g| g.id)
        .collect();
    if incoming.len() < 2 {
        return incoming;
    }
    let reached = program.reached_functions(function);
    let mut used = vec![false; incoming.len()];
    for (fi, f) in program.functions.iter().enumerate() {
        if !reached.get(fi).copied().unwrap_or(false) {
            continue;
        }
        for inst in &program.insts[f.start..=f.end] {
            for o in &inst.operands {
                if let Operand::IdRef(x) = o {
                    if let Some(k) = incoming.iter().position(|v| v == x) {
                        used[k] = true;
                    }
                }
            }
        }
    }
    let mut v: Vec<Id> = incoming
        .into_iter()
        .zip(used)
        .filter(|(v, u)| *u || interface.contains(v))
        .map(|(v, _)| v)
        .collect();
    // In the order declared, where known.
    v.sort_by_key(|&x| declared_at(program, x).map(|l| (l.path, l.line, l.column)));
    v
}
