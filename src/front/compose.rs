//! WGSL written for composition (`#import`, `#define_import_path`,
//! `#ifdef`…), composed into one module by the `naga_oil` crate.
//!
//! Modules are found by their `#define_import_path` in the `.wgsl` files of
//! the shader's own folder and the include directories (`-I`, `[hlsl]
//! include-dirs`), below them too; defines (`-D`, `[hlsl] defines`) are
//! naga_oil's shader defs. Positions: naga_oil keeps the line structure of
//! each file it preprocesses and prefixes it with a generated header, so the
//! composed module's spans in the shader itself are mapped back to its own
//! lines (through a marker constant appended to it); spans inside imported
//! modules are dropped, and findings there are reported at the call in the
//! shader (as for any site without a position).

use crate::diag::{InputError, InputErrorKind};
use naga_oil::compose::{
    preprocess::Preprocessor, ComposableModuleDescriptor, Composer, NagaModuleDescriptor,
    ShaderDefValue, ShaderLanguage, ShaderType,
};
use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};

/// The constant appended to the shader, to find where its text starts in the
/// composed source.
const MARKER: &str = "rtlint_compose_origin";

/// naga_oil's span layout: the module index above bit 21, the offset below.
const SPAN_SHIFT: u32 = 21;

fn defs(defines: &[(String, String)]) -> HashMap<String, ShaderDefValue> {
    defines
        .iter()
        .map(|(n, v)| {
            let v = v.trim();
            let value = match v {
                "true" | "" => ShaderDefValue::Bool(true),
                "false" => ShaderDefValue::Bool(false),
                _ => match (v.parse::<i32>(), v.strip_suffix('u').map(str::parse::<u32>)) {
                    (Ok(i), _) => ShaderDefValue::Int(i),
                    (_, Some(Ok(u))) => ShaderDefValue::UInt(u),
                    _ => ShaderDefValue::Bool(true),
                },
            };
            (n.clone(), value)
        })
        .collect()
}

/// Every `.wgsl` file below `roots` that names itself with
/// `#define_import_path`: import path → (file, text).
fn index(roots: &[PathBuf]) -> HashMap<String, (PathBuf, String)> {
    let mut found = HashMap::new();
    let mut seen = HashSet::new();
    let mut stack: Vec<(PathBuf, u32)> = roots.iter().map(|r| (r.clone(), 0)).collect();
    while let Some((dir, depth)) = stack.pop() {
        if depth > 16 || !seen.insert(std::fs::canonicalize(&dir).unwrap_or(dir.clone())) {
            continue;
        }
        let Ok(entries) = std::fs::read_dir(&dir) else {
            continue;
        };
        let mut entries: Vec<PathBuf> = entries.flatten().map(|e| e.path()).collect();
        entries.sort();
        for p in entries {
            if p.is_dir() {
                stack.push((p, depth + 1));
            } else if p.extension().is_some_and(|e| e == "wgsl") {
                let Ok(text) = std::fs::read_to_string(&p) else {
                    continue;
                };
                if let (Some(name), _, _) = naga_oil::compose::get_preprocessor_data(&text) {
                    found.entry(name).or_insert((p, text));
                }
            }
        }
    }
    found
}

/// The module an import names: `a::b::item` is item `item` of module `a::b`
/// when no module is called `a::b::item`.
fn module_of<'a>(
    import: &str,
    modules: &'a HashMap<String, (PathBuf, String)>,
) -> Option<(&'a String, &'a (PathBuf, String))> {
    let mut name = import;
    loop {
        if let Some(kv) = modules.get_key_value(name) {
            return Some(kv);
        }
        name = &name[..name.rfind("::")?];
    }
}

/// Composes `source` (the file at `path`) into one naga module whose spans
/// lie in `source`.
pub fn compose(
    source: &str,
    path: &Path,
    include_dirs: &[PathBuf],
    defines: &[(String, String)],
) -> Result<naga::Module, InputError> {
    let own = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let roots: Vec<PathBuf> = std::iter::once(own.to_path_buf())
        .chain(include_dirs.iter().cloned())
        .collect();
    let modules = index(&roots);
    let shader_defs = defs(defines);
    let mut composer = Composer::default().with_capabilities(naga::valid::Capabilities::all());
    // rtlint validates the composed module itself, with its own messages.
    composer.validate = false;
    // naga_oil's own report (its codespan text, with the position in the
    // file at fault) as a note under a one-line message.
    let error = |e: naga_oil::compose::ComposerError, composer: &Composer| {
        InputError::new(
            InputErrorKind::WgslParse,
            path,
            format!("cannot compose this module: {}", e.inner),
        )
        .with_note(e.emit_to_string(composer).trim().to_string())
    };
    // Dependencies first: naga_oil needs a module's imports added before it.
    let mut order: Vec<&String> = Vec::new();
    let mut visiting = HashSet::new();
    fn visit<'a>(
        text: &str,
        modules: &'a HashMap<String, (PathBuf, String)>,
        order: &mut Vec<&'a String>,
        visiting: &mut HashSet<&'a String>,
    ) {
        let (_, imports, _) = naga_oil::compose::get_preprocessor_data(text);
        for i in imports {
            if let Some((name, (_, text))) = module_of(&i.import, modules) {
                if visiting.insert(name) {
                    visit(text, modules, order, visiting);
                    order.push(name);
                }
            }
        }
    }
    visit(source, &modules, &mut order, &mut visiting);
    for name in order {
        let (file, text) = &modules[name];
        let file_path = file.display().to_string();
        let added = composer.add_composable_module(ComposableModuleDescriptor {
            source: text,
            file_path: &file_path,
            language: ShaderLanguage::Wgsl,
            as_name: None,
            additional_imports: &[],
            shader_defs: shader_defs.clone(),
        });
        if let Err(e) = added {
            return Err(error(e, &composer));
        }
    }
    let marked = format!("{source}\nconst {MARKER}: u32 = 0u;\n");
    let file_path = path.display().to_string();
    let made = composer.make_naga_module(NagaModuleDescriptor {
        source: &marked,
        file_path: &file_path,
        shader_type: ShaderType::Wgsl,
        shader_defs: shader_defs.clone(),
        additional_imports: &[],
    });
    let mut module = match made {
        Ok(m) => m,
        Err(e) => return Err(error(e, &composer)),
    };
    // The shader's text as naga_oil parsed it (after its preprocessor), to
    // tell lines from offsets.
    let pre = Preprocessor::default();
    let unprocessed = |e: naga_oil::compose::ComposerErrorInner| {
        InputError::new(
            InputErrorKind::WgslParse,
            path,
            format!("cannot preprocess this module: {e}"),
        )
    };
    let meta = pre
        .get_preprocessor_metadata(&marked, true)
        .map_err(unprocessed)?;
    let mut all = shader_defs.clone();
    all.extend(meta.defines);
    let preprocessed = pre
        .preprocess(&meta.cleaned_source, &all)
        .map_err(unprocessed)?
        .preprocessed_source;
    remap_spans(&mut module, source, &preprocessed);
    Ok(module)
}

/// Moves the composed module's spans into `source`: those of the shader's
/// own text by line (column kept where the line is long enough), every other
/// span dropped.
fn remap_spans(module: &mut naga::Module, source: &str, preprocessed: &str) {
    let marker_const = module
        .constants
        .iter()
        .find(|(_, c)| c.name.as_deref() == Some(MARKER))
        .map(|(h, _)| module.constants.get_span(h));
    let origin = marker_const.and_then(|span| {
        let at = preprocessed.rfind(&format!("const {MARKER}"))?;
        let start = span.to_range()?.start;
        if start >> SPAN_SHIFT != 0 {
            return None;
        }
        // naga's span of a constant declaration starts at `const`.
        start.checked_sub(at)
    });
    let line_starts: Vec<usize> = std::iter::once(0)
        .chain(source.match_indices('\n').map(|(i, _)| i + 1))
        .collect();
    let map = |span: naga::Span| -> naga::Span {
        let (Some(origin), Some(r)) = (origin, span.to_range()) else {
            return naga::Span::default();
        };
        if r.start >> SPAN_SHIFT != 0 {
            return naga::Span::default();
        }
        let one = |o: usize| -> Option<usize> {
            let o = (o & ((1 << SPAN_SHIFT) - 1)).checked_sub(origin)?;
            let o = o.min(preprocessed.len());
            if !preprocessed.is_char_boundary(o) {
                return None;
            }
            let before = &preprocessed[..o];
            let line = before.matches('\n').count();
            let col = o - before.rfind('\n').map(|i| i + 1).unwrap_or(0);
            let start = *line_starts.get(line)?;
            let end = line_starts
                .get(line + 1)
                .map(|e| e - 1)
                .unwrap_or(source.len());
            let mut at = (start + col).min(end);
            while !source.is_char_boundary(at) {
                at -= 1;
            }
            Some(at)
        };
        match (one(r.start), one(r.end)) {
            (Some(s), Some(e)) if s <= e => naga::Span::new(s as u32, e as u32),
            (Some(s), _) => naga::Span::new(s as u32, s as u32),
            _ => naga::Span::default(),
        }
    };
    // Types: a UniqueArena has no mutable spans; rebuilt in order, every
    // handle stays the same.
    let mut types = naga::UniqueArena::new();
    for (h, t) in module.types.iter() {
        types.insert(t.clone(), map(module.types.get_span(h)));
    }
    module.types = types;
    rebuild(&mut module.constants, &map);
    rebuild(&mut module.global_variables, &map);
    rebuild(&mut module.overrides, &map);
    rebuild(&mut module.global_expressions, &map);
    rebuild(&mut module.functions, &map);
    let function = |f: &mut naga::Function| {
        rebuild(&mut f.expressions, &map);
        rebuild(&mut f.local_variables, &map);
        block(&mut f.body, &map);
    };
    for (_, f) in module.functions.iter_mut() {
        function(f);
    }
    for ep in &mut module.entry_points {
        function(&mut ep.function);
    }
}

/// An arena's spans are read-only: rebuilt in order, every handle stays.
fn rebuild<T: Clone>(arena: &mut naga::Arena<T>, map: &impl Fn(naga::Span) -> naga::Span) {
    let mut out = naga::Arena::new();
    for (h, v) in arena.iter() {
        out.append(v.clone(), map(arena.get_span(h)));
    }
    *arena = out;
}

fn block(b: &mut naga::Block, map: &impl Fn(naga::Span) -> naga::Span) {
    for (statement, span) in b.span_iter_mut() {
        if let Some(span) = span {
            *span = map(*span);
        }
        match statement {
            naga::Statement::Block(inner) => block(inner, map),
            naga::Statement::If { accept, reject, .. } => {
                block(accept, map);
                block(reject, map);
            }
            naga::Statement::Switch { cases, .. } => {
                for case in cases {
                    block(&mut case.body, map);
                }
            }
            naga::Statement::Loop {
                body, continuing, ..
            } => {
                block(body, map);
                block(continuing, map);
            }
            _ => {}
        }
    }
}
