//! DXR state-object subobjects declared in HLSL (`RaytracingShaderConfig`,
//! `RaytracingPipelineConfig`, hit groups, export associations, root
//! signatures): their content, for use as a pipeline description.
//!
//! They emit nothing into SPIR-V; [`Subobjects`] is what a compile gives back
//! beside the module.

use super::ast::{Expr, ExprKind};
use super::error::{Error, Pos, Result};
use crate::vocab::Location;

/// Which subobject a declaration is, by its type name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    GlobalRootSignature,
    LocalRootSignature,
    StateObjectConfig,
    SubobjectToExportsAssociation,
    RaytracingShaderConfig,
    RaytracingPipelineConfig,
    RaytracingPipelineConfig1,
    TriangleHitGroup,
    ProceduralPrimitiveHitGroup,
}

impl Kind {
    pub fn from_type_name(name: &str) -> Option<Kind> {
        use Kind::*;
        Some(match name {
            "GlobalRootSignature" => GlobalRootSignature,
            "LocalRootSignature" => LocalRootSignature,
            "StateObjectConfig" => StateObjectConfig,
            "SubobjectToExportsAssociation" => SubobjectToExportsAssociation,
            "RaytracingShaderConfig" => RaytracingShaderConfig,
            "RaytracingPipelineConfig" => RaytracingPipelineConfig,
            "RaytracingPipelineConfig1" => RaytracingPipelineConfig1,
            "TriangleHitGroup" => TriangleHitGroup,
            "ProceduralPrimitiveHitGroup" => ProceduralPrimitiveHitGroup,
            _ => return None,
        })
    }

    /// The fields of the initializer, in order, and whether each is a string.
    fn fields(self) -> &'static [(&'static str, bool)] {
        use Kind::*;
        match self {
            GlobalRootSignature | LocalRootSignature => &[("root signature", true)],
            StateObjectConfig => &[("flags", false)],
            SubobjectToExportsAssociation => &[("subobject", true), ("exports", true)],
            RaytracingShaderConfig => &[
                ("maximum payload size", false),
                ("maximum attribute size", false),
            ],
            RaytracingPipelineConfig => &[("maximum recursion depth", false)],
            RaytracingPipelineConfig1 => &[("maximum recursion depth", false), ("flags", false)],
            TriangleHitGroup => &[("any-hit shader", true), ("closest-hit shader", true)],
            ProceduralPrimitiveHitGroup => &[
                ("any-hit shader", true),
                ("closest-hit shader", true),
                ("intersection shader", true),
            ],
        }
    }
}

/// `RaytracingShaderConfig name = { maxPayloadBytes, maxAttributeBytes };`
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ShaderConfig {
    pub name: String,
    pub max_payload_bytes: u32,
    pub max_attribute_bytes: u32,
    pub location: Location,
}

/// `RaytracingPipelineConfig[1] name = { maxTraceRecursionDepth[, flags] };`
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PipelineConfig {
    pub name: String,
    pub max_recursion_depth: u32,
    pub flags: u32,
    pub location: Location,
}

/// `TriangleHitGroup` / `ProceduralPrimitiveHitGroup`; empty strings are `None`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct HitGroup {
    pub name: String,
    pub procedural: bool,
    pub any_hit: Option<String>,
    pub closest_hit: Option<String>,
    pub intersection: Option<String>,
    pub location: Location,
}

/// `SubobjectToExportsAssociation name = { "subobject", "export1;export2" };`
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Association {
    pub name: String,
    pub subobject: String,
    pub exports: Vec<String>,
    pub location: Location,
}

/// A root signature's text, kept as written (it is not used for SPIR-V).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RootSignature {
    pub name: String,
    pub local: bool,
    pub text: String,
    pub location: Location,
}

/// Every subobject a file declares.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Subobjects {
    pub shader_configs: Vec<ShaderConfig>,
    pub pipeline_configs: Vec<PipelineConfig>,
    pub hit_groups: Vec<HitGroup>,
    pub associations: Vec<Association>,
    pub root_signatures: Vec<RootSignature>,
    /// `StateObjectConfig` flags.
    pub state_object_flags: Vec<(String, u32)>,
}

impl Subobjects {
    pub fn is_empty(&self) -> bool {
        *self == Subobjects::default()
    }

    /// The maximum recursion depth the file's pipeline config declares.
    pub fn max_recursion_depth(&self) -> Option<u32> {
        self.pipeline_configs
            .iter()
            .map(|c| c.max_recursion_depth)
            .max()
    }
}

/// Flag names the initializers may use (DXR's `D3D12_*` values).
pub fn flag_constant(name: &str) -> Option<u32> {
    Some(match name {
        "RAYTRACING_PIPELINE_FLAG_NONE" => 0,
        "RAYTRACING_PIPELINE_FLAG_SKIP_TRIANGLES" => 0x100,
        "RAYTRACING_PIPELINE_FLAG_SKIP_PROCEDURAL_PRIMITIVES" => 0x200,
        "STATE_OBJECT_FLAGS_ALLOW_LOCAL_DEPENDENCIES_ON_EXTERNAL_DEFINITONS"
        | "STATE_OBJECT_FLAG_ALLOW_LOCAL_DEPENDENCIES_ON_EXTERNAL_DEFINITIONS" => 0x1,
        "STATE_OBJECT_FLAGS_ALLOW_EXTERNAL_DEPENDENCIES_ON_LOCAL_DEFINITIONS"
        | "STATE_OBJECT_FLAG_ALLOW_EXTERNAL_DEPENDENCIES_ON_LOCAL_DEFINITIONS" => 0x2,
        "STATE_OBJECT_FLAG_ALLOW_STATE_OBJECT_ADDITIONS" => 0x4,
        _ => return None,
    })
}

/// One field's value: a string, or an integer the caller evaluated.
pub enum Value {
    Str(String),
    Int(u32),
}

/// Checks the initializer's shape against `kind`: the number of fields and
/// which are strings. Gives the fields, each with its position.
pub fn fields(kind: Kind, init: &Expr, pos: Pos) -> Result<Vec<&Expr>> {
    let want = kind.fields();
    let ExprKind::InitList(elems) = &init.kind else {
        return Err(Error::new(
            init.pos,
            format!("a `{kind:?}` is initialized with `{{ ... }}`"),
        ));
    };
    if elems.len() != want.len() {
        let names: Vec<&str> = want.iter().map(|(n, _)| *n).collect();
        return Err(Error::new(
            pos,
            format!(
                "a `{kind:?}` has {} field(s) ({}), {} given",
                want.len(),
                names.join(", "),
                elems.len()
            ),
        ));
    }
    for (e, (what, is_str)) in elems.iter().zip(want) {
        if *is_str != matches!(e.kind, ExprKind::Str(_)) {
            let expected = if *is_str { "a string" } else { "a number" };
            return Err(Error::new(
                e.pos,
                format!("the {what} of a `{kind:?}` must be {expected}"),
            ));
        }
    }
    Ok(elems.iter().collect())
}

/// Adds one subobject to `out` from its evaluated fields.
pub fn record(
    out: &mut Subobjects,
    kind: Kind,
    name: &str,
    values: Vec<Value>,
    location: Location,
) {
    let s = |v: &Value| match v {
        Value::Str(s) => s.clone(),
        Value::Int(i) => i.to_string(),
    };
    let n = |v: &Value| match v {
        Value::Int(i) => *i,
        Value::Str(_) => 0,
    };
    let opt = |v: &Value| Some(s(v)).filter(|x| !x.is_empty());
    let name = name.to_string();
    use Kind::*;
    match kind {
        GlobalRootSignature | LocalRootSignature => out.root_signatures.push(RootSignature {
            name,
            local: kind == LocalRootSignature,
            text: s(&values[0]),
            location,
        }),
        StateObjectConfig => out.state_object_flags.push((name, n(&values[0]))),
        SubobjectToExportsAssociation => out.associations.push(Association {
            name,
            subobject: s(&values[0]),
            exports: s(&values[1])
                .split(';')
                .map(str::trim)
                .filter(|x| !x.is_empty())
                .map(String::from)
                .collect(),
            location,
        }),
        RaytracingShaderConfig => out.shader_configs.push(ShaderConfig {
            name,
            max_payload_bytes: n(&values[0]),
            max_attribute_bytes: n(&values[1]),
            location,
        }),
        RaytracingPipelineConfig | RaytracingPipelineConfig1 => {
            out.pipeline_configs.push(PipelineConfig {
                name,
                max_recursion_depth: n(&values[0]),
                flags: values.get(1).map(n).unwrap_or(0),
                location,
            })
        }
        TriangleHitGroup | ProceduralPrimitiveHitGroup => out.hit_groups.push(HitGroup {
            name,
            procedural: kind == ProceduralPrimitiveHitGroup,
            any_hit: opt(&values[0]),
            closest_hit: opt(&values[1]),
            intersection: values.get(2).and_then(opt),
            location,
        }),
    }
}
