//! The ROS 2 message definition (`.msg` text, schema encoding `ros2msg`) written from a layout.

use super::description::{FieldKind, StructLayout};

/// The ROS 2 message definition of `layout` (schema encoding `ros2msg`): its own fields, then
/// every nested type it uses, each once, after a line of 80 `=` and `MSG: rins/Type` (the
/// concatenated-definition form that ROS 2 bag tools and Foxglove read).
pub fn ros2msg(layout: &StructLayout) -> String {
    let mut text = String::new();
    write_fields(layout, &mut text);
    let mut nested: Vec<&'static StructLayout> = Vec::new();
    collect_nested(layout, &mut nested);
    for inner in nested {
        text.push_str(&"=".repeat(80));
        text.push('\n');
        text.push_str(&format!("MSG: {}\n", inner.ros_type_ref()));
        write_fields(inner, &mut text);
    }
    text
}

fn write_fields(layout: &StructLayout, text: &mut String) {
    for field in layout.fields {
        let ty = match field.kind {
            FieldKind::Prim(prim) => prim.ros_name().to_string(),
            FieldKind::Nested(inner) => inner.ros_type_ref(),
        };
        match field.count {
            Some(n) => text.push_str(&format!("{ty}[{n}] {}\n", field.name)),
            None => text.push_str(&format!("{ty} {}\n", field.name)),
        }
    }
}

/// Nested types in first-use order, depth first, each once.
pub(super) fn collect_nested(layout: &StructLayout, out: &mut Vec<&'static StructLayout>) {
    for field in layout.fields {
        if let FieldKind::Nested(inner) = field.kind
            && !out.iter().any(|l| core::ptr::eq(*l, inner))
        {
            out.push(inner);
            collect_nested(inner, out);
        }
    }
}
