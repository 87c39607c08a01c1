//! How a layout is taken from the Rust types themselves: [`FieldType`] for every type a
//! payload field may have, and the `layout!` macro that declares a struct's layout from its
//! field names with `offset_of!`.

use super::description::{Field, FieldKind, Prim, StructLayout};

/// A Rust type a payload field may have: a primitive, a nested payload struct, or a fixed-size
/// array of either. Implemented for exactly those, so a field of any other type does not compile
/// into a layout.
pub trait FieldType {
    /// Type of one element.
    const KIND: FieldKind;
    /// Array length, `None` for a single element.
    const COUNT: Option<usize>;
}

macro_rules! prim_field_type {
    ($($ty:ty => $prim:ident),+ $(,)?) => {
        $(impl FieldType for $ty {
            const KIND: FieldKind = FieldKind::Prim(Prim::$prim);
            const COUNT: Option<usize> = None;
        })+
    };
}

prim_field_type! {
    u8 => U8, i8 => I8, u16 => U16, i16 => I16, u32 => U32, i32 => I32,
    u64 => U64, i64 => I64, f32 => F32, f64 => F64,
}

impl<T: FieldType, const N: usize> FieldType for [T; N] {
    // Arrays of arrays do not occur in payloads; the inner length would be lost here, which the
    // layout test would catch as a size mismatch.
    const KIND: FieldKind = T::KIND;
    const COUNT: Option<usize> = Some(N);
}

/// Builds the [`Field`] of `S`'s field that `_get` reads; only the types matter, the function is
/// never called: it lets the compiler infer the field's type from its name.
pub(super) const fn field_of<S, F: FieldType>(
    name: &'static str,
    rust_name: &'static str,
    offset: usize,
    _get: fn(&S) -> &F,
) -> Field {
    Field {
        name,
        rust_name,
        kind: F::KIND,
        count: F::COUNT,
        offset,
        size: size_of::<F>(),
    }
}

/// Declares the layout of a `#[repr(C)]` struct from its field names:
///
/// ```text
/// layout! {
///     /// Doc.
///     pub static NAME: RustType = "RosName" { field_a, _pad as pad0, field_b }
/// }
/// ```
///
/// lists every field in declaration order (`as` renames one in the ROS 2 definition); the macro
/// destructures the struct without `..`, so leaving a field out does not compile. A nested struct
/// type also gets its [`FieldType`] impl, so that other layouts can hold it.
macro_rules! layout {
    ($(
        $(#[$meta:meta])*
        $vis:vis static $name:ident: $ty:ident = $ros:literal {
            $($field:ident $(as $ros_field:ident)?),+ $(,)?
        }
    )+) => {$(
        $(#[$meta])*
        $vis static $name: StructLayout = StructLayout {
            ros_name: $ros,
            type_name: concat!("rins::", stringify!($ty)),
            size: size_of::<$ty>(),
            align: align_of::<$ty>(),
            fields: &[$(
                field_of(
                    layout!(@name $field $($ros_field)?),
                    stringify!($field),
                    core::mem::offset_of!($ty, $field),
                    |s: &$ty| &s.$field,
                ),
            )+],
        };

        // Every field listed: a destructuring pattern without `..` must name them all.
        const _: () = {
            #[allow(dead_code)]
            fn every_field_is_listed(s: $ty) {
                let $ty { $($field: _),+ } = s;
            }
        };

        impl FieldType for $ty {
            const KIND: FieldKind = FieldKind::Nested(&$name);
            const COUNT: Option<usize> = None;
        }
    )+};
    (@name $field:ident) => { stringify!($field) };
    (@name $field:ident $ros_field:ident) => { stringify!($ros_field) };
}

pub(crate) use layout;

/// `T`'s layout: the one its [`FieldType`] impl (written by `layout!`) points to. Only for a
/// struct with a layout; for a primitive it fails to compile where it is evaluated.
pub const fn layout_of<T: FieldType>() -> &'static StructLayout {
    match T::KIND {
        FieldKind::Nested(layout) => layout,
        FieldKind::Prim(_) => panic!("a primitive has no struct layout"),
    }
}
