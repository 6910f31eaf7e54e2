//! WGSL through naga: parse, validate with every capability, write SPIR-V with
//! debug info so each instruction carries its WGSL line and column.

use crate::diag::{InputError, InputErrorKind};
use crate::program::NamedDecl;
use crate::shader::{line_col, Location};
use naga::back::spv;
use naga::valid::{Capabilities, ValidationFlags, Validator};
use std::path::Path;

/// Opcodes of the instructions [`restore_positions`] rewrites.
const OP_SOURCE_CONTINUED: u32 = 2;
const OP_SOURCE: u32 = 3;

/// SPIR-V version written for WGSL input: 1.4 is the floor for ray tracing.
const SPIRV_VERSION: (u8, u8) = (1, 4);

pub fn parse(
    source: &str,
    path: &Path,
) -> Result<(naga::Module, naga::valid::ModuleInfo), InputError> {
    deep(source, path, || {
        guard(path, "parse", || parse_unguarded(source, path))
    })
}

/// Gives every pipeline-overridable constant (`override`) a value, as a
/// pipeline does before naga can write SPIR-V: the value of a `-D NAME=VALUE`
/// (or `[hlsl.defines]`) naming the override (by name, or by its `@id`),
/// else its default. An override with neither is an input error, since any
/// value rtlint chose could be wrong. `None`: the module has none.
pub fn apply_overrides(
    module: &naga::Module,
    info: &naga::valid::ModuleInfo,
    source: &str,
    defines: &[(String, String)],
    path: &Path,
) -> Result<Option<(naga::Module, naga::valid::ModuleInfo)>, InputError> {
    if module.overrides.is_empty() {
        return Ok(None);
    }
    let mut constants = naga::back::PipelineConstants::default();
    for (_, o) in module.overrides.iter() {
        let key = match o.id {
            Some(id) => id.to_string(),
            None => o.name.clone().unwrap_or_default(),
        };
        let given = defines
            .iter()
            .rev()
            .find(|(n, _)| *n == key || o.name.as_deref() == Some(n.as_str()));
        let name = o.name.as_deref().unwrap_or(&key);
        match given {
            Some((_, v)) => {
                let value = match v.trim() {
                    "true" => 1.0,
                    "false" => 0.0,
                    t => t.parse::<f64>().map_err(|_| {
                        InputError::new(
                            InputErrorKind::WgslValidation,
                            path,
                            format!("override `{name}`: `{v}` is not a number or boolean"),
                        )
                    })?,
                };
                constants.insert(key, value);
            }
            None if o.init.is_none() => {
                let err = InputError::new(
                    InputErrorKind::WgslValidation,
                    path,
                    format!(
                        "override `{name}` has no default value: give it one with -D {name}=VALUE (or under [hlsl.defines] in rtlint.toml)"
                    ),
                );
                return Err(match override_location(source, name, path) {
                    Some(l) => err.at(l, "declared here"),
                    None => err,
                });
            }
            None => {}
        }
    }
    guard(path, "evaluate the overrides of", || {
        naga::back::pipeline_constants::process_overrides(module, info, None, &constants)
            .map(|(m, i)| Some((m.into_owned(), i.into_owned())))
            .map_err(|e| {
                InputError::new(
                    InputErrorKind::WgslValidation,
                    path,
                    format!("cannot evaluate the module's overrides: {e}"),
                )
            })
    })
}

/// Where an override is declared: naga keeps no span for it, so its name
/// after `override` in the text.
fn override_location(text: &str, name: &str, path: &Path) -> Option<Location> {
    let mut from = 0;
    while let Some(i) = text[from..].find("override") {
        let at = from + i + "override".len();
        let rest = &text[at..];
        let trimmed = rest.trim_start();
        if trimmed.starts_with(name)
            && !trimmed[name.len()..].starts_with(|c: char| c.is_alphanumeric() || c == '_')
        {
            let start = at + (rest.len() - trimmed.len());
            let (line, col) = line_col(text, start);
            return Some(Location::span(path, line, col, name.chars().count() as u32));
        }
        from = at;
    }
    None
}

/// Deepest expression nesting accepted: naga's lowering recurses once per
/// level of an operator chain (`a + b + ...`, `- - x`, `a.b.c`), which its
/// parser does not limit (it does brackets, at 197, and braces, at 126), and
/// overflowing a stack aborts the whole run. 20,000 levels fit
/// [`DEEP_STACK`] with room in a debug build.
pub const MAX_EXPRESSION_DEPTH: usize = 20_000;

/// Above this bound naga runs on a thread of its own with [`DEEP_STACK`];
/// below, on the caller's (a worker thread's 2 MiB hold it in a debug build).
const SHALLOW: usize = 128;

const DEEP_STACK: usize = 256 << 20;

/// Runs `f` (naga over `source`) where its recursion fits: refuses a module
/// nested deeper than [`MAX_EXPRESSION_DEPTH`] at the place it gets there,
/// and gives a deep one a large stack.
fn deep<T: Send>(
    source: &str,
    path: &Path,
    f: impl FnOnce() -> Result<T, InputError> + Send,
) -> Result<T, InputError> {
    let (depth, at) = nesting_bound(source, MAX_EXPRESSION_DEPTH);
    if depth > MAX_EXPRESSION_DEPTH {
        let (line, column) = line_col(source, at);
        let loc = Location::point(path, line, column);
        return Err(InputError::new(
            InputErrorKind::WgslParse,
            path,
            format!("expression nested too deep (more than {MAX_EXPRESSION_DEPTH} levels of operators and brackets)"),
        )
        .at(loc, "nested too deep here"));
    }
    if depth <= SHALLOW {
        return f();
    }
    std::thread::scope(|s| {
        std::thread::Builder::new()
            .stack_size(DEEP_STACK)
            .spawn_scoped(s, f)
            .map_err(|e| {
                InputError::new(
                    InputErrorKind::WgslInternal,
                    path,
                    format!("cannot start a thread for a deeply nested module: {e}"),
                )
            })?
            .join()
            .unwrap_or_else(|p| std::panic::resume_unwind(p))
    })
}

/// Whether the `.` at `i` is a decimal point: the token before it starts
/// with a digit (`1.5`, `0x1.8p3`; not `v1.x`).
fn in_number(b: &[u8], i: usize) -> bool {
    let mut k = i;
    while k > 0 && (b[k - 1].is_ascii_alphanumeric() || b[k - 1] == b'_') {
        k -= 1;
    }
    k < i && b[k].is_ascii_digit()
}

/// An upper bound on the expression nesting of `source` (and the byte where
/// it first passes `limit`): within a statement, each operator character
/// adds a level to the bracket it is in, each open bracket a level, and a
/// comma ends its argument's levels (a long list stays shallow). Comments
/// are skipped; a decimal point is not an operator.
fn nesting_bound(source: &str, limit: usize) -> (usize, usize) {
    let n = nesting(source, limit);
    (n.bound, n.bound_at)
}

/// What [`nesting_bound`] finds, and where brackets nest deepest.
struct Nesting {
    bound: usize,
    /// Where `bound` first passed the limit.
    bound_at: usize,
    /// The first open bracket at the deepest bracket nesting.
    deepest_bracket: usize,
}

fn nesting(source: &str, limit: usize) -> Nesting {
    let b = source.as_bytes();
    let (mut brackets, mut deepest, mut deepest_at) = (0usize, 0usize, 0usize);
    // Operators counted in each open bracket (the statement's level first).
    let mut levels: Vec<usize> = vec![0];
    let (mut sum, mut max, mut at) = (0usize, 0usize, 0usize);
    // Bytes the scan looks at; the rest (names, numbers, spaces) are
    // skipped in a tight loop.
    const fn marks() -> [bool; 256] {
        let mut t = [false; 256];
        let s = b"/;{}()[],.+-*%&|^!~<>=";
        let mut k = 0;
        while k < s.len() {
            t[s[k] as usize] = true;
            k += 1;
        }
        t
    }
    const MARKED: [bool; 256] = marks();
    let mut i = 0;
    while i < b.len() {
        if !MARKED[b[i] as usize] {
            i += 1;
            continue;
        }
        let c = b[i];
        match c {
            b'/' if b.get(i + 1) == Some(&b'/') => {
                while i < b.len() && b[i] != b'\n' {
                    i += 1;
                }
                continue;
            }
            b'/' if b.get(i + 1) == Some(&b'*') => {
                // Block comments nest in WGSL.
                let mut open = 0usize;
                while i < b.len() {
                    if b[i] == b'/' && b.get(i + 1) == Some(&b'*') {
                        open += 1;
                        i += 2;
                    } else if b[i] == b'*' && b.get(i + 1) == Some(&b'/') {
                        open -= 1;
                        i += 2;
                        if open == 0 {
                            break;
                        }
                    } else {
                        i += 1;
                    }
                }
                continue;
            }
            b';' | b'{' | b'}' => {
                levels.clear();
                levels.push(0);
                sum = 0;
                brackets = 0;
            }
            b'(' | b'[' => {
                levels.push(0);
                sum += 1;
                brackets += 1;
                if brackets > deepest {
                    deepest = brackets;
                    deepest_at = i;
                }
            }
            b')' | b']' => {
                brackets = brackets.saturating_sub(1);
                if levels.len() > 1 {
                    sum -= levels.pop().unwrap_or(0) + 1;
                }
            }
            b',' => {
                if let Some(last) = levels.last_mut() {
                    sum -= *last;
                    *last = 0;
                }
            }
            b'.' if in_number(b, i) => {}
            b'+' | b'-' | b'*' | b'/' | b'%' | b'&' | b'|' | b'^' | b'!' | b'~' | b'<' | b'>'
            | b'=' | b'.' => {
                if let Some(last) = levels.last_mut() {
                    *last += 1;
                }
                sum += 1;
            }
            _ => {}
        }
        if sum > max {
            max = sum;
            if max > limit && at == 0 {
                at = i;
            }
        }
        i += 1;
    }
    Nesting {
        bound: max,
        bound_at: at,
        deepest_bracket: deepest_at,
    }
}

/// Runs naga, turning a panic inside it into an input error: rtlint reports
/// bad input, it does not crash on it.
fn guard<T>(
    path: &Path,
    what: &str,
    f: impl FnOnce() -> Result<T, InputError>,
) -> Result<T, InputError> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).unwrap_or_else(|payload| {
        let msg = payload
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_default();
        Err(InputError::new(
            InputErrorKind::WgslInternal,
            path,
            format!("naga failed to {what} this module (internal error: {msg})"),
        ))
    })
}

/// Whether `source` uses naga_oil's preprocessor directives.
pub fn is_composable(source: &str) -> bool {
    source.lines().any(|l| {
        let l = l.trim_start();
        l.strip_prefix('#').is_some_and(|d| {
            let d = d.trim_start();
            [
                "import",
                "define_import_path",
                "ifdef",
                "ifndef",
                "if ",
                "else",
                "endif",
                "define ",
            ]
            .iter()
            .any(|k| d.starts_with(k))
        })
    })
}

/// WGSL written for composition (`#import`, `#ifdef`…): composed by
/// naga_oil from the modules in `include_dirs` and the file's folder, with
/// `defines`; then validated as [`parse`] does. Other WGSL: [`parse`].
pub fn parse_composed(
    source: &str,
    path: &Path,
    include_dirs: &[std::path::PathBuf],
    defines: &[(String, String)],
) -> Result<(naga::Module, naga::valid::ModuleInfo), InputError> {
    if !is_composable(source) {
        return parse(source, path);
    }
    #[cfg(not(feature = "naga-oil"))]
    {
        let _ = (include_dirs, defines);
        Err(InputError::new(
            InputErrorKind::UnsupportedLanguage,
            path,
            "this WGSL is written for naga_oil composition (`#import`, `#ifdef`): build rtlint with the `naga-oil` feature",
        ))
    }
    #[cfg(feature = "naga-oil")]
    deep(source, path, || {
        guard(path, "compose", || {
            let module = super::compose::compose(source, path, include_dirs, defines)?;
            let info = Validator::new(ValidationFlags::all(), Capabilities::all())
                .validate(&module)
                .map_err(|e| validation_error(path, source, &e))?;
            Ok((module, info))
        })
    })
}

fn parse_unguarded(
    source: &str,
    path: &Path,
) -> Result<(naga::Module, naga::valid::ModuleInfo), InputError> {
    let module = naga::front::wgsl::parse_str(source).map_err(|e| {
        let mut err = InputError::new(InputErrorKind::WgslParse, path, e.message().to_string());
        let mut labels = e.labels();
        if let Some((span, label)) = labels.next() {
            err = err.at(span_location(path, source, span), label);
        } else if e.notes().any(|n| n.contains("recursion limit")) {
            // naga's parser stops 200 calls deep (brackets, calls, indexing)
            // and says so without a position: point at the deepest bracket.
            let at = nesting(source, usize::MAX).deepest_bracket;
            let (line, column) = line_col(source, at);
            err = InputError::new(
                InputErrorKind::WgslParse,
                path,
                "brackets nested too deep for naga's WGSL parser (it stops at 200 levels of brackets, calls and indexing)",
            )
            .at(Location::point(path, line, column), "nested too deep here");
        }
        for (span, label) in labels {
            err.0.secondary.push(crate::diag::Label::new(
                span_location(path, source, span),
                label,
            ));
        }
        for note in e.notes() {
            err = err.with_note(note);
        }
        err
    })?;
    let info = Validator::new(ValidationFlags::all(), Capabilities::all())
        .validate(&module)
        .map_err(|e| validation_error(path, source, &e))?;
    Ok((module, info))
}

/// Compiles WGSL source to SPIR-V words with `OpString`/`OpLine` debug info.
pub fn compile(source: &str, path: &Path) -> Result<Vec<u32>, InputError> {
    let (mut module, info) = parse(source, path)?;
    write_spirv(&mut module, &info, source, path)
}

/// Source positions of named declarations, which naga's SPIR-V writer does not
/// emit: structs and their members, globals, functions.
pub fn declarations(
    module: &naga::Module,
    source: &str,
    path: &Path,
) -> Vec<(NamedDecl, Location)> {
    let lines = Lines::new(source);
    let fns = fn_names(source);
    let mut out = Vec::new();
    for (handle, ty) in module.types.iter() {
        let (Some(name), naga::TypeInner::Struct { members, .. }) = (&ty.name, &ty.inner) else {
            continue;
        };
        let span = module.types.get_span(handle);
        let Some(range) = span.to_range() else {
            continue;
        };
        let at = find_ident(source, range.start, range.end, name).unwrap_or(range.start);
        out.push((
            NamedDecl::Type(name.clone()),
            lines.location(path, at, name),
        ));
        // Members are found by name inside the struct's body, in order.
        let mut from = source[range.clone()]
            .find('{')
            .map(|b| range.start + b)
            .unwrap_or(range.start);
        for (k, m) in members.iter().enumerate() {
            let Some(mname) = &m.name else { continue };
            if let Some(at) = find_ident(source, from, range.end, mname) {
                out.push((
                    NamedDecl::Member(name.clone(), k as u32),
                    lines.location(path, at, mname),
                ));
                from = at + mname.len();
            }
        }
    }
    for (handle, g) in module.global_variables.iter() {
        if let (Some(name), Some(range)) =
            (&g.name, module.global_variables.get_span(handle).to_range())
        {
            let at = find_ident(source, range.start, range.end, name).unwrap_or(range.start);
            out.push((
                NamedDecl::Global(name.clone()),
                lines.location(path, at, name),
            ));
        }
    }
    for (handle, f) in module.functions.iter() {
        if let (Some(name), Some(range)) = (&f.name, module.functions.get_span(handle).to_range()) {
            let at = find_ident(source, range.start, range.end, name).unwrap_or(range.start);
            out.push((
                NamedDecl::Function(name.clone()),
                lines.location(path, at, name),
            ));
        }
    }
    for ep in &module.entry_points {
        if let Some(at) = find_fn(source, &fns, &ep.name) {
            out.push((
                NamedDecl::Function(ep.name.clone()),
                lines.location(path, at, &ep.name),
            ));
        }
    }
    // Entry-point arguments become input variables of the same name (the
    // builtin `id` of `fn raygen(@builtin(ray_invocation_id) id: …)`); a
    // name used by one entry point only is placed at its argument.
    let mut args: Vec<(&str, &str)> = Vec::new();
    for ep in &module.entry_points {
        for a in &ep.function.arguments {
            if let Some(n) = &a.name {
                args.push((ep.name.as_str(), n.as_str()));
            }
        }
    }
    for &(ep, name) in &args {
        if args.iter().filter(|(_, n)| *n == name).count() > 1
            || module
                .global_variables
                .iter()
                .any(|(_, g)| g.name.as_deref() == Some(name))
        {
            continue;
        }
        let Some(start) = find_fn(source, &fns, ep) else {
            continue;
        };
        let end = source[start..]
            .find('{')
            .map_or(source.len(), |b| start + b);
        if let Some(at) = find_ident(source, start + ep.len(), end, name) {
            out.push((
                NamedDecl::Global(name.to_string()),
                lines.location(path, at, name),
            ));
        }
    }
    out
}

/// Where each line of a source starts: a declaration's position costs a
/// binary search, not a scan from the top of the file.
struct Lines<'a> {
    source: &'a str,
    starts: Vec<usize>,
}

impl<'a> Lines<'a> {
    fn new(source: &'a str) -> Self {
        let starts = std::iter::once(0)
            .chain(source.match_indices('\n').map(|(i, _)| i + 1))
            .collect();
        Lines { source, starts }
    }

    /// [`line_col`], from the index.
    fn line_col(&self, offset: usize) -> (u32, u32) {
        let mut offset = offset.min(self.source.len());
        while !self.source.is_char_boundary(offset) {
            offset -= 1;
        }
        let line = self.starts.partition_point(|&s| s <= offset);
        let line_start = self.starts[line - 1];
        let column = self.source[line_start..offset].chars().count() as u32 + 1;
        (line as u32, column)
    }

    /// The line and the column in bytes of byte `start`, as naga's
    /// `Span::location` counts them.
    fn line_byte_col(&self, start: usize) -> (u32, u32) {
        let start = start.min(self.source.len());
        let line = self.starts.partition_point(|&s| s <= start);
        (line as u32, (start - self.starts[line - 1] + 1) as u32)
    }

    /// The location of `name` written at byte `at`.
    fn location(&self, path: &Path, at: usize, name: &str) -> Location {
        let start = at.min(self.source.len());
        let end = (at + name.len()).clamp(start, self.source.len());
        Location::between(path, self.line_col(start), self.line_col(end))
    }
}

fn is_ident_byte(b: u8) -> bool {
    b.is_ascii_alphanumeric() || b == b'_'
}

/// Byte offset of `name` as a whole identifier in `source[from..to]`.
fn find_ident(source: &str, from: usize, to: usize, name: &str) -> Option<usize> {
    let bytes = source.as_bytes();
    let to = to.min(source.len());
    let mut start = from;
    while start < to {
        let rel = find_str(source.get(start..to)?, name)?;
        let at = start + rel;
        let end = at + name.len();
        let before_ok = at == 0 || !is_ident_byte(bytes[at - 1]);
        let after_ok = end >= bytes.len() || !is_ident_byte(bytes[end]);
        if before_ok && after_ok {
            return Some(at);
        }
        start = at + 1;
    }
    None
}

/// `hay.find(needle)`, by a `memchr` for the needle's first character and a
/// comparison at each hit: the general substring search took a quarter of
/// the declarations' time on short identifiers.
fn find_str(hay: &str, needle: &str) -> Option<usize> {
    let Some(first) = needle.chars().next() else {
        return Some(0);
    };
    let mut from = 0;
    while let Some(k) = hay[from..].find(first) {
        let at = from + k;
        if hay[at..].starts_with(needle) {
            return Some(at);
        }
        from = at + first.len_utf8();
    }
    None
}

/// Where the word after each `fn` keyword starts, in source order: found
/// once per file, not once per entry point and argument.
fn fn_names(source: &str) -> Vec<usize> {
    let mut out = Vec::new();
    let mut from = 0;
    while let Some(at) = find_ident(source, from, source.len(), "fn") {
        let rest = &source[at + 2..];
        out.push(at + 2 + (rest.len() - rest.trim_start().len()));
        from = at + 2;
    }
    out
}

/// Byte offset of the name in `fn name(` (`names` from [`fn_names`]).
fn find_fn(source: &str, names: &[usize], name: &str) -> Option<usize> {
    names.iter().copied().find(|&at| {
        let trimmed = &source[at..];
        trimmed.starts_with(name)
            && !trimmed[name.len()..].starts_with(|c: char| c.is_alphanumeric() || c == '_')
    })
}

/// Writes the module's SPIR-V with `OpSource` (the WGSL text) and an
/// `OpLine` per statement.
///
/// naga's writer finds each `OpLine`'s line by counting the newlines from the
/// top of the source (`Span::location`), which makes writing quadratic in the
/// file's length (two thirds of the writer's time on the repository's
/// shaders, and minutes for a 10 MB file). So the writer is handed statement
/// numbers instead of positions: the `k`th statement of a function gets byte
/// `k` of a blank text with no newline (line 1, column `k + 1`, found by one
/// `memchr` over at most the longest function's statement count), and the
/// words are put back afterwards: each `OpLine` gets the line and column
/// naga writes for the real span, found from its function (by the name the
/// writer gives it) and a line index, and `OpSource` the real text. Where a
/// line cannot be traced back that way (two functions of one name), naga
/// writes from the real text. The module's spans are restored before
/// returning.
pub fn write_spirv(
    module: &mut naga::Module,
    info: &naga::valid::ModuleInfo,
    source: &str,
    path: &Path,
) -> Result<Vec<u32>, InputError> {
    match write_coded(module, info, source, path)? {
        Some(words) => Ok(words),
        None => write_spirv_with(module, info, source, path),
    }
}

/// [`write_spirv`] through statement numbers; `None` where a line cannot be
/// traced back.
fn write_coded(
    module: &mut naga::Module,
    info: &naga::valid::ModuleInfo,
    source: &str,
    path: &Path,
) -> Result<Option<Vec<u32>>, InputError> {
    let mut spans: Vec<Vec<naga::Span>> =
        vec![Vec::new(); module.functions.len() + module.entry_points.len()];
    each_statement_span(module, &mut |function, span| {
        let k = spans[function].len() as u32;
        spans[function].push(*span);
        *span = naga::Span::new(k, k);
    });
    let longest = spans.iter().map(Vec::len).max().unwrap_or(0);
    let blank = " ".repeat(longest + 1);
    let coded = write_spirv_with(module, info, &blank, path);
    // Back in the order they were taken.
    let mut next = vec![0; spans.len()];
    each_statement_span(module, &mut |function, span| {
        *span = spans[function][next[function]];
        next[function] += 1;
    });
    Ok(restore_positions(
        coded?,
        source,
        &function_names(module),
        &spans,
    ))
}

/// Holds [`write_spirv`] to naga's own writer given the text itself: the
/// same words, through the traced path (for the fuzz target and tests;
/// `Ok` for a source naga does not accept).
pub fn check_positions_against_naga(source: &str, path: &Path) -> Result<(), String> {
    let Ok((mut module, info)) = parse(source, path) else {
        return Ok(());
    };
    let direct = write_spirv_with(&module, &info, source, path).map_err(|e| e.to_string());
    let coded = write_coded(&mut module, &info, source, path).map_err(|e| e.to_string());
    match (coded, direct) {
        (Ok(Some(c)), Ok(d)) if c == d => Ok(()),
        (Ok(Some(c)), Ok(d)) => Err(format!(
            "words differ ({} against naga's {}), first at word {}",
            c.len(),
            d.len(),
            c.iter()
                .zip(&d)
                .position(|(a, b)| a != b)
                .unwrap_or(c.len().min(d.len()))
        )),
        (Ok(None), _) => Err("an OpLine was not traced back".into()),
        (Err(a), Err(b)) if a == b => Ok(()),
        (c, d) => Err(format!("one writer failed: {:?} / {:?}", c.err(), d.err())),
    }
}

/// The functions in the order the writer writes them (the module's
/// functions, then its entry points), with the name it gives each.
fn function_names(module: &naga::Module) -> Vec<Option<&str>> {
    let functions = module.functions.iter().map(|(_, f)| f.name.as_deref());
    let entries = module
        .entry_points
        .iter()
        .map(|ep| ep.function.name.as_deref());
    functions.chain(entries).collect()
}

/// Calls `f` with the function's number (as [`function_names`] counts
/// them) and the span of each statement it holds, in a fixed order.
fn each_statement_span(module: &mut naga::Module, f: &mut impl FnMut(usize, &mut naga::Span)) {
    fn block(n: usize, b: &mut naga::Block, f: &mut impl FnMut(usize, &mut naga::Span)) {
        for (statement, span) in b.span_iter_mut() {
            if let Some(span) = span {
                f(n, span);
            }
            match statement {
                naga::Statement::Block(inner) => block(n, inner, f),
                naga::Statement::If { accept, reject, .. } => {
                    block(n, accept, f);
                    block(n, reject, f);
                }
                naga::Statement::Switch { cases, .. } => {
                    for case in cases {
                        block(n, &mut case.body, f);
                    }
                }
                naga::Statement::Loop {
                    body, continuing, ..
                } => {
                    block(n, body, f);
                    block(n, continuing, f);
                }
                _ => {}
            }
        }
    }
    let functions = module.functions.iter_mut().map(|(_, function)| function);
    let entries = module.entry_points.iter_mut().map(|ep| &mut ep.function);
    for (n, function) in functions.chain(entries).enumerate() {
        block(n, &mut function.body, f);
    }
}

/// The words naga wrote with statement numbers for positions (see
/// [`write_spirv`]), with each `OpLine` and the `OpSource` text as naga
/// writes them for `source`; `None` where an `OpLine` cannot be traced to
/// its statement.
fn restore_positions(
    mut words: Vec<u32>,
    source: &str,
    names: &[Option<&str>],
    spans: &[Vec<naga::Span>],
) -> Option<Vec<u32>> {
    const OP_NAME: u32 = 5;
    const OP_LINE: u32 = 8;
    const OP_FUNCTION: u32 = 54;
    const OP_FUNCTION_END: u32 = 56;
    let mut by_name: rustc_hash::FxHashMap<&str, usize> = Default::default();
    for (n, name) in names.iter().enumerate() {
        if let Some(name) = name {
            if by_name.insert(name, n).is_some() {
                return None;
            }
        }
    }
    let lines = Lines::new(source);
    let mut named: rustc_hash::FxHashMap<u32, usize> = Default::default();
    let mut function: Option<usize> = None;
    let mut name_bytes: Vec<u8> = Vec::new();
    // `OpLine`s are mended in place; the `OpSource` (its operands kept
    // for the real text's) and `OpSourceContinued` ranges are replaced
    // afterwards, so the rest of the module is copied in a few pieces,
    // not instruction by instruction.
    let mut replaced: Vec<(usize, usize, Option<[u32; 3]>)> = Vec::new();
    let mut i = 5;
    while i < words.len() {
        let (count, op) = ((words[i] >> 16) as usize, words[i] & 0xffff);
        let end = (i + count.max(1)).min(words.len());
        match op {
            OP_NAME if end - i > 2 => {
                name_bytes.clear();
                name_bytes.extend(words[i + 2..end].iter().flat_map(|w| w.to_le_bytes()));
                let text = name_bytes.split(|&b| b == 0).next().unwrap_or_default();
                if let Some(&n) = std::str::from_utf8(text).ok().and_then(|t| by_name.get(t)) {
                    named.insert(words[i + 1], n);
                }
            }
            OP_FUNCTION if end - i > 2 => function = named.get(&words[i + 2]).copied(),
            OP_FUNCTION_END => function = None,
            OP_LINE if end - i == 4 => {
                let code = words[i + 3].checked_sub(1)? as usize;
                let span = spans.get(function?)?.get(code)?;
                let (line, column) = lines.line_byte_col(span.to_range().map_or(0, |r| r.start));
                words[i + 2] = line;
                words[i + 3] = column;
            }
            OP_SOURCE if end - i > 4 => {
                replaced.push((i, end, Some([words[i + 1], words[i + 2], words[i + 3]])));
            }
            // The blank text's continuation, replaced with the source's.
            OP_SOURCE_CONTINUED => replaced.push((i, end, None)),
            _ => {}
        }
        i = end;
    }
    if replaced.is_empty() {
        return Some(words);
    }
    let mut out = Vec::with_capacity(words.len() + source.len() / 4 + 8);
    let mut from = 0;
    for (start, end, head) in replaced {
        out.extend_from_slice(&words[from..start]);
        if let Some([language, version, file]) = head {
            source_instructions(&mut out, language, version, file, source);
        }
        from = end;
    }
    out.extend_from_slice(&words[from..]);
    Some(out)
}

/// `OpSource` with the text, and `OpSourceContinued` for what does not fit,
/// split as naga splits it: after every 65,535 bytes (at a character
/// boundary) when the text is longer than that, each piece nul-terminated.
fn source_instructions(out: &mut Vec<u32>, language: u32, version: u32, file: u32, text: &str) {
    let limit = u16::MAX as usize;
    let mut pieces = Vec::new();
    if text.len() > limit {
        let mut start = 0;
        while start < text.len() {
            let mut end = (start + limit).min(text.len());
            while !text.is_char_boundary(end) {
                end -= 1;
            }
            pieces.push(&text.as_bytes()[start..end]);
            start = end;
        }
    } else {
        pieces.push(text.as_bytes());
    }
    for (n, piece) in pieces.iter().enumerate() {
        let head: &[u32] = if n == 0 {
            &[language, version, file]
        } else {
            &[]
        };
        let string_words = piece.len() / 4 + 1;
        let count = 1 + head.len() + string_words;
        let op = if n == 0 {
            OP_SOURCE
        } else {
            OP_SOURCE_CONTINUED
        };
        out.push(((count as u32) << 16) | op);
        out.extend_from_slice(head);
        for chunk in piece.chunks(4) {
            let mut b = [0u8; 4];
            b[..chunk.len()].copy_from_slice(chunk);
            out.push(u32::from_le_bytes(b));
        }
        if piece.len() % 4 == 0 {
            out.push(0);
        }
    }
}

fn write_spirv_with(
    module: &naga::Module,
    info: &naga::valid::ModuleInfo,
    source: &str,
    path: &Path,
) -> Result<Vec<u32>, InputError> {
    let file_name = path.to_string_lossy();
    let options = spv::Options {
        lang_version: SPIRV_VERSION,
        flags: spv::WriterFlags::DEBUG | spv::WriterFlags::LABEL_VARYINGS,
        debug_info: Some(spv::DebugInfo {
            source_code: source,
            file_name: &file_name,
            language: naga::back::spv::SourceLanguage::WGSL,
        }),
        // The checks naga wraps around each trace hide the trace's own source
        // position and add a function to every call chain; rtlint analyses what
        // the author wrote.
        trace_ray_argument_validation: false,
        ..Default::default()
    };
    guard(path, "write SPIR-V for", || {
        spv::write_vec(module, info, &options, None).map_err(|e| {
            InputError::new(
                InputErrorKind::WgslSpirvOut,
                path,
                format!("naga could not write SPIR-V for this module: {e}"),
            )
        })
    })
}

fn validation_error(
    path: &Path,
    source: &str,
    e: &naga::WithSpan<naga::valid::ValidationError>,
) -> InputError {
    // naga's own chain of causes is the most precise message it has.
    let mut message = e.as_inner().to_string();
    let mut cause = std::error::Error::source(e.as_inner());
    while let Some(c) = cause {
        message.push_str(": ");
        message.push_str(&c.to_string());
        cause = c.source();
    }
    let mut err = InputError::new(
        InputErrorKind::WgslValidation,
        path,
        format!("invalid WGSL module: {message}"),
    );
    let mut spans = e.spans();
    if let Some((span, label)) = spans.next() {
        err = err.at(span_location(path, source, *span), label.clone());
    }
    for (span, label) in spans {
        err.0.secondary.push(crate::diag::Label::new(
            span_location(path, source, *span),
            label.clone(),
        ));
    }
    err
}

/// Converts a naga byte span into a line/column location.
pub fn span_location(path: &Path, source: &str, span: naga::Span) -> Location {
    let start = span
        .to_range()
        .map(|r| r.start)
        .unwrap_or(0)
        .min(source.len());
    let end = span
        .to_range()
        .map(|r| r.end)
        .unwrap_or(start)
        .clamp(start, source.len());
    Location::between(path, line_col(source, start), line_col(source, end))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bound counts operator chains, prefixes and brackets, not list
    /// items, decimal points or comments.
    #[test]
    fn nesting_bound_counts_chains_not_lists() {
        let bound = |s: &str| nesting_bound(s, usize::MAX).0;
        assert_eq!(bound("let x = a + b + c + d;"), 4);
        assert_eq!(bound("let x = - - - 1.5;"), 4);
        assert_eq!(bound("let x = f(a + b, c);"), 3);
        assert_eq!(bound("let x = array(1.5, -2.5, 3.5, -4.5, 5.5);"), 3);
        assert_eq!(bound("let x = ((1));"), 3);
        assert_eq!(bound("let x = v1.x.y;"), 3);
        assert_eq!(
            bound("let x = 1; // - - - - - -\n/* + /* + */ + */ let y = 2;"),
            1
        );
        // Statements do not add up.
        assert_eq!(bound("let x = a + b; let y = c + d;"), 2);
        // Where it first passes the limit: the third `+`.
        assert_eq!(nesting_bound("let x = a + b + c + d;", 3), (4, 18));
    }

    /// Statement numbers in, positions back: the same words as naga's writer
    /// given the text itself, including a text long enough for
    /// `OpSourceContinued`, multi-byte characters and `\r\n`.
    #[test]
    fn positions_restored_as_naga_writes_them() {
        let body = |i: usize| {
            format!(
                "fn g{i}(x: f32) -> f32 {{\r\n  var y = x; // ü λ\n  \
                 for (var j = 0; j < 3; j++) {{ y = y * 2.0; if y > 4.0 {{ break; }} }}\n  \
                 switch i32(y) {{ case 1: {{ y = 3.0; }} default: {{ y = 1.0; }} }}\n  \
                 loop {{ y += 1.0; continuing {{ break if y > 9.0; }} }}\n  return y;\n}}\n"
            )
        };
        let entry = "@compute @workgroup_size(1)\nfn main() {\n  var z = g0(1.0);\n  \
                     if z > 2.0 { z = g0(z); }\n}\n";
        let small = body(0) + entry;
        let large = format!(
            "/* {} */\n{}{entry}",
            "é".repeat(40_000),
            (0..400).map(body).collect::<String>()
        );
        assert!(large.len() > 2 * u16::MAX as usize);
        for source in [small, large] {
            let path = Path::new("t.wgsl");
            let (mut module, info) = parse(&source, path).unwrap();
            let direct = write_spirv_with(&module, &info, &source, path).unwrap();
            let spans_before: Vec<naga::Span> = {
                let mut v = Vec::new();
                each_statement_span(&mut module, &mut |_, s| v.push(*s));
                v
            };
            assert!(spans_before.len() > 5);
            let coded = write_coded(&mut module, &info, &source, path).unwrap();
            assert_eq!(coded.as_ref(), Some(&direct), "traced back, as naga writes");
            assert_eq!(
                write_spirv(&mut module, &info, &source, path).unwrap(),
                direct
            );
            let mut after = Vec::new();
            each_statement_span(&mut module, &mut |_, s| after.push(*s));
            assert_eq!(after, spans_before, "spans restored");
        }
    }

    /// Every WGSL file of the repository: the traced words are naga's.
    #[test]
    fn repository_wgsl_written_as_naga_writes_it() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let mut files = Vec::new();
        let mut dirs = vec![
            root.join("shaders"),
            root.join("fixtures"),
            root.join("tests"),
        ];
        while let Some(d) = dirs.pop() {
            for e in std::fs::read_dir(&d).unwrap().flatten() {
                let p = e.path();
                if p.is_dir() {
                    dirs.push(p);
                } else if p.extension().is_some_and(|x| x == "wgsl") {
                    files.push(p);
                }
            }
        }
        assert!(files.len() >= 20, "{} WGSL files", files.len());
        for f in files {
            let text = std::fs::read_to_string(&f).unwrap();
            check_positions_against_naga(&text, &f)
                .unwrap_or_else(|e| panic!("{}: {e}", f.display()));
        }
    }

    /// `find_str` answers as `str::find`, for every start and needle,
    /// multi-byte characters included.
    #[test]
    fn find_str_is_str_find() {
        let hay = "fn f(x: f32) -> f32 { let fé = x; return fé; } // fn éfn";
        for needle in [
            "", "f", "fn", "fé", "é", "éfn", "x", "return", "missing", "f32) ->",
        ] {
            for from in (0..=hay.len()).filter(|&k| hay.is_char_boundary(k)) {
                assert_eq!(
                    find_str(&hay[from..], needle),
                    hay[from..].find(needle),
                    "{needle:?} from {from}"
                );
            }
        }
    }

    /// The line index gives what scanning from the top gives, at every byte
    /// (inside multi-byte characters, at `\r\n`, past the end).
    #[test]
    fn line_index_agrees_with_line_col() {
        for source in [
            "",
            "\n",
            "a\r\nbé\n\nfn f() {}\nλx",
            "struct S {\n  a: f32, // ü\n}",
        ] {
            let lines = Lines::new(source);
            for at in 0..=source.len() + 2 {
                assert_eq!(
                    lines.line_col(at),
                    line_col(source, at),
                    "{source:?} at {at}"
                );
            }
        }
    }
}
