//! The plain-data description of a payload's layout: primitive types, fields, nested structs,
//! and the names a ROS 2 definition gives them.

/// A primitive field type of a payload; payloads hold no `bool`, `usize` or Rust enum (enums
/// travel as their `u8` discriminant), so these are all there is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Prim {
    /// `u8`, ROS 2 `uint8`.
    U8,
    /// `i8`, ROS 2 `int8`.
    I8,
    /// `u16`, ROS 2 `uint16`.
    U16,
    /// `i16`, ROS 2 `int16`.
    I16,
    /// `u32`, ROS 2 `uint32`.
    U32,
    /// `i32`, ROS 2 `int32`.
    I32,
    /// `u64`, ROS 2 `uint64`.
    U64,
    /// `i64`, ROS 2 `int64`.
    I64,
    /// `f32`, ROS 2 `float32`.
    F32,
    /// `f64`, ROS 2 `float64`.
    F64,
}

impl Prim {
    /// Size in bytes, which is also the alignment CDR gives it.
    pub const fn size(self) -> usize {
        match self {
            Prim::U8 | Prim::I8 => 1,
            Prim::U16 | Prim::I16 => 2,
            Prim::U32 | Prim::I32 | Prim::F32 => 4,
            Prim::U64 | Prim::I64 | Prim::F64 => 8,
        }
    }

    /// The ROS 2 `.msg` type name.
    pub const fn ros_name(self) -> &'static str {
        match self {
            Prim::U8 => "uint8",
            Prim::I8 => "int8",
            Prim::U16 => "uint16",
            Prim::I16 => "int16",
            Prim::U32 => "uint32",
            Prim::I32 => "int32",
            Prim::U64 => "uint64",
            Prim::I64 => "int64",
            Prim::F32 => "float32",
            Prim::F64 => "float64",
        }
    }

    /// The Rust type name (also the numpy/`struct` spelling a generator may want to map from).
    pub const fn rust_name(self) -> &'static str {
        match self {
            Prim::U8 => "u8",
            Prim::I8 => "i8",
            Prim::U16 => "u16",
            Prim::I16 => "i16",
            Prim::U32 => "u32",
            Prim::I32 => "i32",
            Prim::U64 => "u64",
            Prim::I64 => "i64",
            Prim::F32 => "f32",
            Prim::F64 => "f64",
        }
    }
}

/// What one element of a field is: a primitive, or a nested struct with its own layout.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FieldKind {
    /// A primitive.
    Prim(Prim),
    /// A nested `#[repr(C)]` struct ([`Header`](ipc_types::Header), the parts of a
    /// [`HealthReport`](ipc_types::HealthReport)).
    Nested(&'static StructLayout),
}

impl FieldKind {
    /// Size in bytes of one element.
    pub const fn size(self) -> usize {
        match self {
            FieldKind::Prim(prim) => prim.size(),
            FieldKind::Nested(layout) => layout.size,
        }
    }
}

/// One field of a payload, in declaration (and offset) order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Field {
    /// The field's name in the ROS 2 definition: the Rust name, except for the explicit padding
    /// (`_pad`, `_pad2`), which ROS 2 names may not start with an underscore, and so become
    /// `pad0`, `pad1`.
    pub name: &'static str,
    /// The Rust field name.
    pub rust_name: &'static str,
    /// Type of one element.
    pub kind: FieldKind,
    /// Array length for a fixed-size array field, `None` for a single element.
    pub count: Option<usize>,
    /// Offset from the start of the enclosing struct, bytes (`offset_of!`).
    pub offset: usize,
    /// `size_of` the Rust field's type, bytes: `kind.size() * count`.
    pub size: usize,
}

/// The layout of one `#[repr(C)]` payload or nested struct.
#[derive(Debug, PartialEq, Eq)]
pub struct StructLayout {
    /// The short type name, e.g. `NavState`.
    pub ros_name: &'static str,
    /// The payload's iceoryx2 type name, e.g. `rins::NavState`: what a recording's channel
    /// metadata names, and what a reader looks a layout up by.
    pub type_name: &'static str,
    /// `size_of` the Rust type, bytes.
    pub size: usize,
    /// `align_of` the Rust type, bytes.
    pub align: usize,
    /// Every field, in offset order.
    pub fields: &'static [Field],
}

/// The ROS 2 package every definition belongs to.
pub const ROS_PACKAGE: &str = "rins";

impl StructLayout {
    /// The schema name of a top-level message in the ROS 2 `package/msg/Type` form, e.g.
    /// `rins/msg/NavState`.
    pub fn schema_name(&self) -> String {
        format!("{ROS_PACKAGE}/msg/{}", self.ros_name)
    }

    /// How a field of another definition names this type, e.g. `rins/Header`.
    pub fn ros_type_ref(&self) -> String {
        format!("{ROS_PACKAGE}/{}", self.ros_name)
    }

    /// The field whose Rust name is `rust_name`.
    pub fn field(&self, rust_name: &str) -> Option<&Field> {
        self.fields.iter().find(|f| f.rust_name == rust_name)
    }
}
