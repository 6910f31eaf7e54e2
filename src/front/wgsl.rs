//! WGSL through naga: parse, validate with every capability, write SPIR-V with
//! debug info so each instruction carries its WGSL line and column.

use crate::diag::{InputError, InputErrorKind};
use crate::program::NamedDecl;
use crate::shader::{line_col, Location};
use naga::back::spv;
use naga::valid::{Capabilities, ValidationFlags, Validator};
use std::path::Path;

/// SPIR-V version written for WGSL input: 1.4 is the floor for ray tracing.
const SPIRV_VERSION: (u8, u8) = (1, 4);

pub fn parse(
    source: &str,
    path: &Path,
) -> Result<(naga::Module, naga::valid::ModuleInfo), InputError> {
    guard(path, "parse", || parse_unguarded(source, path))
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

fn parse_unguarded(
    source: &str,
    path: &Path,
) -> Result<(naga::Module, naga::valid::ModuleInfo), InputError> {
    let module = naga::front::wgsl::parse_str(source).map_err(|e| {
        let mut err = InputError::new(InputErrorKind::WgslParse, path, e.message().to_string());
        let mut labels = e.labels();
        if let Some((span, label)) = labels.next() {
            err = err.at(span_location(path, source, span), label);
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
    let (module, info) = parse(source, path)?;
    write_spirv(&module, &info, source, path)
}

/// Source positions of named declarations, which naga's SPIR-V writer does not
/// emit: structs and their members, globals, functions.
pub fn declarations(
    module: &naga::Module,
    source: &str,
    path: &Path,
) -> Vec<(NamedDecl, Location)> {
    let lines = Lines::new(source);
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
        if let Some(at) = find_fn(source, &ep.name) {
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
        let Some(start) = find_fn(source, ep) else {
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
        let rel = source.get(start..to)?.find(name)?;
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

/// Byte offset of the name in `fn name(`.
fn find_fn(source: &str, name: &str) -> Option<usize> {
    let mut from = 0;
    while let Some(at) = find_ident(source, from, source.len(), "fn") {
        let rest = &source[at + 2..];
        let trimmed = rest.trim_start();
        if trimmed.starts_with(name)
            && !trimmed[name.len()..].starts_with(|c: char| c.is_alphanumeric() || c == '_')
        {
            return Some(at + 2 + (rest.len() - trimmed.len()));
        }
        from = at + 2;
    }
    None
}

pub fn write_spirv(
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
