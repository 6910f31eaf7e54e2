//! `NonSemantic.Shader.DebugInfo.100`: source files, structs with their
//! members, globals and functions with their positions, so a module written
//! to disk (`rtlint compile`) still leads back to declarations when checked.

use super::*;
use spirv::NonsemanticShaderDebuginfo100Op as D;

pub(super) struct DebugInfo {
    set: Id,
    void: Id,
    none: Id,
    unit: Id,
    sources: Vec<Id>,
    types: HashMap<Ty, Id>,
    /// (debug function, function, result id) for `DebugFunctionDefinition`.
    pub(super) definitions: Vec<(Id, Id, Id)>,
    /// (function, debug local, variable, result id) for `DebugDeclare`.
    declares: Vec<(Id, Id, Id, Id)>,
    expression: Id,
}

impl<'a> Lowerer<'a> {
    /// A debug instruction at module scope (`Builder::ext_inst` emits only
    /// into a block).
    fn dbg_inst(&mut self, d: &DebugInfo, which: D, args: &[Id]) -> Id {
        let id = self.b.id();
        let mut ops = vec![
            Operand::IdRef(d.set),
            Operand::LiteralExtInstInteger(which as u32),
        ];
        ops.extend(args.iter().map(|a| Operand::IdRef(*a)));
        self.b.insert_types_global_values(
            InsertPoint::End,
            Instruction::new(Op::ExtInst, Some(d.void), Some(id), ops),
        );
        id
    }

    fn dbg_type(&mut self, d: &mut DebugInfo, t: &Ty) -> Id {
        if let Some(id) = d.types.get(t) {
            return *id;
        }
        let id = match t {
            Ty::ScalarKind(s) => {
                let name = self.b.string(s.name());
                let size = self.const_u32(8 * s.size());
                // DWARF-style encodings: Boolean 2, Float 3, Signed 4, Unsigned 6.
                let enc = self.const_u32(match s {
                    ScalarKind::Bool => 2,
                    ScalarKind::Float | ScalarKind::Half => 3,
                    ScalarKind::Int | ScalarKind::Int64 | ScalarKind::Int16 => 4,
                    ScalarKind::Uint | ScalarKind::Uint64 | ScalarKind::Uint16 => 6,
                });
                let flags = self.const_u32(0);
                self.dbg_inst(d, D::DebugTypeBasic, &[name, size, enc, flags])
            }
            Ty::Vec(s, n) => {
                let base = self.dbg_type(d, &Ty::ScalarKind(*s));
                let count = self.const_u32(*n as u32);
                self.dbg_inst(d, D::DebugTypeVector, &[base, count])
            }
            Ty::Mat(s, r, c) => {
                let col = self.dbg_type(d, &Ty::Vec(*s, *c));
                let count = self.const_u32(*r as u32);
                let column_major = self.const_bool(true);
                self.dbg_inst(d, D::DebugTypeMatrix, &[col, count, column_major])
            }
            Ty::Array(e, n) => {
                let base = self.dbg_type(d, e);
                if base == d.none {
                    return d.none; // arrays of resources
                }
                let count = self.const_u32(*n);
                self.dbg_inst(d, D::DebugTypeArray, &[base, count])
            }
            Ty::Struct(k) => self.dbg_struct(d, *k),
            _ => d.none,
        };
        d.types.insert(t.clone(), id);
        id
    }

    fn dbg_struct(&mut self, d: &mut DebugInfo, k: u32) -> Id {
        let def = self.structs[k as usize].clone();
        let source = d
            .sources
            .get(def.pos.file as usize)
            .copied()
            .unwrap_or(d.sources[0]);
        let layout = if def.name.starts_with("type.") {
            Layout::CBuffer
        } else {
            Layout::Std430
        };
        let offsets = struct_offsets(k, layout, &self.structs);
        let mut members = Vec::new();
        for (f, off) in def.fields.iter().zip(offsets) {
            let ty = self.dbg_type(d, &f.ty);
            let name = self.b.string(f.name.clone());
            let (size, _) = size_align(&f.ty, layout, &self.structs);
            let line = self.const_u32(f.pos.line.max(1));
            let col = self.const_u32(f.pos.col.max(1));
            let offset = self.const_u32(off * 8);
            let bits = self.const_u32(size * 8);
            let flags = self.const_u32(3); // FlagIsPublic
            members.push(self.dbg_inst(
                d,
                D::DebugTypeMember,
                &[name, ty, source, line, col, offset, bits, flags],
            ));
        }
        let name = self.b.string(def.name.clone());
        let tag = self.const_u32(1); // Structure
        let line = self.const_u32(def.pos.line.max(1));
        let col = self.const_u32(def.pos.col.max(1));
        let (size, _) = size_align(&Ty::Struct(k), layout, &self.structs);
        let bits = self.const_u32(size * 8);
        let flags = self.const_u32(3);
        let mut args = vec![name, tag, source, line, col, d.unit, name, bits, flags];
        args.extend(members);
        self.dbg_inst(d, D::DebugTypeComposite, &args)
    }

    /// Emits the debug info; returns what `finish` needs to place the
    /// function definitions.
    pub(super) fn emit_debug_info(&mut self) -> Option<DebugInfo> {
        if self.file_ids.is_empty() {
            return None;
        }
        self.ext("SPV_KHR_non_semantic_info");
        let set = self.b.ext_inst_import("NonSemantic.Shader.DebugInfo.100");
        let void = self.b.type_void();
        let mut d = DebugInfo {
            set,
            void,
            none: 0,
            unit: 0,
            sources: Vec::new(),
            types: HashMap::new(),
            definitions: Vec::new(),
            declares: Vec::new(),
            expression: 0,
        };
        d.none = self.dbg_inst(&d, D::DebugInfoNone, &[]);
        for f in self.file_ids.clone() {
            let s = self.dbg_inst(&d, D::DebugSource, &[f]);
            d.sources.push(s);
        }
        let version = self.const_u32(100);
        let dwarf = self.const_u32(4);
        let lang = self.const_u32(5); // HLSL
        d.unit = self.dbg_inst(
            &d,
            D::DebugCompilationUnit,
            &[version, dwarf, d.sources[0], lang],
        );
        // User structs (the built-in RayDesc and attributes have no source).
        for k in 0..self.structs.len() as u32 {
            if self.structs[k as usize].pos.line > 0 {
                self.dbg_type(&mut d, &Ty::Struct(k));
            }
        }
        for (var, name, ty, pos) in self.global_decls.clone() {
            let t = self.dbg_type(&mut d, &ty);
            if t == d.none {
                continue; // resources: no debug type to give
            }
            let n = self.b.string(name);
            let source = d
                .sources
                .get(pos.file as usize)
                .copied()
                .unwrap_or(d.sources[0]);
            let line = self.const_u32(pos.line.max(1));
            let col = self.const_u32(pos.col.max(1));
            let flags = self.const_u32(3);
            self.dbg_inst(
                &d,
                D::DebugGlobalVariable,
                &[n, t, source, line, col, d.unit, n, var, flags],
            );
        }
        let flags = self.const_u32(3);
        let mut dbg_fns = HashMap::new();
        for k in 0..self.funcs.len() {
            if !self.lowered.contains(&k) {
                continue;
            }
            let sig = self.funcs[k].clone();
            let ret = match sig.ret {
                Ty::Void => d.void,
                ref t => self.dbg_type(&mut d, t),
            };
            let mut targs = vec![flags, ret];
            for p in &sig.params {
                targs.push(self.dbg_type(&mut d, &p.ty));
            }
            if targs[1..].contains(&d.none) {
                continue; // resource parameters have no debug type to give
            }
            let fty = self.dbg_inst(&d, D::DebugTypeFunction, &targs);
            let n = self.b.string(sig.name.clone());
            let pos = sig.func.pos;
            let source = d
                .sources
                .get(pos.file as usize)
                .copied()
                .unwrap_or(d.sources[0]);
            let line = self.const_u32(pos.line.max(1));
            let col = self.const_u32(pos.col.max(1));
            let f = self.dbg_inst(
                &d,
                D::DebugFunction,
                &[n, fty, source, line, col, d.unit, n, flags, line],
            );
            let result = self.b.id();
            d.definitions.push((f, sig.id, result));
            dbg_fns.insert(k, f);
        }
        d.expression = self.dbg_inst(&d, D::DebugExpression, &[]);
        let local_flags = self.const_u32(4); // FlagIsLocal
        for (k, var, name, ty, pos) in self.local_decls.clone() {
            let Some(&scope) = dbg_fns.get(&k) else {
                continue;
            };
            let t = self.dbg_type(&mut d, &ty);
            if t == d.none {
                continue;
            }
            let n = self.b.string(name);
            let source = d
                .sources
                .get(pos.file as usize)
                .copied()
                .unwrap_or(d.sources[0]);
            let line = self.const_u32(pos.line.max(1));
            let col = self.const_u32(pos.col.max(1));
            let local = self.dbg_inst(
                &d,
                D::DebugLocalVariable,
                &[n, t, source, line, col, scope, local_flags],
            );
            let result = self.b.id();
            d.declares.push((self.funcs[k].id, local, var, result));
        }
        Some(d)
    }

    /// `DebugDeclare` of each local where it is declared: right after its
    /// `OpVariable`, before the variables are hoisted to the entry block
    /// (as DXC does; the variable's lifetime starts at its declaration).
    /// Parameters, which have no `OpVariable`, are declared in the entry
    /// block by `place_definitions`.
    pub(super) fn place_declares(module: &mut dr::Module, d: &mut DebugInfo) {
        let mut at_var: HashMap<Id, usize> = HashMap::new();
        for (k, x) in d.declares.iter().enumerate() {
            at_var.insert(x.2, k);
        }
        let mut placed = HashSet::new();
        for f in &mut module.functions {
            for b in &mut f.blocks {
                let mut out = Vec::with_capacity(b.instructions.len());
                let mut pending = Vec::new();
                for i in b.instructions.drain(..) {
                    // Phis stay first in their block.
                    if i.class.opcode != Op::Phi {
                        out.append(&mut pending);
                    }
                    let declared = (i.class.opcode == Op::Variable)
                        .then(|| i.result_id.and_then(|v| at_var.get(&v).copied()))
                        .flatten();
                    out.push(i);
                    if let Some(k) = declared {
                        let (_, local, var, result) = d.declares[k];
                        pending.push(declare(d, local, var, result));
                        placed.insert(k);
                    }
                }
                out.append(&mut pending);
                b.instructions = out;
            }
        }
        let mut k = 0;
        d.declares.retain(|_| {
            k += 1;
            !placed.contains(&(k - 1))
        });
    }

    /// `DebugFunctionDefinition` in each function's entry block, after its variables.
    pub(super) fn place_definitions(module: &mut dr::Module, d: &DebugInfo) {
        for (dbg_fn, fn_id, result) in &d.definitions {
            let Some(f) = module
                .functions
                .iter_mut()
                .find(|f| f.def_id() == Some(*fn_id))
            else {
                continue;
            };
            let Some(block) = f.blocks.first_mut() else {
                continue;
            };
            let at = block
                .instructions
                .iter()
                .position(|i| i.class.opcode != Op::Variable)
                .unwrap_or(block.instructions.len());
            for (_, local, var, result) in d.declares.iter().filter(|x| x.0 == *fn_id).rev() {
                block
                    .instructions
                    .insert(at, declare(d, *local, *var, *result));
            }
            block.instructions.insert(
                at,
                Instruction::new(
                    Op::ExtInst,
                    Some(d.void),
                    Some(*result),
                    vec![
                        Operand::IdRef(d.set),
                        Operand::LiteralExtInstInteger(D::DebugFunctionDefinition as u32),
                        Operand::IdRef(*dbg_fn),
                        Operand::IdRef(*fn_id),
                    ],
                ),
            );
        }
    }
}

fn declare(d: &DebugInfo, local: Id, var: Id, result: Id) -> Instruction {
    Instruction::new(
        Op::ExtInst,
        Some(d.void),
        Some(result),
        vec![
            Operand::IdRef(d.set),
            Operand::LiteralExtInstInteger(D::DebugDeclare as u32),
            Operand::IdRef(local),
            Operand::IdRef(var),
            Operand::IdRef(d.expression),
        ],
    )
}
