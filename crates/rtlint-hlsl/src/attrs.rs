//! Every attribute the parser accepts, and what becomes of it.
//!
//! An attribute is either implemented, a hint with no meaning for SPIR-V
//! (loop and branch hints), or refused with `not supported` at its position.
//! Names not in [`ATTRIBUTES`] are refused too, so no attribute is ever
//! silently dropped. `tests/hlsl_errors.rs` walks this table.

use super::ast::Attr;
use super::error::{Error, Result};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Support {
    /// Lowered as DXC lowers it.
    Implemented,
    /// An optimization hint: no effect on what the module computes.
    Hint,
    /// Refused with `not supported: <why>`.
    Refused(&'static str),
}

/// Where an attribute is written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Site {
    Function,
    /// A global variable or a `cbuffer`.
    Global,
    /// A struct member or a `cbuffer` member.
    Member,
    Param,
    Statement,
    /// After `struct` (`struct [raypayload] P`).
    Struct,
}

impl Site {
    const fn bit(self) -> u8 {
        1 << self as u8
    }

    fn name(self) -> &'static str {
        match self {
            Site::Function => "a function",
            Site::Global => "a global declaration",
            Site::Member => "a struct or cbuffer member",
            Site::Param => "a parameter",
            Site::Statement => "a statement",
            Site::Struct => "a struct",
        }
    }
}

pub struct AttrInfo {
    /// Lowercase (attribute names are not case sensitive).
    pub name: &'static str,
    pub support: Support,
    /// Where it may be written (a bit per [`Site`]); elsewhere it is refused.
    pub sites: u8,
}

const FUNCTION: u8 = Site::Function.bit();
const GLOBAL: u8 = Site::Global.bit();
const MEMBER: u8 = Site::Member.bit();
const PARAM: u8 = Site::Param.bit();
const STATEMENT: u8 = Site::Statement.bit();
const STRUCT: u8 = Site::Struct.bit();
const ANY: u8 = FUNCTION | GLOBAL | MEMBER | PARAM | STATEMENT | STRUCT;

const fn a(name: &'static str, support: Support, sites: u8) -> AttrInfo {
    AttrInfo {
        name,
        support,
        sites,
    }
}

use Support::*;

pub const ATTRIBUTES: &[AttrInfo] = &[
    // Entry points.
    a("shader", Implemented, FUNCTION),
    a("numthreads", Implemented, FUNCTION),
    // Root signatures describe D3D12 bindings; Vulkan has none (DXC drops them too).
    a("rootsignature", Hint, FUNCTION),
    // Statements.
    a("unroll", Hint, STATEMENT),
    a("loop", Hint, STATEMENT),
    a("fastopt", Hint, STATEMENT),
    a("allow_uav_condition", Hint, STATEMENT),
    a("branch", Hint, STATEMENT),
    a("flatten", Hint, STATEMENT),
    a("call", Hint, STATEMENT),
    a("forcecase", Hint, STATEMENT),
    // Functions.
    a("noinline", Hint, FUNCTION),
    // Payload structs: access qualifiers are checked by DXC, not used by SPIR-V.
    a("raypayload", Hint, STRUCT),
    // Vulkan.
    a("vk::binding", Implemented, GLOBAL),
    a("vk::push_constant", Implemented, GLOBAL),
    a("vk::shader_record_ext", Implemented, GLOBAL),
    a("vk::shader_record_nv", Implemented, GLOBAL),
    a("vk::constant_id", Implemented, GLOBAL),
    a("vk::location", Implemented, PARAM | MEMBER | FUNCTION),
    a("vk::image_format", Implemented, GLOBAL),
    a("vk::ext_builtin_input", Implemented, GLOBAL),
    a("vk::ext_extension", Implemented, GLOBAL | FUNCTION),
    a("vk::ext_capability", Implemented, GLOBAL | FUNCTION),
    a("vk::ext_builtin_output", Implemented, GLOBAL),
    // A function declaration whose calls are the instruction.
    a("vk::ext_instruction", Implemented, FUNCTION),
    a("vk::ext_reference", Implemented, PARAM),
    a("vk::ext_literal", Implemented, PARAM),
    // `OpMemberDecorate` on struct members, `OpDecorate` on global variables
    // and function parameters; elsewhere refused (by site, or where the
    // declaration becomes no variable: `lower/inline_spirv.rs`).
    a("vk::ext_decorate", Implemented, MEMBER | GLOBAL | PARAM),
    a("vk::ext_decorate_id", Refused("`vk::ext_decorate_id`"), ANY),
    a(
        "vk::ext_decorate_string",
        Refused("`vk::ext_decorate_string`"),
        ANY,
    ),
    a(
        "vk::ext_storage_class",
        Refused("`vk::ext_storage_class`"),
        ANY,
    ),
    a("vk::ext_type_def", Refused("`vk::ext_type_def`"), ANY),
    a("vk::builtin", Refused("`vk::builtin`"), ANY),
    a(
        "vk::index",
        Refused("`vk::index` (dual-source blending)"),
        ANY,
    ),
    a("vk::offset", Refused("`vk::offset`"), ANY),
    a("vk::counter_binding", Refused("`vk::counter_binding`"), ANY),
    a(
        "vk::input_attachment_index",
        Refused("`vk::input_attachment_index`"),
        ANY,
    ),
    a(
        "vk::combinedimagesampler",
        Refused("`vk::combinedImageSampler`"),
        ANY,
    ),
    a(
        "vk::post_depth_coverage",
        Refused("`vk::post_depth_coverage`"),
        ANY,
    ),
    a(
        "vk::early_and_late_tests",
        Refused("`vk::early_and_late_tests`"),
        ANY,
    ),
    // Other stages and their attributes.
    // Pixel entry points: `EarlyFragmentTests`.
    a("earlydepthstencil", Implemented, FUNCTION),
    a("wavesize", Refused("`[WaveSize]`"), ANY),
    a("maxvertexcount", Refused("geometry shaders"), ANY),
    a("domain", Refused("tessellation shaders"), ANY),
    a("partitioning", Refused("tessellation shaders"), ANY),
    a(
        "outputtopology",
        Refused("tessellation and mesh shaders"),
        ANY,
    ),
    a("outputcontrolpoints", Refused("tessellation shaders"), ANY),
    a("patchconstantfunc", Refused("tessellation shaders"), ANY),
    a("maxtessfactor", Refused("tessellation shaders"), ANY),
    a("instance", Refused("geometry shader instancing"), ANY),
    a("nodelaunch", Refused("work graphs"), ANY),
];

/// The name attributes are looked up by: plain HLSL attributes are not case
/// sensitive (`[NumThreads]`), `vk::` ones keep their case except for the
/// table's lowercase spelling.
pub fn normalize(name: &str) -> String {
    name.to_ascii_lowercase()
}

pub fn lookup(name: &str) -> Option<&'static AttrInfo> {
    let n = normalize(name);
    ATTRIBUTES.iter().find(|a| a.name == n)
}

/// Refuses unknown and unsupported attributes at their position.
pub fn check(attr: &Attr) -> Result<()> {
    match lookup(&attr.name) {
        Some(AttrInfo {
            support: Implemented | Hint,
            ..
        }) => Ok(()),
        Some(AttrInfo {
            support: Refused(what),
            ..
        }) => Err(Error::unsupported(attr.pos, what).len(attr.name.len() as u32)),
        None => Err(
            Error::unsupported(attr.pos, format!("attribute `{}`", attr.name))
                .len(attr.name.len() as u32),
        ),
    }
}

/// Refuses attributes written where they mean nothing to the compiler.
pub fn check_site(attrs: &[Attr], site: Site) -> Result<()> {
    for attr in attrs {
        check(attr)?;
        if let Some(info) = lookup(&attr.name) {
            if info.sites & site.bit() == 0 {
                return Err(Error::unsupported(
                    attr.pos,
                    format!("`{}` on {}", attr.name, site.name()),
                )
                .len(attr.name.len() as u32));
            }
        }
    }
    Ok(())
}
