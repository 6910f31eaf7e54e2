//! The 16-bit storage capabilities (`SPV_KHR_16bit_storage`): which ones a
//! module needs follows from the storage classes its 16-bit values live in,
//! so they are added once the module is complete.

use super::*;

/// Adds `StorageBuffer16BitAccess`, `UniformAndStorageBuffer16BitAccess`,
/// `StoragePushConstant16` and `StorageInputOutput16` for the variables whose
/// types hold 16-bit scalars, with the extension when any is added.
pub(super) fn add_16bit_storage(module: &mut dr::Module) {
    let mut has16: HashSet<Id> = HashSet::new();
    let mut pointee: HashMap<Id, (StorageClass, Id)> = HashMap::new();
    let mut needed = BTreeSet::new();
    for i in &module.types_global_values {
        let Some(id) = i.result_id else { continue };
        let refs = || {
            i.operands.iter().filter_map(|o| match o {
                Operand::IdRef(r) => Some(*r),
                _ => None,
            })
        };
        match i.class.opcode {
            Op::TypeInt | Op::TypeFloat => {
                if matches!(i.operands.first(), Some(Operand::LiteralBit32(16))) {
                    has16.insert(id);
                }
            }
            // Types are declared before use, so one pass sees every member.
            Op::TypeVector
            | Op::TypeMatrix
            | Op::TypeArray
            | Op::TypeRuntimeArray
            | Op::TypeStruct
                if refs().any(|r| has16.contains(&r)) =>
            {
                has16.insert(id);
            }
            Op::TypePointer => {
                if let (Some(Operand::StorageClass(c)), Some(Operand::IdRef(t))) =
                    (i.operands.first(), i.operands.get(1))
                {
                    // Loads through device addresses have no variable.
                    if *c == StorageClass::PhysicalStorageBuffer && has16.contains(t) {
                        needed.insert(Capability::StorageBuffer16BitAccess as u32);
                    }
                    pointee.insert(id, (*c, *t));
                }
            }
            Op::Variable => {
                let Some((class, t)) = i.result_type.and_then(|p| pointee.get(&p)) else {
                    continue;
                };
                if !has16.contains(t) {
                    continue;
                }
                let cap = match class {
                    StorageClass::StorageBuffer | StorageClass::PhysicalStorageBuffer => {
                        Capability::StorageBuffer16BitAccess
                    }
                    StorageClass::Uniform => Capability::UniformAndStorageBuffer16BitAccess,
                    StorageClass::PushConstant => Capability::StoragePushConstant16,
                    StorageClass::Input | StorageClass::Output => Capability::StorageInputOutput16,
                    _ => continue,
                };
                needed.insert(cap as u32);
            }
            _ => {}
        }
    }
    if needed.is_empty() {
        return;
    }
    let have: HashSet<u32> = module
        .capabilities
        .iter()
        .filter_map(|i| match i.operands.first() {
            Some(Operand::Capability(c)) => Some(*c as u32),
            _ => None,
        })
        .collect();
    for c in needed {
        if have.contains(&c) {
            continue;
        }
        let cap = Capability::from_u32(c).unwrap_or_else(|| unreachable!("a known capability"));
        module.capabilities.push(Instruction::new(
            Op::Capability,
            None,
            None,
            vec![Operand::Capability(cap)],
        ));
    }
    let ext = "SPV_KHR_16bit_storage";
    let has_ext = module
        .extensions
        .iter()
        .any(|i| matches!(i.operands.first(), Some(Operand::LiteralString(s)) if s == ext));
    if !has_ext {
        module.extensions.push(Instruction::new(
            Op::Extension,
            None,
            None,
            vec![Operand::LiteralString(ext.to_string())],
        ));
    }
}
