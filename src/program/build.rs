//! Building a [`Program`] from SPIR-V words. Every malformed input becomes an
//! [`InputError`] naming the file and the word offset; nothing here panics on
//! bad input (ids are looked up, never assumed).

use super::debug::resolve_path;
use super::*;
use crate::diag::{InputError, InputErrorKind};
use rspirv::binary::{Consumer, ParseAction};
use rspirv::dr::{self, ModuleHeader};
use std::path::Path;

use spirv::NonsemanticShaderDebuginfo100Op as DebugOp;

struct Collect {
    header: Option<ModuleHeader>,
    insts: Vec<dr::Instruction>,
}

impl Consumer for Collect {
    fn initialize(&mut self) -> ParseAction {
        ParseAction::Continue
    }
    fn finalize(&mut self) -> ParseAction {
        ParseAction::Continue
    }
    fn consume_header(&mut self, module: ModuleHeader) -> ParseAction {
        self.header = Some(module);
        ParseAction::Continue
    }
    fn consume_instruction(&mut self, inst: dr::Instruction) -> ParseAction {
        self.insts.push(inst);
        ParseAction::Continue
    }
}

fn err(path: &Path, msg: impl Into<String>) -> InputError {
    InputError::new(InputErrorKind::InvalidSpirv, path, msg)
}

/// Parses and checks a module. `language` is the front-end's language; a
/// `.spv` takes the one its `OpSource` names.
pub fn parse(words: &[u32], path: &Path, language: Language) -> Result<Program, InputError> {
    parse_owned(words.to_vec(), path, language)
}

/// [`parse`], keeping `words` as the Program's copy of the module instead
/// of copying them.
pub fn parse_owned(
    words: Vec<u32>,
    path: &Path,
    language: Language,
) -> Result<Program, InputError> {
    if words.len() < 5 {
        return Err(err(path, "SPIR-V module is shorter than the 5-word header"));
    }
    if words[0] != super::binary::MAGIC {
        return Err(err(
            path,
            format!("not a SPIR-V module: word 0 is {:#010x}", words[0]),
        ));
    }
    let bound = words[3];
    // Our own pass over the instruction stream first: it gives every
    // instruction's word offset and catches what the parser reports vaguely.
    let mut offsets = Vec::new();
    let mut i = 5usize;
    while i < words.len() {
        let count = (words[i] >> 16) as usize;
        if count == 0 {
            return Err(err(
                path,
                format!("instruction at word {i} has a word count of 0"),
            ));
        }
        if i + count > words.len() {
            return Err(err(
                path,
                format!(
                    "module is truncated: the instruction at word {i} needs {count} words, {} remain",
                    words.len() - i
                ),
            ));
        }
        let opcode = words[i] & 0xffff;
        if !super::decode::known_opcode(opcode as u16) {
            return Err(err(path, format!("unknown opcode {opcode} at word {i}")));
        }
        // rspirv reads the operands of the operation an `OpSpecConstantOp`
        // names by that opcode's grammar and panics on one it cannot take
        // (another `OpSpecConstant*`: found by fuzzing); the spec allows a
        // fixed list.
        if opcode == Op::SpecConstantOp as u32 && count >= 4 {
            let inner = words[i + 3];
            if !Op::from_u32(inner).is_some_and(spec_constant_op_allows) {
                return Err(err(
                    path,
                    format!(
                        "OpSpecConstantOp at word {i} performs {}, which OpSpecConstantOp does not allow",
                        opname(&[inner], 0)
                    ),
                ));
            }
        }
        offsets.push(i as u32);
        i += count;
    }
    let mut c = Collect {
        header: None,
        insts: Vec::new(),
    };
    // Compilers copy source bytes into strings unchecked (glslang `-g` keeps
    // a Latin-1 comment), and spirv-val accepts that: parse a copy whose
    // strings have each invalid byte replaced by `?`.
    let cleaned = valid_utf8_strings(&words, &offsets);
    let input = cleaned.as_deref().unwrap_or(&words);
    if let Some(insts) = super::decode::decode(input, &offsets) {
        let (major, minor) = (
            ((words[1] >> 16) & 0xff) as u8,
            ((words[1] >> 8) & 0xff) as u8,
        );
        let mut header = ModuleHeader::new(bound);
        header.set_version(major, minor);
        c.header = Some(header);
        c.insts = insts;
    } else if let Err(e) = rspirv::binary::parse_words(input, &mut c) {
        use rspirv::binary::ParseState as S;
        let at = |n: usize| offsets.get(n).copied().unwrap_or(words.len() as u32);
        let msg = match e {
            S::OpcodeUnknown(_, n, op) => format!("unknown opcode {op} at word {}", at(n)),
            S::OperandExpected(_, n) => format!(
                "instruction at word {} ({}) is missing operands",
                at(n),
                opname(&words, at(n))
            ),
            S::OperandExceeded(_, n) => format!(
                "instruction at word {} ({}) has more operands than its opcode takes",
                at(n),
                opname(&words, at(n))
            ),
            S::TypeUnsupported(_, n) => format!(
                "instruction at word {} ({}) uses an undeclared or unsupported type",
                at(n),
                opname(&words, at(n))
            ),
            S::WordCountZero(_, n) => {
                format!("instruction at word {} has a word count of 0", at(n))
            }
            S::OperandError(d) => {
                format!("bad operand after word {}: {d}", at(c.insts.len()))
            }
            other => format!("{other} (near word {})", at(c.insts.len())),
        };
        return Err(err(path, msg));
    }
    let header = c.header.unwrap_or_else(|| ModuleHeader::new(bound));
    let (major, minor) = header.version();
    let mut b = Builder {
        path,
        p: Program {
            path: path.to_path_buf(),
            language,
            version: (major, minor),
            words,
            memo: Default::default(),
            insts: c.insts,
            offsets,
            locs: Vec::new(),
            files: Vec::new(),
            types: FastMap::default(),
            names: FastMap::default(),
            member_names: FastMap::default(),
            decorations: FastMap::default(),
            member_decorations: FastMap::default(),
            constants: FastMap::default(),
            spec_constants: FastMap::default(),
            globals: Vec::new(),
            entry_points: Vec::new(),
            functions: Vec::new(),
            sites: Vec::new(),
            decl_pos: FastMap::default(),
            defs: FastMap::default(),
            debug_info_set: None,
            debug_sets: Vec::new(),
        },
        strings: FastMap::default(),
        file_of_string: FastMap::default(),
        dbg_sources: FastMap::default(),
        dbg_members: FastMap::default(),
        dbg_composites: Vec::new(),
        dbg_functions: FastMap::default(),
        dbg_locals: FastMap::default(),
    };
    b.check_ids(bound)?;
    b.collect()?;
    b.functions()?;
    b.link_debug_composites();
    b.drop_impossible_positions();
    b.sites();
    super::callpos::refine(&mut b.p);
    super::textdecl::fill(&mut b.p);
    Ok(b.p)
}

/// The word within an instruction where its literal string starts, for the
/// instructions that carry one.
fn string_word(opcode: u32, count: usize) -> Option<usize> {
    // By number: every instruction is asked, and `Op::from_u32` is slow.
    const STRING: u32 = Op::String as u32;
    const NAME: u32 = Op::Name as u32;
    const EXT_INST_IMPORT: u32 = Op::ExtInstImport as u32;
    const MEMBER_NAME: u32 = Op::MemberName as u32;
    const ENTRY_POINT: u32 = Op::EntryPoint as u32;
    const SOURCE_CONTINUED: u32 = Op::SourceContinued as u32;
    const SOURCE_EXTENSION: u32 = Op::SourceExtension as u32;
    const EXTENSION: u32 = Op::Extension as u32;
    const MODULE_PROCESSED: u32 = Op::ModuleProcessed as u32;
    const SOURCE: u32 = Op::Source as u32;
    let at = match opcode {
        STRING | NAME | EXT_INST_IMPORT => 2,
        MEMBER_NAME | ENTRY_POINT => 3,
        SOURCE_CONTINUED | SOURCE_EXTENSION | EXTENSION | MODULE_PROCESSED => 1,
        SOURCE => 4,
        _ => return None,
    };
    (at < count).then_some(at)
}

/// A copy of the module with every string's invalid UTF-8 bytes replaced by
/// `?` (same length, so no word moves); `None` when every string is valid.
fn valid_utf8_strings(words: &[u32], offsets: &[u32]) -> Option<Vec<u32>> {
    let mut out: Option<Vec<u32>> = None;
    for &at in offsets {
        let at = at as usize;
        let count = (words[at] >> 16) as usize;
        let Some(k) = string_word(words[at] & 0xffff, count) else {
            continue;
        };
        // Plain ASCII up to the terminating zero is valid as it stands: no
        // copy of the bytes for the strings nearly every module has.
        let string = &words[at + k..at + count];
        let ascii_end = string.iter().position(|w| w & 0x8080_8080 != 0);
        let nul_word = string.iter().position(|w| w.to_le_bytes().contains(&0));
        if nul_word.is_some_and(|z| ascii_end.is_none_or(|a| z < a)) {
            continue;
        }
        let mut bytes: Vec<u8> = words[at + k..at + count]
            .iter()
            .flat_map(|w| w.to_le_bytes())
            .collect();
        let len = bytes.iter().position(|&b| b == 0).unwrap_or(bytes.len());
        let mut changed = false;
        let mut start = 0;
        while start < len {
            match std::str::from_utf8(&bytes[start..len]) {
                Ok(_) => break,
                Err(e) => {
                    let bad = start + e.valid_up_to();
                    let n = e.error_len().unwrap_or(len - bad);
                    bytes[bad..bad + n].fill(b'?');
                    start = bad + n;
                    changed = true;
                }
            }
        }
        if changed {
            let out = out.get_or_insert_with(|| words.to_vec());
            for (j, c) in bytes.chunks_exact(4).enumerate() {
                out[at + k + j] = u32::from_le_bytes([c[0], c[1], c[2], c[3]]);
            }
        }
    }
    out
}

/// The operations `OpSpecConstantOp` may perform: the SPIR-V specification's
/// list for shaders and for kernels together.
fn spec_constant_op_allows(op: Op) -> bool {
    use Op::*;
    matches!(
        op,
        SConvert
            | UConvert
            | FConvert
            | SNegate
            | Not
            | IAdd
            | ISub
            | IMul
            | UDiv
            | SDiv
            | UMod
            | SRem
            | SMod
            | ShiftRightLogical
            | ShiftRightArithmetic
            | ShiftLeftLogical
            | BitwiseOr
            | BitwiseXor
            | BitwiseAnd
            | VectorShuffle
            | CompositeExtract
            | CompositeInsert
            | LogicalOr
            | LogicalAnd
            | LogicalNot
            | LogicalEqual
            | LogicalNotEqual
            | Select
            | IEqual
            | INotEqual
            | ULessThan
            | SLessThan
            | UGreaterThan
            | SGreaterThan
            | ULessThanEqual
            | SLessThanEqual
            | UGreaterThanEqual
            | SGreaterThanEqual
            | QuantizeToF16
            | ConvertFToS
            | ConvertSToF
            | ConvertFToU
            | ConvertUToF
            | ConvertPtrToU
            | ConvertUToPtr
            | GenericCastToPtr
            | PtrCastToGeneric
            | Bitcast
            | FNegate
            | FAdd
            | FSub
            | FMul
            | FDiv
            | FRem
            | FMod
            | AccessChain
            | InBoundsAccessChain
            | PtrAccessChain
            | InBoundsPtrAccessChain
    )
}

fn opname(words: &[u32], offset: u32) -> String {
    let w = words.get(offset as usize).copied().unwrap_or(0);
    match Op::from_u32(w & 0xffff) {
        Some(op) => format!("Op{op:?}"),
        None => format!("opcode {}", w & 0xffff),
    }
}

struct Builder<'a> {
    path: &'a Path,
    p: Program,
    strings: FastMap<Id, String>,
    /// File index for each `OpString` naming a source file.
    file_of_string: FastMap<Id, u32>,
    /// `DebugSource` result id → file index.
    dbg_sources: FastMap<Id, u32>,
    /// `DebugTypeMember` result id → its position.
    dbg_members: FastMap<Id, SrcPos>,
    /// `DebugTypeComposite`: name, position, member ids.
    dbg_composites: Vec<(String, SrcPos, Vec<Id>)>,
    dbg_functions: FastMap<Id, SrcPos>,
    dbg_locals: FastMap<Id, SrcPos>,
}

fn id_at(inst: &dr::Instruction, i: usize) -> Option<Id> {
    match inst.operands.get(i)? {
        Operand::IdRef(x) | Operand::IdScope(x) | Operand::IdMemorySemantics(x) => Some(*x),
        _ => None,
    }
}

fn lit_at(inst: &dr::Instruction, i: usize) -> Option<u32> {
    match inst.operands.get(i)? {
        Operand::LiteralBit32(x) | Operand::LiteralExtInstInteger(x) => Some(*x),
        _ => None,
    }
}

fn str_at(inst: &dr::Instruction, i: usize) -> Option<&str> {
    match inst.operands.get(i)? {
        Operand::LiteralString(s) => Some(s),
        _ => None,
    }
}

impl Builder<'_> {
    fn word(&self, inst: usize) -> u32 {
        self.p.offsets.get(inst).copied().unwrap_or(0)
    }

    fn at(&self, inst: usize, msg: impl std::fmt::Display) -> InputError {
        err(
            self.path,
            // From the words: `collect` holds the instructions out of `p`.
            format!(
                "{msg} (instruction {} at word {})",
                opname(&self.p.words, self.word(inst)),
                self.word(inst)
            ),
        )
    }

    /// Positions on line 0 or past the end of their file's embedded text
    /// (glslang 12 `-gV` writes both) are no positions.
    fn drop_impossible_positions(&mut self) {
        let lines: Vec<Option<usize>> = self
            .p
            .files
            .iter()
            .map(|f| {
                // glslang `-gV` embeds no text: the file on disk, if any.
                match &f.text {
                    Some(t) => Some(line_count(t)),
                    None => crate::shader::read_source_text(&f.path).map(|t| line_count(&t)),
                }
            })
            .collect();
        let possible = |p: &SrcPos| {
            p.line > 0
                && lines
                    .get(p.file as usize)
                    .copied()
                    .flatten()
                    .is_none_or(|n| p.line as usize <= n)
        };
        for loc in &mut self.p.locs {
            if loc.as_ref().is_some_and(|p| !possible(p)) {
                *loc = None;
            }
        }
        self.p.decl_pos.retain(|_, p| possible(p));
    }

    /// Every id used must be defined somewhere in the module and below the bound.
    fn check_ids(&mut self, bound: u32) -> Result<(), InputError> {
        // Which ids are defined, by id where the bound is near the module's
        // size (ids are dense): a use costs an index, not a hash lookup.
        let dense = bound as usize <= 4 * self.p.words.len() + 64;
        let mut defined = vec![false; if dense { bound as usize } else { 0 }];
        let results = self
            .p
            .insts
            .iter()
            .filter(|i| i.result_id.is_some())
            .count();
        self.p.defs.reserve(results);
        for (i, inst) in self.p.insts.iter().enumerate() {
            if let Some(r) = inst.result_id {
                if r == 0 || r >= bound {
                    return Err(
                        self.at(i, format!("result id %{r} is outside the id bound {bound}"))
                    );
                }
                if self.p.defs.insert(r, i).is_some() {
                    return Err(self.at(i, format!("id %{r} is defined twice")));
                }
                if dense {
                    defined[r as usize] = true;
                }
            }
        }
        let is_defined = |id: Id| {
            if dense {
                defined.get(id as usize).copied().unwrap_or(false)
            } else {
                self.p.defs.contains_key(&id)
            }
        };
        for (i, inst) in self.p.insts.iter().enumerate() {
            let used = inst
                .result_type
                .into_iter()
                .chain(inst.operands.iter().filter_map(|o| match o {
                    Operand::IdRef(x) | Operand::IdScope(x) | Operand::IdMemorySemantics(x) => {
                        Some(*x)
                    }
                    _ => None,
                }));
            for id in used {
                if !is_defined(id) {
                    return Err(self.at(i, format!("id %{id} is used but never defined")));
                }
            }
        }
        Ok(())
    }

    fn add_file(&mut self, named: &str) -> u32 {
        let path = resolve_path(named, self.path);
        if let Some(i) = self.p.files.iter().position(|f| f.path == path) {
            return i as u32;
        }
        self.p.files.push(SourceFile { path, text: None });
        (self.p.files.len() - 1) as u32
    }

    fn file_for_string(&mut self, id: Id) -> Option<u32> {
        if let Some(f) = self.file_of_string.get(&id) {
            return Some(*f);
        }
        let name = self.strings.get(&id)?.clone();
        let f = self.add_file(&name);
        self.file_of_string.insert(id, f);
        Some(f)
    }

    fn const_u32(&self, id: Option<Id>) -> u32 {
        id.and_then(|id| self.p.const_u64(id)).unwrap_or(0) as u32
    }

    /// Position from a debug instruction's (source, line, column) operands.
    fn dbg_pos(
        &self,
        inst: &dr::Instruction,
        source: usize,
        line: usize,
        col: usize,
    ) -> Option<SrcPos> {
        let file = *self.dbg_sources.get(&id_at(inst, source)?)?;
        let line = self.const_u32(id_at(inst, line));
        let column = self.const_u32(id_at(inst, col));
        Some(SrcPos {
            file,
            line,
            column,
            end_line: line,
            end_column: column,
        })
    }

    /// Module-level pass: names, decorations, types, constants, globals, entry
    /// points, debug info, and the source position of every instruction.
    fn collect(&mut self) -> Result<(), InputError> {
        self.p.locs = vec![None; self.p.insts.len()];
        // The maps sized once, not grown as they fill.
        let (mut names, mut member_names, mut decorated, mut types, mut constants) =
            (0, 0, 0, 0, 0);
        for inst in &self.p.insts {
            match inst.class.opcode {
                Op::Name => names += 1,
                Op::MemberName => member_names += 1,
                Op::Decorate => decorated += 1,
                op if op.is_type() => types += 1,
                op if op.is_constant() => constants += 1,
                _ => {}
            }
        }
        self.p.names.reserve(names);
        self.p.member_names.reserve(member_names);
        self.p.decorations.reserve(decorated);
        self.p.types.reserve(types);
        self.p.constants.reserve(constants);
        // Taken out while read, not cloned per instruction; put back on
        // every path out.
        let insts = std::mem::take(&mut self.p.insts);
        let result = self.collect_from(&insts);
        self.p.insts = insts;
        result
    }

    fn collect_from(&mut self, insts: &[dr::Instruction]) -> Result<(), InputError> {
        let mut cur: Option<SrcPos> = None;
        let mut last_source_file: Option<u32> = None;
        // Module-scope variables come before the first OpFunction.
        let mut in_function = false;
        for (i, inst) in insts.iter().enumerate() {
            let op = inst.class.opcode;
            match op {
                Op::String => {
                    if let (Some(r), Some(s)) = (inst.result_id, str_at(inst, 0)) {
                        self.strings.insert(r, s.to_string());
                    }
                }
                Op::Source => {
                    if let Some(Operand::SourceLanguage(l)) = inst.operands.first() {
                        if self.p.language == Language::Spirv {
                            self.p.language = match l {
                                spirv::SourceLanguage::GLSL | spirv::SourceLanguage::ESSL => {
                                    Language::Glsl
                                }
                                spirv::SourceLanguage::HLSL => Language::Hlsl,
                                spirv::SourceLanguage::WGSL => Language::Wgsl,
                                _ => Language::Spirv,
                            };
                        }
                    }
                    if let Some(file_id) = id_at(inst, 2) {
                        let f = self.file_for_string(file_id);
                        if let (Some(f), Some(text)) = (f, str_at(inst, 3)) {
                            self.p.files[f as usize].text = Some(text.to_string());
                        }
                        last_source_file = f;
                    }
                }
                Op::SourceContinued => {
                    if let (Some(f), Some(s)) = (last_source_file, str_at(inst, 0)) {
                        if let Some(t) = &mut self.p.files[f as usize].text {
                            t.push_str(s);
                        }
                    }
                }
                Op::Name => {
                    if let (Some(id), Some(s)) = (id_at(inst, 0), str_at(inst, 1)) {
                        self.p.names.insert(id, s.to_string());
                    }
                }
                Op::MemberName => {
                    if let (Some(id), Some(m), Some(s)) =
                        (id_at(inst, 0), lit_at(inst, 1), str_at(inst, 2))
                    {
                        self.p.member_names.insert((id, m), s.to_string());
                    }
                }
                Op::Decorate => {
                    if let (Some(id), Some(Operand::Decoration(d))) =
                        (id_at(inst, 0), inst.operands.get(1))
                    {
                        let lits = inst.operands[2..].iter().filter_map(lit_of).collect();
                        self.p.decorations.entry(id).or_default().push((*d, lits));
                    }
                }
                Op::MemberDecorate => {
                    if let (Some(id), Some(m), Some(Operand::Decoration(d))) =
                        (id_at(inst, 0), lit_at(inst, 1), inst.operands.get(2))
                    {
                        let lits = inst.operands[3..].iter().filter_map(lit_of).collect();
                        self.p
                            .member_decorations
                            .entry((id, m))
                            .or_default()
                            .push((*d, lits));
                    }
                }
                Op::ExtInstImport => {
                    let set = str_at(inst, 0).unwrap_or("");
                    if set == "NonSemantic.Shader.DebugInfo.100" {
                        self.p.debug_info_set = inst.result_id;
                    }
                    if set.starts_with("NonSemantic.")
                        || set == "OpenCL.DebugInfo.100"
                        || set == "DebugInfo"
                    {
                        self.p.debug_sets.extend(inst.result_id);
                    }
                }
                Op::EntryPoint => {
                    let model = match inst.operands.first() {
                        Some(Operand::ExecutionModel(m)) => *m,
                        _ => return Err(self.at(i, "entry point without an execution model")),
                    };
                    let function = id_at(inst, 1)
                        .ok_or_else(|| self.at(i, "entry point without a function"))?;
                    let name = str_at(inst, 2).unwrap_or("").to_string();
                    let interface = inst.operands[3..]
                        .iter()
                        .filter_map(|o| match o {
                            Operand::IdRef(x) => Some(*x),
                            _ => None,
                        })
                        .collect();
                    self.p.entry_points.push(EntryPoint {
                        function,
                        name,
                        stage: Stage::from_model(model),
                        interface,
                    });
                }
                Op::Line => {
                    let file = id_at(inst, 0).and_then(|f| self.file_for_string(f));
                    if let (Some(file), Some(line), Some(column)) =
                        (file, lit_at(inst, 1), lit_at(inst, 2))
                    {
                        // naga's writer puts `OpLine 1 1` on code that has no
                        // span (its generated helpers): that is no position.
                        let placeholder =
                            self.p.language == Language::Wgsl && line == 1 && column == 1;
                        cur = (!placeholder).then_some(SrcPos {
                            file,
                            line,
                            column,
                            end_line: line,
                            end_column: column,
                        });
                    }
                }
                Op::NoLine | Op::Label | Op::FunctionEnd => cur = None,
                Op::ExtInst
                    if id_at(inst, 0) == self.p.debug_info_set
                        && self.p.debug_info_set.is_some() =>
                {
                    self.debug_ext_inst(i, inst, &mut cur);
                }
                _ => {
                    self.type_or_constant(i, inst, in_function)?;
                }
            }
            in_function |= op == Op::Function;
            // OpLine applies to the instructions after it, up to the block's end.
            if !matches!(op, Op::Line | Op::NoLine) {
                self.p.locs[i] = cur;
            }
            if is_terminator(op) {
                cur = None;
            }
        }
        Ok(())
    }

    fn debug_ext_inst(&mut self, i: usize, inst: &dr::Instruction, cur: &mut Option<SrcPos>) {
        let Some(which) = lit_at(inst, 1).and_then(DebugOp::from_u32) else {
            return;
        };
        // Operands after (set, instruction) are ids; shift by 2.
        let r = inst.result_id.unwrap_or(0);
        match which {
            DebugOp::DebugCompilationUnit => {
                // Version, DWARF version, source, language (a constant id).
                let lang = self.const_u32(id_at(inst, 5));
                if self.p.language == Language::Spirv {
                    self.p.language = match lang {
                        1 | 2 => Language::Glsl,
                        5 => Language::Hlsl,
                        10 => Language::Wgsl,
                        _ => Language::Spirv,
                    };
                }
            }
            DebugOp::DebugSource => {
                if let Some(f) = id_at(inst, 2).and_then(|s| self.file_for_string(s)) {
                    if let Some(text) = id_at(inst, 3).and_then(|t| self.strings.get(&t)).cloned() {
                        self.p.files[f as usize].text = Some(text);
                    }
                    self.dbg_sources.insert(r, f);
                }
            }
            DebugOp::DebugSourceContinued => {
                // Appends to the most recent DebugSource's text.
                if let Some(text) = id_at(inst, 2).and_then(|t| self.strings.get(&t)).cloned() {
                    if let Some(f) = self.dbg_sources.values().max().copied() {
                        if let Some(t) = &mut self.p.files[f as usize].text {
                            t.push_str(&text);
                        }
                    }
                }
            }
            DebugOp::DebugLine => {
                if let Some(file) = id_at(inst, 2)
                    .and_then(|s| self.dbg_sources.get(&s))
                    .copied()
                {
                    let line = self.const_u32(id_at(inst, 3));
                    let end_line = self.const_u32(id_at(inst, 4));
                    let column = self.const_u32(id_at(inst, 5));
                    let end_column = self.const_u32(id_at(inst, 6));
                    *cur = Some(SrcPos {
                        file,
                        line,
                        column,
                        end_line,
                        end_column,
                    });
                }
            }
            DebugOp::DebugNoLine => *cur = None,
            DebugOp::DebugTypeMember => {
                if let Some(pos) = self.dbg_pos(inst, 4, 5, 6) {
                    self.dbg_members.insert(r, pos);
                }
            }
            DebugOp::DebugTypeComposite => {
                let name = id_at(inst, 2).and_then(|s| self.strings.get(&s)).cloned();
                if let (Some(name), Some(pos)) = (name, self.dbg_pos(inst, 4, 5, 6)) {
                    let members = inst.operands.iter().skip(11).filter_map(|o| match o {
                        Operand::IdRef(x) => Some(*x),
                        _ => None,
                    });
                    self.dbg_composites.push((name, pos, members.collect()));
                }
            }
            DebugOp::DebugGlobalVariable => {
                if let (Some(pos), Some(var)) = (self.dbg_pos(inst, 4, 5, 6), id_at(inst, 9)) {
                    self.p.decl_pos.insert(Decl::Var(var), pos);
                }
            }
            DebugOp::DebugFunction => {
                if let Some(pos) = self.dbg_pos(inst, 4, 5, 6) {
                    self.dbg_functions.insert(r, pos);
                }
            }
            DebugOp::DebugFunctionDefinition => {
                if let (Some(df), Some(f)) = (id_at(inst, 2), id_at(inst, 3)) {
                    if let Some(pos) = self.dbg_functions.get(&df) {
                        self.p.decl_pos.insert(Decl::Func(f), *pos);
                    }
                }
            }
            DebugOp::DebugLocalVariable => {
                if let Some(pos) = self.dbg_pos(inst, 4, 5, 6) {
                    self.dbg_locals.insert(r, pos);
                }
            }
            DebugOp::DebugDeclare => {
                if let (Some(local), Some(var)) = (id_at(inst, 2), id_at(inst, 3)) {
                    if let Some(pos) = self.dbg_locals.get(&local) {
                        self.p.decl_pos.insert(Decl::Var(var), *pos);
                    }
                }
            }
            _ => {}
        }
        let _ = i;
    }

    /// Links `DebugTypeComposite`s to `OpTypeStruct`s by name.
    fn link_debug_composites(&mut self) {
        let composites = std::mem::take(&mut self.dbg_composites);
        for (name, pos, members) in composites {
            let structs: Vec<Id> = self
                .p
                .types
                .iter()
                .filter(|(id, t)| {
                    matches!(t, Type::Struct { .. }) && self.p.names.get(id) == Some(&name)
                })
                .map(|(id, _)| *id)
                .collect();
            for s in structs {
                self.p.decl_pos.insert(Decl::Type(s), pos);
                for (k, m) in members.iter().enumerate() {
                    if let Some(mp) = self.dbg_members.get(m) {
                        self.p.decl_pos.insert(Decl::Member(s, k as u32), *mp);
                    }
                }
            }
        }
    }

    fn type_or_constant(
        &mut self,
        i: usize,
        inst: &dr::Instruction,
        in_function: bool,
    ) -> Result<(), InputError> {
        let op = inst.class.opcode;
        let r = inst.result_id.unwrap_or(0);
        if op == Op::TypeForwardPointer {
            // `buffer_reference` structs point to themselves: the pointer type
            // is named before its `OpTypePointer`, which later replaces this.
            if let (Some(ptr), Some(Operand::StorageClass(storage))) =
                (id_at(inst, 0), inst.operands.get(1))
            {
                self.p.types.entry(ptr).or_insert(Type::Pointer {
                    storage: *storage,
                    pointee: 0,
                });
            }
            return Ok(());
        }
        let ty = match op {
            Op::TypeVoid => Some(Type::Void),
            Op::TypeBool => Some(Type::Bool),
            Op::TypeInt => Some(Type::Int {
                width: lit_at(inst, 0).unwrap_or(32),
                signed: lit_at(inst, 1).unwrap_or(0) != 0,
            }),
            Op::TypeFloat => Some(Type::Float {
                width: lit_at(inst, 0).unwrap_or(32),
            }),
            // Counts the spec allows, checked here: analyses size tables by
            // them (a fuzzed count of 2^32 asked for gigabytes).
            Op::TypeVector => {
                let count = lit_at(inst, 1).unwrap_or(0);
                if !matches!(count, 2 | 3 | 4 | 8 | 16) {
                    return Err(self.at(
                        i,
                        format!("vector of {count} components (SPIR-V allows 2, 3, 4, 8 or 16)"),
                    ));
                }
                Some(Type::Vector {
                    elem: self.type_operand(i, inst, 0)?,
                    count,
                })
            }
            Op::TypeMatrix => {
                let columns = lit_at(inst, 1).unwrap_or(0);
                if !matches!(columns, 2..=4) {
                    return Err(self.at(
                        i,
                        format!("matrix of {columns} columns (SPIR-V allows 2 to 4)"),
                    ));
                }
                Some(Type::Matrix {
                    column: self.type_operand(i, inst, 0)?,
                    columns,
                })
            }
            Op::TypeArray => {
                let elem = self.type_operand(i, inst, 0)?;
                let len_id = id_at(inst, 1).ok_or_else(|| self.at(i, "array without a length"))?;
                let len = match (
                    self.p.constants.get(&len_id),
                    self.p.spec_constants.get(&len_id),
                ) {
                    (Some(Constant::Int(v)), _) => ArrayLen::Const(*v),
                    (_, Some(Constant::Int(v))) => ArrayLen::Spec(len_id, Some(*v)),
                    _ => ArrayLen::Spec(len_id, None),
                };
                Some(Type::Array { elem, len })
            }
            Op::TypeRuntimeArray => Some(Type::RuntimeArray {
                elem: self.type_operand(i, inst, 0)?,
            }),
            Op::TypeStruct => {
                let mut members = Vec::new();
                for k in 0..inst.operands.len() {
                    members.push(self.type_operand(i, inst, k)?);
                }
                Some(Type::Struct { members })
            }
            Op::TypePointer => {
                let storage = match inst.operands.first() {
                    Some(Operand::StorageClass(s)) => *s,
                    _ => return Err(self.at(i, "pointer type without a storage class")),
                };
                // Not checked against the types read so far: pointees may be
                // types this reader does not model (a new extension's). But
                // never the pointer itself (a forward-declared pointer could
                // be): naming it recursed without end.
                let pointee =
                    id_at(inst, 1).ok_or_else(|| self.at(i, "pointer type without a pointee"))?;
                if pointee == r {
                    return Err(self.at(i, format!("pointer type %{r} points to itself")));
                }
                Some(Type::Pointer { storage, pointee })
            }
            Op::TypeFunction => {
                let ret = self.type_operand(i, inst, 0)?;
                let mut params = Vec::new();
                for k in 1..inst.operands.len() {
                    params.push(self.type_operand(i, inst, k)?);
                }
                Some(Type::Function { ret, params })
            }
            Op::TypeAccelerationStructureKHR => Some(Type::AccelerationStructure),
            Op::TypeRayQueryKHR => Some(Type::RayQuery),
            // Shader execution reordering's hit object (HLSL `dx::HitObject`),
            // opaque like a ray query; pointers to it are Function locals.
            Op::TypeHitObjectNV | Op::TypeHitObjectEXT => Some(Type::Other("hit object")),
            Op::TypeImage => Some(Type::Image),
            Op::TypeSampler => Some(Type::Sampler),
            Op::TypeSampledImage => Some(Type::SampledImage),
            Op::TypeOpaque
            | Op::TypeEvent
            | Op::TypeDeviceEvent
            | Op::TypeReserveId
            | Op::TypeQueue
            | Op::TypePipe => Some(Type::Other("opaque")),
            _ => None,
        };
        if let Some(t) = ty {
            self.p.types.insert(r, t);
            return Ok(());
        }
        let constant = |b: &Self| -> Option<Constant> {
            Some(match op {
                Op::Constant | Op::SpecConstant => {
                    let ty = b.p.types.get(&inst.result_type?)?;
                    match (ty, inst.operands.first()?) {
                        (Type::Float { width: 32 }, Operand::LiteralBit32(v)) => {
                            Constant::Float(f32::from_bits(*v) as f64)
                        }
                        (Type::Float { width: 64 }, Operand::LiteralBit64(v)) => {
                            Constant::Float(f64::from_bits(*v))
                        }
                        (Type::Float { .. }, _) => Constant::Float(f64::NAN),
                        (_, Operand::LiteralBit32(v)) => Constant::Int(*v as u64),
                        (_, Operand::LiteralBit64(v)) => Constant::Int(*v),
                        _ => return None,
                    }
                }
                Op::ConstantTrue | Op::SpecConstantTrue => Constant::Bool(true),
                Op::ConstantFalse | Op::SpecConstantFalse => Constant::Bool(false),
                Op::ConstantNull => Constant::Null,
                Op::ConstantComposite | Op::SpecConstantComposite => Constant::Composite(
                    inst.operands
                        .iter()
                        .filter_map(|o| match o {
                            Operand::IdRef(x) => Some(*x),
                            _ => None,
                        })
                        .collect(),
                ),
                _ => return None,
            })
        };
        if let Some(c) = constant(self) {
            let spec = matches!(
                op,
                Op::SpecConstant
                    | Op::SpecConstantTrue
                    | Op::SpecConstantFalse
                    | Op::SpecConstantComposite
            );
            if spec {
                self.p.spec_constants.insert(r, c);
            } else {
                self.p.constants.insert(r, c);
            }
            return Ok(());
        }
        if op == Op::Variable && !in_function {
            let storage = match inst.operands.first() {
                Some(Operand::StorageClass(s)) => *s,
                _ => return Err(self.at(i, "variable without a storage class")),
            };
            let ptr = inst.result_type.unwrap_or(0);
            let ty = match self.p.types.get(&ptr) {
                Some(Type::Pointer { pointee, .. }) => *pointee,
                _ => return Err(self.at(i, format!("variable %{r} does not have a pointer type"))),
            };
            let set = self
                .p
                .decoration(r, spirv::Decoration::DescriptorSet)
                .and_then(|v| v.first().copied());
            let binding = self
                .p
                .decoration(r, spirv::Decoration::Binding)
                .and_then(|v| v.first().copied());
            self.p.globals.push(Global {
                id: r,
                name: self.p.names.get(&r).cloned(),
                storage,
                ty,
                set,
                binding,
                inst: i,
            });
        }
        Ok(())
    }

    fn type_operand(&self, i: usize, inst: &dr::Instruction, k: usize) -> Result<Id, InputError> {
        let id = id_at(inst, k).ok_or_else(|| self.at(i, format!("operand {k} is not an id")))?;
        if !self.p.types.contains_key(&id) {
            return Err(self.at(
                i,
                format!("operand %{id} is not a type declared before its use"),
            ));
        }
        Ok(id)
    }

    /// Splits the instruction stream into functions and blocks with successors.
    fn functions(&mut self) -> Result<(), InputError> {
        let n = self.p.insts.len();
        let mut i = 0;
        while i < n {
            if self.p.insts[i].class.opcode != Op::Function {
                i += 1;
                continue;
            }
            let id = self.p.insts[i].result_id.unwrap_or(0);
            let start = i;
            let mut params = Vec::new();
            let mut blocks: Vec<Block> = Vec::new();
            let mut block_start: Option<usize> = None;
            i += 1;
            loop {
                if i >= n {
                    return Err(self.at(start, "function has no OpFunctionEnd"));
                }
                let op = self.p.insts[i].class.opcode;
                match op {
                    Op::FunctionParameter => params.push(self.p.insts[i].result_id.unwrap_or(0)),
                    Op::Label => {
                        if block_start.is_some() {
                            return Err(self.at(i, "block starts before the previous one ends"));
                        }
                        block_start = Some(i);
                    }
                    Op::FunctionEnd => break,
                    Op::Function => {
                        return Err(self.at(i, "function starts inside another function"))
                    }
                    _ if is_terminator(op) => {
                        let s = block_start
                            .take()
                            .ok_or_else(|| self.at(i, "terminator outside a block"))?;
                        blocks.push(Block {
                            label: self.p.insts[s].result_id.unwrap_or(0),
                            start: s,
                            end: i,
                            succs: Vec::new(),
                        });
                    }
                    _ => {}
                }
                i += 1;
            }
            if block_start.is_some() {
                return Err(self.at(i, "block has no terminator"));
            }
            // Successors by label (labels are defined once: `check_ids`).
            let mut f = Function::new(id, self.p.names.get(&id).cloned(), params, start, i, blocks);
            let mut all_succs = Vec::with_capacity(f.blocks.len());
            for block in &f.blocks {
                let term = &self.p.insts[block.end];
                let (branch, cases): ([Option<Id>; 2], &[Operand]) = match term.class.opcode {
                    Op::Branch => ([id_at(term, 0), None], &[]),
                    Op::BranchConditional => ([id_at(term, 1), id_at(term, 2)], &[]),
                    // Every id after the selector: the default and each case's.
                    Op::Switch => ([None, None], term.operands.get(1..).unwrap_or(&[])),
                    _ => ([None, None], &[]),
                };
                let targets =
                    branch
                        .into_iter()
                        .flatten()
                        .chain(cases.iter().filter_map(|o| match o {
                            Operand::IdRef(x) => Some(*x),
                            _ => None,
                        }));
                let mut succs = Vec::new();
                for t in targets {
                    match f.block_by_label(t) {
                        Some(s) => {
                            if !succs.contains(&s) {
                                succs.push(s)
                            }
                        }
                        None => {
                            return Err(self.at(
                                block.end,
                                format!("branch target %{t} is not a block of this function"),
                            ));
                        }
                    }
                }
                all_succs.push(succs);
            }
            for (block, succs) in f.blocks.iter_mut().zip(all_succs) {
                block.succs = succs;
            }
            self.p.functions.push(f);
            i += 1;
        }
        for e in &self.p.entry_points {
            if self.p.function(e.function).is_none() {
                return Err(err(
                    self.path,
                    format!(
                        "entry point `{}` names %{}, which is not a function",
                        e.name, e.function
                    ),
                ));
            }
        }
        Ok(())
    }

    fn sites(&mut self) {
        let mut sites = Vec::new();
        for (fi, f) in self.p.functions.iter().enumerate() {
            for k in f.start..=f.end {
                let inst = &self.p.insts[k];
                let op = inst.class.opcode;
                let kind = match op {
                    Op::TraceRayKHR => SiteKind::TraceRay,
                    Op::ExecuteCallableKHR => SiteKind::ExecuteCallable,
                    Op::ReportIntersectionKHR => SiteKind::ReportIntersection,
                    Op::IgnoreIntersectionKHR => SiteKind::IgnoreIntersection,
                    Op::TerminateRayKHR => SiteKind::TerminateRay,
                    _ if super::is_ray_query_op(op) => SiteKind::RayQuery,
                    _ => continue,
                };
                let o = |n| {
                    id_at(inst, n)
                        .map(|id| self.p.operand_value(id))
                        .unwrap_or(OperandValue::Dynamic(0))
                };
                let (trace, payload, sbt_index) = match kind {
                    SiteKind::TraceRay => (
                        Some(TraceOperands {
                            ray_flags: o(1),
                            cull_mask: o(2),
                            sbt_offset: o(3),
                            sbt_stride: o(4),
                            miss_index: o(5),
                        }),
                        id_at(inst, 10),
                        None,
                    ),
                    SiteKind::ExecuteCallable => (None, id_at(inst, 1), Some(o(0))),
                    SiteKind::RayQuery => (None, id_at(inst, 0), None),
                    _ => (None, None, None),
                };
                sites.push(RtSite {
                    kind,
                    op,
                    function: fi,
                    inst: k,
                    trace,
                    payload,
                    sbt_index,
                });
            }
        }
        self.p.sites = sites;
    }
}

fn lit_of(o: &Operand) -> Option<u32> {
    match o {
        Operand::LiteralBit32(x) => Some(*x),
        Operand::IdRef(x) => Some(*x),
        Operand::BuiltIn(b) => Some(*b as u32),
        _ => None,
    }
}

/// `text.lines().count()`, by counting newlines in one pass (the
/// embedded source is the whole file).
fn line_count(text: &str) -> usize {
    let newlines = text.bytes().filter(|&b| b == b'\n').count();
    newlines + usize::from(!text.is_empty() && !text.ends_with('\n'))
}

pub fn is_terminator(op: Op) -> bool {
    matches!(
        op,
        Op::Branch
            | Op::BranchConditional
            | Op::Switch
            | Op::Return
            | Op::ReturnValue
            | Op::Kill
            | Op::Unreachable
            | Op::TerminateInvocation
            | Op::IgnoreIntersectionKHR
            | Op::TerminateRayKHR
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pointer_module(cycle_through_array: bool) -> Vec<u32> {
        use rspirv::binary::Assemble;
        use rspirv::spirv::{AddressingModel, Capability, MemoryModel, StorageClass};
        let mut b = rspirv::dr::Builder::new();
        b.capability(Capability::Shader);
        b.capability(Capability::PhysicalStorageBufferAddresses);
        b.memory_model(
            AddressingModel::PhysicalStorageBuffer64,
            MemoryModel::GLSL450,
        );
        let u = b.type_int(32, 0);
        let four = b.constant_bit32(u, 4);
        let p = b.id();
        b.type_forward_pointer(p, StorageClass::PhysicalStorageBuffer);
        let pointee = if cycle_through_array {
            b.type_array(p, four)
        } else {
            p
        };
        b.type_pointer(Some(p), StorageClass::PhysicalStorageBuffer, pointee);
        b.module().assemble()
    }

    /// Found by fuzzing: a pointer to itself sent naming into an endless
    /// recursion; now an input error. A cycle through a forward-declared
    /// pointer and an array is legal, and its name is cut short.
    #[test]
    fn types_that_contain_themselves() {
        let path = Path::new("t.spv");
        let e = parse(&pointer_module(false), path, Language::Spirv).unwrap_err();
        assert!(e.to_string().contains("points to itself"), "{e}");
        let p = parse(&pointer_module(true), path, Language::Hlsl).unwrap();
        let ptr = p
            .types
            .iter()
            .find(|(_, t)| matches!(t, Type::Pointer { pointee, .. } if *pointee != 0))
            .map(|(id, _)| *id)
            .unwrap();
        let name = p.type_name(ptr);
        assert!(name.starts_with("ptr<ptr<") && name.contains('…'), "{name}");
    }

    /// Found by fuzzing: rspirv panicked reading an `OpSpecConstantOp` that
    /// performs another `OpSpecConstant*`; now an input error naming it, and
    /// an operation the specification allows still parses.
    #[test]
    fn spec_constant_op_performs_only_what_the_spec_allows() {
        use rspirv::binary::Assemble;
        let module = |op: Op| {
            let mut b = rspirv::dr::Builder::new();
            b.capability(spirv::Capability::Shader);
            b.memory_model(spirv::AddressingModel::Logical, spirv::MemoryModel::GLSL450);
            let u = b.type_int(32, 0);
            let one = b.spec_constant_bit32(u, 1);
            let mut words = b.module().assemble();
            // OpSpecConstantOp %u %id <op> %one %one, by hand: rspirv's
            // builder takes only the operations it knows.
            let id = words[3];
            words[3] += 1;
            words.extend([
                (6 << 16) | Op::SpecConstantOp as u32,
                u,
                id,
                op as u32,
                one,
                one,
            ]);
            words
        };
        let path = Path::new("t.spv");
        for bad in [Op::SpecConstant, Op::SpecConstantOp, Op::Constant] {
            let e = parse(&module(bad), path, Language::Spirv).unwrap_err();
            assert!(
                e.to_string().contains(&format!(
                    "performs Op{bad:?}, which OpSpecConstantOp does not allow"
                )),
                "{e}"
            );
        }
        assert!(parse(&module(Op::IAdd), path, Language::Spirv).is_ok());
    }

    /// Successors by label: each target's block once, in branch order
    /// (a switch's default first); a target in another function is an
    /// input error naming it.
    #[test]
    fn successors_by_label() {
        use rspirv::binary::Assemble;
        use rspirv::dr::Operand as O;
        let module = |stray: bool| {
            let mut b = rspirv::dr::Builder::new();
            b.capability(spirv::Capability::Shader);
            b.memory_model(spirv::AddressingModel::Logical, spirv::MemoryModel::GLSL450);
            let void = b.type_void();
            let boolean = b.type_bool();
            let u = b.type_int(32, 0);
            let yes = b.constant_true(boolean);
            let one = b.constant_bit32(u, 1);
            let fty = b.type_function(void, []);
            let elsewhere = b.id();
            b.begin_function(void, None, spirv::FunctionControl::NONE, fty)
                .unwrap();
            let (a, bb, c) = (b.id(), b.id(), b.id());
            b.begin_block(None).unwrap();
            b.branch_conditional(yes, a, bb, []).unwrap();
            b.begin_block(Some(a)).unwrap();
            b.branch(if stray { elsewhere } else { c }).unwrap();
            b.begin_block(Some(bb)).unwrap();
            b.switch(one, c, [(O::LiteralBit32(1), a), (O::LiteralBit32(2), c)])
                .unwrap();
            b.begin_block(Some(c)).unwrap();
            b.ret().unwrap();
            b.end_function().unwrap();
            b.begin_function(void, None, spirv::FunctionControl::NONE, fty)
                .unwrap();
            b.begin_block(Some(elsewhere)).unwrap();
            b.ret().unwrap();
            b.end_function().unwrap();
            (b.module().assemble(), elsewhere)
        };
        let path = Path::new("t.spv");
        let p = parse(&module(false).0, path, Language::Spirv).unwrap();
        let succs: Vec<Vec<usize>> = p.functions[0]
            .blocks
            .iter()
            .map(|b| b.succs.clone())
            .collect();
        assert_eq!(succs, [vec![1, 2], vec![3], vec![3, 1], vec![]]);
        let (words, elsewhere) = module(true);
        let e = parse(&words, path, Language::Spirv).unwrap_err();
        assert!(
            e.to_string().contains(&format!(
                "branch target %{elsewhere} is not a block of this function"
            )),
            "{e}"
        );
    }

    #[test]
    fn line_count_is_lines_count() {
        for t in [
            "",
            "\n",
            "a",
            "a\n",
            "a\nb",
            "a\r\nb\r\n",
            "\n\n",
            "a\n\nb\n",
            "\r\n\r",
        ] {
            assert_eq!(line_count(t), t.lines().count(), "{t:?}");
        }
    }

    /// glslang 12 `-gV` gives `main` line 0; such positions, and lines past
    /// the end of the file, are dropped rather than relayed.
    #[test]
    fn no_position_on_line_zero_or_past_the_end() {
        let path =
            Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/live/loop_local.rgen.gV.spv");
        let bytes = std::fs::read(&path).unwrap();
        let words = super::super::words_from_bytes(&bytes, &path).unwrap();
        let p = parse(&words, &path, Language::Spirv).unwrap();
        // The module does say line 0 for `main` (DebugFunction's line).
        let zero_line_function = p.insts.iter().any(|i| {
            i.class.opcode == Op::ExtInst
                && lit_at(i, 1) == Some(DebugOp::DebugFunction as u32)
                && id_at(i, 5).and_then(|c| p.const_u64(c)) == Some(0)
        });
        assert!(zero_line_function);
        let lines = std::fs::read_to_string(path.with_file_name("loop_local.rgen"))
            .unwrap()
            .lines()
            .count() as u32;
        let all = p.locs.iter().flatten().chain(p.decl_pos.values());
        for pos in all {
            assert!(pos.line >= 1 && pos.line <= lines, "{pos:?}");
        }
        let main = p
            .functions
            .iter()
            .find(|f| f.name.as_deref() == Some("main"))
            .unwrap();
        assert!(p.decl_location(Decl::Func(main.id)).is_none());
    }

    /// A `-gV` module whose source on disk is shorter than its positions
    /// claim (glslang embeds no text with `-gV`): positions past the end of
    /// the file are dropped.
    #[test]
    fn no_position_past_the_end_of_the_file() {
        let src =
            Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/live/loop_local.rgen.gV.spv");
        let dir = std::env::temp_dir().join(format!("rtlint-past-end-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let spv = dir.join("loop_local.rgen.gV.spv");
        std::fs::copy(&src, &spv).unwrap();
        std::fs::write(dir.join("loop_local.rgen"), "#version 460\n\n\n\n\n").unwrap();
        let words = super::super::words_from_bytes(&std::fs::read(&spv).unwrap(), &spv).unwrap();
        let p = parse(&words, &spv, Language::Spirv).unwrap();
        let full = parse(&words, &src, Language::Spirv).unwrap();
        assert!(full.locs.iter().flatten().any(|l| l.line > 5));
        assert!(p
            .locs
            .iter()
            .flatten()
            .chain(p.decl_pos.values())
            .all(|l| l.line <= 5));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
