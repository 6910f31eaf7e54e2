//! Reach by payload: which shaders a trace (or callable) site can run.
//!
//! The driver passes a trace's payload to the closest-hit, any-hit and miss
//! shaders it selects, and a callable's data to the callable it selects; the
//! languages require the callee's incoming payload to have the caller's type
//! (DXR: "the same structure as the one provided at the originating TraceRay
//! call"; `GL_EXT_ray_tracing`: "the type of this variable must match the
//! type of the rayPayloadEXT variable as passed … to traceRayEXT()"). So a
//! trace reaches a shader only when the shader's incoming payload has the
//! same shape as the traced one: the same members in the same order, each
//! with the same scalar widths, vector and matrix sizes and array lengths.
//! Names do not matter (two modules name their structs as they like), nor
//! does integer versus float of one width, nor the Vulkan `Location` of the
//! incoming payload (the spec links the caller's location to the caller's
//! variable only). The coarser match can only add edges, the safe side for
//! depths and stack sizes.
//!
//! Where the match cannot be decided (the traced payload is not a variable
//! the module declares, or a type has no defined size), the shader is taken
//! as reached and the reason kept, so outputs can say it.

use crate::analysis::layout::Shape;
use crate::analysis::payload_use;
use crate::program::{Id, Program, SiteKind, Type};
use crate::shader::Stage;
use rustc_hash::FxHashMap;
use spirv::StorageClass;

/// One incoming payload (or callable data) variable of a shader.
#[derive(Clone, Debug, PartialEq)]
pub struct Incoming {
    pub var: Id,
    pub shape: Shape,
}

/// Why a site was taken to reach a shader without a payload match.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Ambiguity {
    /// The site's payload operand is not a variable with a pointer type.
    TracedPayloadUnknown,
    /// The traced payload's type has no defined size.
    TracedPayloadUnsized,
    /// The shader's incoming payload type has no defined size.
    IncomingUnsized,
    /// No miss shader the trace can select takes its payload: its own miss
    /// shader is not among those given, or its payload does not match.
    NoMissTakesPayload,
}

/// Whether a site's payload can be passed to a shader (or hit group).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Admit {
    Yes,
    No,
    /// Taken as reached: the match could not be decided.
    Assumed(Ambiguity),
}

impl Admit {
    pub fn reaches(self) -> bool {
        !matches!(self, Admit::No)
    }
}

/// The payloads of a pipeline's sites and shaders, each worked out once.
#[derive(Clone, Debug, Default)]
pub struct Payloads {
    /// Per (program, entry function): incoming payload or callable data.
    incoming: FxHashMap<(usize, Id), Vec<Incoming>>,
    /// Per (program, site instruction): the traced payload's shape.
    traced: FxHashMap<(usize, usize), Result<Shape, Ambiguity>>,
}

/// The storage class of what a stage is invoked with.
fn incoming_storage(stage: Stage) -> Option<StorageClass> {
    match stage {
        Stage::ClosestHit | Stage::AnyHit | Stage::Miss => {
            Some(StorageClass::IncomingRayPayloadKHR)
        }
        Stage::Callable => Some(StorageClass::IncomingCallableDataKHR),
        _ => None,
    }
}

/// The incoming payload variables of entry `function` of `program`: those
/// its code names, else those its entry point lists (a shader that never
/// touches its payload still declares it).
pub fn incoming_of(program: &Program, function: Id, stage: Stage) -> Vec<Incoming> {
    let Some(storage) = incoming_storage(stage) else {
        return Vec::new();
    };
    let mut vars = payload_use::globals_used(program, function, storage);
    if vars.is_empty() {
        if let Some(e) = program.entry_points.iter().find(|e| e.function == function) {
            vars = program
                .globals_in(storage)
                .filter(|g| e.interface.contains(&g.id))
                .map(|g| g.id)
                .collect();
        }
    }
    vars.into_iter()
        .filter_map(|v| {
            let g = program.globals.iter().find(|g| g.id == v)?;
            Some(Incoming {
                var: v,
                shape: payload_use::shape_of(program, g.ty),
            })
        })
        .collect()
}

/// The shape of the payload (or callable data) site `inst` passes.
pub fn traced_of(program: &Program, inst: usize) -> Result<Shape, Ambiguity> {
    let var = program
        .sites
        .iter()
        .find(|s| {
            s.inst == inst && matches!(s.kind, SiteKind::TraceRay | SiteKind::ExecuteCallable)
        })
        .and_then(|s| s.payload)
        .ok_or(Ambiguity::TracedPayloadUnknown)?;
    let ty = program
        .def(var)
        .and_then(|d| d.result_type)
        .and_then(|t| match program.ty(t) {
            Some(Type::Pointer { pointee, .. }) => Some(*pointee),
            _ => None,
        })
        .ok_or(Ambiguity::TracedPayloadUnknown)?;
    let shape = payload_use::shape_of(program, ty);
    if shape.is_sized() {
        Ok(shape)
    } else {
        Err(Ambiguity::TracedPayloadUnsized)
    }
}

impl Payloads {
    /// A shader's incoming payloads (worked out on first use).
    pub fn incoming(
        &mut self,
        programs: &[Program],
        program: usize,
        function: Id,
        stage: Stage,
    ) -> &[Incoming] {
        self.incoming.entry((program, function)).or_insert_with(|| {
            programs
                .get(program)
                .map(|p| incoming_of(p, function, stage))
                .unwrap_or_default()
        })
    }

    /// A site's traced payload (worked out on first use).
    pub fn traced(
        &mut self,
        programs: &[Program],
        program: usize,
        inst: usize,
    ) -> Result<Shape, Ambiguity> {
        self.traced
            .entry((program, inst))
            .or_insert_with(|| match programs.get(program) {
                Some(p) => traced_of(p, inst),
                None => Err(Ambiguity::TracedPayloadUnknown),
            })
            .clone()
    }

    /// The incoming payloads already worked out for a shader.
    pub fn incoming_known(&self, program: usize, function: Id) -> &[Incoming] {
        self.incoming
            .get(&(program, function))
            .map_or(&[], Vec::as_slice)
    }

    /// The traced payload already worked out for a site.
    pub fn traced_known(&self, program: usize, inst: usize) -> Option<&Shape> {
        self.traced
            .get(&(program, inst))
            .and_then(|r| r.as_ref().ok())
    }
}

/// Whether payload `traced` can be passed to shaders whose incoming
/// payloads are `incoming` (all the shaders of one hit group, or one miss
/// or callable shader). A shader that declares none takes any payload; one
/// that declares several (invalid, but accepted by glslang) is reached
/// when any of them matches.
pub fn admit<'a>(
    traced: &Result<Shape, Ambiguity>,
    incoming: impl IntoIterator<Item = &'a Incoming>,
) -> Admit {
    let mut any = false;
    let mut no_size = false;
    for i in incoming {
        any = true;
        if !i.shape.is_sized() {
            no_size = true;
            continue;
        }
        if let Ok(s) = traced {
            if *s == i.shape {
                return Admit::Yes;
            }
        }
    }
    match traced {
        _ if !any => Admit::Yes,
        Err(why) => Admit::Assumed(*why),
        Ok(_) if no_size => Admit::Assumed(Ambiguity::IncomingUnsized),
        Ok(_) => Admit::No,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn inc(shape: Shape) -> Incoming {
        Incoming { var: 1, shape }
    }

    #[test]
    fn same_shape_reaches_other_shape_does_not() {
        let radiance = Shape::Struct {
            members: vec![
                Shape::Vector {
                    scalar: 4,
                    count: 3,
                },
                Shape::Scalar { bytes: 4 },
            ],
        };
        let shadow = Shape::Struct {
            members: vec![Shape::Scalar { bytes: 4 }],
        };
        assert_eq!(
            admit(&Ok(radiance.clone()), &[inc(radiance.clone())]),
            Admit::Yes
        );
        assert_eq!(
            admit(&Ok(shadow.clone()), &[inc(radiance.clone())]),
            Admit::No
        );
        // No incoming payload: anything goes.
        assert_eq!(admit(&Ok(shadow.clone()), &[]), Admit::Yes);
        // Undecidable: reached, with the reason.
        assert_eq!(
            admit(
                &Err(Ambiguity::TracedPayloadUnknown),
                &[inc(radiance.clone())]
            ),
            Admit::Assumed(Ambiguity::TracedPayloadUnknown)
        );
        assert_eq!(
            admit(&Ok(shadow), &[inc(Shape::Opaque)]),
            Admit::Assumed(Ambiguity::IncomingUnsized)
        );
    }
}
