//! The layout of every payload, described once from the Rust types themselves, and the ROS 2
//! message definitions (`.msg` text) written from it.
//!
//! A recording stores each payload's bytes as they are in shared memory. That is only readable by
//! other tools if a schema says where each field lies, and the schema is only right if it is taken
//! from the Rust layout: every [`Field::offset`] here comes from `core::mem::offset_of!`, every
//! element type and array length from the field's Rust type (through [`FieldType`]), so a field
//! that changes type moves its schema with it, and a field added to a payload without being added
//! here does not compile. The tests check the rest: fields follow each other without a gap and
//! fill the payload to its size, and every primitive sits at an offset that is a multiple of its
//! size, which is what lets the raw bytes be read as CDR.
//!
//! The description is plain data ([`StructLayout`], [`Field`], [`Prim`]) so that other generators
//! (a Python `ctypes` mirror, a C header) can be written from it as well.

use ipc_types::{
    Altitude, FaultApplied, FusedImu, FusionControl, FusionReply, GnssFix, Header, Health,
    HealthReport, LinkReport, NavReport, NavState, RawAux, RawBaro, RawImu, RawMag,
    RedundancyReport, ServiceHealth, SimControl, Truth,
};

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
    /// A nested `#[repr(C)]` struct ([`Header`], the parts of a [`HealthReport`]).
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
const fn field_of<S, F: FieldType>(
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

layout! {
    /// [`Header`], nested in every pipeline payload.
    pub static HEADER: Header = "Header" {
        origin_seq, origin_device_time_us, origin_rx_ns, stage_pub_ns,
    }

    /// [`RawImu`], on [`ipc_types::names::RAW_IMU`].
    pub static RAW_IMU: RawImu = "RawImu" {
        version, n_gyro, n_accel, n_temperature, _pad as pad0, status, valid_mask, header,
        gyro_counts, accel_counts, temperature_c,
    }

    /// [`RawBaro`], on [`ipc_types::names::RAW_BARO`].
    pub static RAW_BARO: RawBaro = "RawBaro" {
        version, _pad as pad0, header, pressure_pa, temperature_c, _pad2 as pad1,
    }

    /// [`RawMag`], on [`ipc_types::names::RAW_MAG`].
    pub static RAW_MAG: RawMag = "RawMag" {
        version, _pad as pad0, header, field_ut, _pad2 as pad1,
    }

    /// [`RawAux`], on [`ipc_types::names::RAW_AUX`].
    pub static RAW_AUX: RawAux = "RawAux" {
        version, _pad as pad0, header, foot_pressure, _pad2 as pad1,
    }

    /// [`GnssFix`], on [`ipc_types::names::GNSS`].
    pub static GNSS_FIX: GnssFix = "GnssFix" {
        version, fix_type, satellites, protocol, velocity_valid, accuracy_reported,
        _pad as pad0, header, receiver_time_us, latitude_rad, longitude_rad, altitude_m,
        velocity_ned_mps, horizontal_accuracy_m, vertical_accuracy_m, speed_accuracy_mps, hdop,
    }

    /// [`FusedImu`], on [`ipc_types::names::FUSED_IMU`].
    pub static FUSED_IMU: FusedImu = "FusedImu" {
        version, n_gyro, n_accel, flags, header, rate_rps, specific_force_mps2, rate_var,
        specific_force_var, gyro_state, accel_state, gyro_reason, accel_reason,
        gyro_test_statistic, accel_test_statistic,
    }

    /// [`Altitude`], on [`ipc_types::names::ALTITUDE`].
    pub static ALTITUDE: Altitude = "Altitude" {
        version, valid, _pad as pad0, header, height_m, vertical_speed_mps, height_var,
    }

    /// [`NavState`], on both navigator lanes ([`ipc_types::names::NAV_LANES`]).
    pub static NAV_STATE: NavState = "NavState" {
        version, mode, lane, aiding, header, quaternion, velocity_ned_mps, latitude_rad,
        longitude_rad, altitude_m, covariance_diag, aiding_accepted, aiding_rejected,
        solution_start_seq, gyro_bias_rps, accel_bias_mps2, integrity, _pad as pad0,
        integrity_reasons,
    }

    /// [`Truth`], on [`ipc_types::names::TRUTH`].
    pub static TRUTH: Truth = "Truth" {
        version, _pad as pad0, header, quaternion, velocity_ned_mps, latitude_rad,
        longitude_rad, altitude_m,
    }

    /// [`Health`], on [`ipc_types::names::HEARTBEAT`].
    pub static HEALTH: Health = "Health" {
        version, service, _pad as pad0, pid, now_ns, received, published, crc_errors, lost,
        malformed, duplicates, late, seq_jumps, time_rebases, resync_bytes, reconnects,
        rejected, stale_input_episodes, bytes_received, valid_frames, input_stale,
        last_decode_error, _pad2 as pad1,
    }

    /// [`ServiceHealth`], nested in [`HealthReport`].
    pub static SERVICE_HEALTH: ServiceHealth = "ServiceHealth" {
        service, state, input_stale, _pad as pad0, pid, restarts, heartbeat_age_ms,
        output_rate_hz, _pad2 as pad1,
    }

    /// [`LinkReport`], nested in [`HealthReport`].
    pub static LINK_REPORT: LinkReport = "LinkReport" {
        heard, last_decode_error, _pad as pad0, bytes_received, valid_frames, discarded_bytes,
        crc_errors, malformed, reconnects,
    }

    /// [`RedundancyReport`], nested in [`HealthReport`].
    pub static REDUNDANCY_REPORT: RedundancyReport = "RedundancyReport" {
        heard, n_gyro, n_accel, _pad as pad0, flags, gyro_state, accel_state, gyro_reason,
        accel_reason, gyro_test_statistic, accel_test_statistic, age_ms, _pad2 as pad1,
    }

    /// [`NavReport`], nested in [`HealthReport`].
    pub static NAV_REPORT: NavReport = "NavReport" {
        heard, mode, lane, integrity, aiding, integrity_reasons, age_ms,
    }

    /// [`HealthReport`], on [`ipc_types::names::HEALTH`].
    pub static HEALTH_REPORT: HealthReport = "HealthReport" {
        version, count, _pad as pad0, now_ns, uptime_ms, services, link, redundancy, nav,
    }

    /// [`FaultApplied`], on [`ipc_types::names::SIM_FAULT_APPLIED`].
    pub static FAULT_APPLIED: FaultApplied = "FaultApplied" {
        version, sensor, channel, fault, outcome, _pad as pad0, device_time_us, param,
    }

    /// [`SimControl`], on [`ipc_types::names::SIM_CONTROL`].
    pub static SIM_CONTROL: SimControl = "SimControl" {
        version, sensor, channel, fault, _pad as pad0, param,
    }

    /// [`FusionControl`], on [`ipc_types::names::FUSION_CONTROL`].
    pub static FUSION_CONTROL: FusionControl = "FusionControl" {
        version, sensor, channel, request_id,
    }

    /// [`FusionReply`], on [`ipc_types::names::FUSION_REPLY`].
    pub static FUSION_REPLY: FusionReply = "FusionReply" {
        version, sensor, channel, request_id, outcome, reason, _pad as pad0, pid,
    }
}

/// `T`'s layout: the one its [`FieldType`] impl (written by `layout!`) points to. Only for a
/// struct with a layout; for a primitive it fails to compile where it is evaluated.
pub const fn layout_of<T: FieldType>() -> &'static StructLayout {
    match T::KIND {
        FieldKind::Nested(layout) => layout,
        FieldKind::Prim(_) => panic!("a primitive has no struct layout"),
    }
}

/// Lists every payload of the topic table, in its order.
macro_rules! payload_lists {
    ($($payload:ident ($kind:ident) { $($topics:tt)* })+) => {
        /// Every top-level payload (each starts with `version`); the nested structs are reached
        /// through their fields.
        pub static PAYLOADS: [&StructLayout; PAYLOAD_COUNT] = [$(layout_of::<$payload>()),+];

        // A constant cannot read a static's fields, so the sizes are listed again from the types;
        // a test checks the list against `PAYLOADS`.
        const PAYLOAD_SIZES: [usize; PAYLOAD_COUNT] = [$(size_of::<$payload>()),+];

        const PAYLOAD_COUNT: usize = [$(stringify!($payload)),+].len();
    };
}

ipc_types::for_each_topic!(payload_lists);

/// The largest payload, bytes: what a fixed buffer must hold to carry any of them.
pub const MAX_PAYLOAD: usize = {
    let mut max = 0;
    let mut i = 0;
    while i < PAYLOAD_SIZES.len() {
        if PAYLOAD_SIZES[i] > max {
            max = PAYLOAD_SIZES[i];
        }
        i += 1;
    }
    max
};

/// The top-level payload whose iceoryx2 type name is `type_name` (e.g. `rins::NavState`).
pub fn payload_by_type_name(type_name: &str) -> Option<&'static StructLayout> {
    PAYLOADS.iter().copied().find(|l| l.type_name == type_name)
}

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
fn collect_nested(layout: &StructLayout, out: &mut Vec<&'static StructLayout>) {
    for field in layout.fields {
        if let FieldKind::Nested(inner) = field.kind
            && !out.iter().any(|l| core::ptr::eq(*l, inner))
        {
            out.push(inner);
            collect_nested(inner, out);
        }
    }
}

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

#[cfg(test)]
mod tests {
    use super::*;

    /// Every layout described, nested ones included.
    fn all_layouts() -> Vec<&'static StructLayout> {
        let mut all: Vec<&'static StructLayout> = PAYLOADS.to_vec();
        for payload in PAYLOADS {
            collect_nested(payload, &mut all);
        }
        all
    }

    fn alignment(kind: FieldKind) -> usize {
        match kind {
            FieldKind::Prim(prim) => prim.size(),
            FieldKind::Nested(layout) => layout.align,
        }
    }

    /// The `.msg` schemas against the Rust layout: the fields, at their `offset_of!` offsets,
    /// follow each other in order with no gap (the only padding is the explicit fields), each at
    /// the offset C alignment gives it, each as large as its Rust type, and together they fill
    /// `size_of` the type.
    #[test]
    fn every_schema_matches_the_rust_layout_without_hidden_padding() {
        for layout in all_layouts() {
            let name = layout.type_name;
            let mut end: usize = 0;
            for field in layout.fields {
                let align = alignment(field.kind);
                assert_eq!(
                    field.offset,
                    end.next_multiple_of(align),
                    "{name}.{}: not where C alignment puts it",
                    field.rust_name
                );
                assert_eq!(
                    field.offset, end,
                    "{name}.{}: hidden padding before it",
                    field.rust_name
                );
                assert_eq!(
                    field.size,
                    field.kind.size() * field.count.unwrap_or(1),
                    "{name}.{}: the schema's element type differs from the Rust type",
                    field.rust_name
                );
                end = field.offset + field.size;
            }
            assert_eq!(end, layout.size, "{name}: hidden padding at the end");
            assert_eq!(layout.size % layout.align, 0, "{name}");
            let widest = layout.fields.iter().map(|f| alignment(f.kind)).max();
            assert_eq!(widest, Some(layout.align), "{name}: alignment");
        }
    }

    /// What CDR needs on top: every primitive, nested ones included, at an offset from the start
    /// of the payload that is a multiple of its size, and the primitives back to back.
    #[test]
    fn every_primitive_is_where_cdr_reads_it() {
        for payload in PAYLOADS {
            let mut end = 0;
            for prim in flatten(payload) {
                assert_eq!(
                    prim.offset, end,
                    "{}: gap before {}",
                    payload.ros_name, prim.path
                );
                assert_eq!(
                    prim.offset % prim.prim.size(),
                    0,
                    "{}: {} misaligned for CDR",
                    payload.ros_name,
                    prim.path
                );
                end += prim.prim.size();
            }
            assert_eq!(end, payload.size, "{}", payload.ros_name);
        }
    }

    #[test]
    fn every_payload_starts_with_its_version() {
        for payload in PAYLOADS {
            let first = &payload.fields[0];
            assert_eq!(first.rust_name, "version", "{}", payload.ros_name);
            assert!(matches!(first.kind, FieldKind::Prim(Prim::U16)));
        }
    }

    #[test]
    fn type_names_are_the_iceoryx2_type_names() {
        use iceoryx2::prelude::ZeroCopySend;
        fn name<T: ZeroCopySend>() -> &'static str {
            // SAFETY: reading the type name has no precondition; the trait marks it unsafe to
            // implement, not to call.
            unsafe { <T as ZeroCopySend>::type_name() }
        }
        let expected = [
            name::<RawImu>(),
            name::<RawBaro>(),
            name::<RawMag>(),
            name::<RawAux>(),
            name::<GnssFix>(),
            name::<FusedImu>(),
            name::<Altitude>(),
            name::<NavState>(),
            name::<Truth>(),
            name::<Health>(),
            name::<HealthReport>(),
            name::<FaultApplied>(),
            name::<SimControl>(),
            name::<FusionControl>(),
            name::<FusionReply>(),
        ];
        let ours: Vec<&str> = PAYLOADS.iter().map(|l| l.type_name).collect();
        assert_eq!(ours, expected);
        for layout in PAYLOADS {
            assert_eq!(
                payload_by_type_name(layout.type_name).map(|l| l.size),
                Some(layout.size)
            );
        }
    }

    #[test]
    fn field_names_are_valid_ros2_names() {
        for layout in all_layouts() {
            for field in layout.fields {
                let name = field.name;
                let ok = name.starts_with(|c: char| c.is_ascii_lowercase())
                    && name
                        .chars()
                        .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_')
                    && !name.ends_with('_')
                    && !name.contains("__");
                assert!(ok, "{}.{name} is not a ROS 2 field name", layout.ros_name);
                if !field.rust_name.starts_with('_') {
                    assert_eq!(field.name, field.rust_name);
                }
            }
        }
    }

    #[test]
    fn max_payload_is_the_largest_payload() {
        let sizes: Vec<usize> = PAYLOADS.iter().map(|l| l.size).collect();
        assert_eq!(sizes, PAYLOAD_SIZES);
        assert_eq!(Some(MAX_PAYLOAD), sizes.iter().copied().max());
        assert_eq!(MAX_PAYLOAD, size_of::<HealthReport>());
    }

    #[test]
    fn the_altitude_definition_is_the_expected_text() {
        let expected = "\
uint16 version
uint8 valid
uint8[5] pad0
rins/Header header
float64 height_m
float64 vertical_speed_mps
float64 height_var
================================================================================
MSG: rins/Header
uint64 origin_seq
uint64 origin_device_time_us
uint64 origin_rx_ns
uint64[4] stage_pub_ns
";
        assert_eq!(ros2msg(&ALTITUDE), expected);
        assert_eq!(ALTITUDE.schema_name(), "rins/msg/Altitude");
    }

    #[test]
    fn nested_definitions_are_appended_once_each() {
        let text = ros2msg(&HEALTH_REPORT);
        assert!(text.contains("rins/ServiceHealth[8] services\n"));
        for name in [
            "ServiceHealth",
            "LinkReport",
            "RedundancyReport",
            "NavReport",
        ] {
            assert_eq!(
                text.matches(&format!("MSG: rins/{name}\n")).count(),
                1,
                "{name}"
            );
        }
        let nav = ros2msg(&NAV_STATE);
        assert_eq!(nav.matches("MSG: rins/Header\n").count(), 1);
        assert_eq!(ros2msg(&FUSION_CONTROL).matches("MSG:").count(), 0);
    }
}
