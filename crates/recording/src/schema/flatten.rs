//! A layout flattened to its primitive elements, each with its path and offset from the start
//! of the payload.

use super::description::{FieldKind, Prim, StructLayout};

/// One primitive element of a flattened layout: where it lies from the start of the payload.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FlatPrim {
    /// Dotted path with array indices, e.g. `services[2].pid`.
    pub path: String,
    /// Its type.
    pub prim: Prim,
    /// Offset from the start of the payload, bytes.
    pub offset: usize,
}

/// Every primitive element of `layout` in offset order, arrays and nested structs expanded: what
/// a CDR reader walks, and what the layout test checks for gaps and alignment.
pub fn flatten(layout: &StructLayout) -> Vec<FlatPrim> {
    let mut out = Vec::new();
    flatten_into(layout, 0, "", &mut out);
    out
}

fn flatten_into(layout: &StructLayout, base: usize, prefix: &str, out: &mut Vec<FlatPrim>) {
    for field in layout.fields {
        let elem = field.kind.size();
        let indices: Vec<Option<usize>> = match field.count {
            Some(n) => (0..n).map(Some).collect(),
            None => vec![None],
        };
        for index in indices {
            let path = match index {
                Some(i) => format!("{prefix}{}[{i}]", field.name),
                None => format!("{prefix}{}", field.name),
            };
            let offset = base + field.offset + index.unwrap_or(0) * elem;
            match field.kind {
                FieldKind::Prim(prim) => out.push(FlatPrim { path, prim, offset }),
                FieldKind::Nested(inner) => flatten_into(inner, offset, &format!("{path}."), out),
            }
        }
    }
}
