//! `rtlint layout` in words and as JSON.

use crate::analysis::layout::{FileLayouts, TypeLayout, EXACT_ORDER_LIMIT};
use crate::explain;
use crate::shader::Language;

/// The reordered declaration to paste, when the type is a struct whose
/// optimal order was searched.
pub fn optimal_declaration(language: Language, t: &TypeLayout) -> Option<String> {
    let order = t.optimal_indices.as_ref().filter(|_| t.is_struct)?;
    Some(explain::struct_declaration(
        language, &t.name, order, &t.members,
    ))
}

/// The JSON form: the layouts with each struct's reordered declaration.
pub fn json(layouts: &FileLayouts) -> serde_json::Value {
    let mut v = serde_json::to_value(layouts).unwrap_or_default();
    if let Some(types) = v.get_mut("types").and_then(|t| t.as_array_mut()) {
        for (jt, t) in types.iter_mut().zip(&layouts.types) {
            if let Some(o) = jt.as_object_mut() {
                o.insert(
                    "optimal_declaration".into(),
                    optimal_declaration(layouts.language, t).into(),
                );
            }
        }
    }
    v
}

pub fn human(layouts: &FileLayouts) -> String {
    let this = layouts;
    let mut s = format!("{} ({})\n", this.path, this.language.as_str());
    if this.types.is_empty() {
        s.push_str(
            "  no payload, attribute, callable-data, shader-record or push-constant types\n\n",
        );
    }
    for t in &this.types {
        let roles: Vec<String> = t
            .roles
            .iter()
            .map(|r| {
                serde_json::to_value(r)
                    .ok()
                    .and_then(|v| v.as_str().map(String::from))
                    .unwrap_or_default()
            })
            .collect();
        s.push_str(&format!(
            "  {}  [{}]  variables: {}\n",
            t.name,
            roles.join(", "),
            t.variables.join(", ")
        ));
        let mut sizes = format!(
            "    scalar {} B · HLSL 16-byte packed {} B in {} row{} ({} B padding)",
            t.scalar_size,
            t.hlsl_packed_size,
            t.hlsl_rows,
            if t.hlsl_rows == 1 { "" } else { "s" },
            t.hlsl_padding
        );
        if let Some(w) = t.wgsl_size {
            sizes.push_str(&format!(" · WGSL {w} B"));
        }
        s.push_str(&sizes);
        s.push('\n');
        let wgsl = t.wgsl_size.is_some();
        let name_w = t
            .members
            .iter()
            .map(|m| m.name.len())
            .max()
            .unwrap_or(4)
            .max(6);
        let ty_w = t
            .members
            .iter()
            .map(|m| m.ty.len())
            .max()
            .unwrap_or(4)
            .max(4);
        s.push_str(&format!(
            "    {:<name_w$}  {:<ty_w$}  {:>4}  {:>6}  {:>6}  {:>3}{}  straddles\n",
            "member",
            "type",
            "size",
            "scalar",
            "packed",
            "row",
            if wgsl { "    wgsl" } else { "" }
        ));
        for m in &t.members {
            s.push_str(&format!(
                "    {:<name_w$}  {:<ty_w$}  {:>4}  {:>6}  {:>6}  {:>3}{}  {}\n",
                m.name,
                m.ty,
                m.size,
                m.scalar_offset,
                m.hlsl_packed_offset,
                m.row,
                m.wgsl_offset
                    .map(|o| format!("  {o:>6}"))
                    .unwrap_or_default(),
                if m.straddles { "yes" } else { "" }
            ));
        }
        match (
            &t.optimal_order,
            t.optimal_hlsl_packed_size,
            t.optimal_hlsl_rows,
        ) {
            (Some(order), Some(size), Some(rows)) if t.is_struct => {
                if size < t.hlsl_packed_size {
                    s.push_str(&format!(
                        "    optimal order: {} → {size} B in {rows} row{}\n",
                        order.join(", "),
                        if rows == 1 { "" } else { "s" }
                    ));
                    if let Some(d) = optimal_declaration(this.language, t) {
                        for line in d.lines() {
                            s.push_str(&format!("      {line}\n"));
                        }
                    }
                } else {
                    s.push_str("    optimal order: as declared\n");
                }
            }
            (None, _, _) if t.is_struct => s.push_str(&format!(
                "    optimal order: not searched (more than {EXACT_ORDER_LIMIT} members)\n"
            )),
            _ => {}
        }
        s.push('\n');
    }
    s
}
