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

mod description;
mod field_type;
mod flatten;
mod layouts;
mod msg_text;
mod payloads;

pub use description::{Field, FieldKind, Prim, ROS_PACKAGE, StructLayout};
pub use field_type::{FieldType, layout_of};
pub use flatten::{FlatPrim, flatten};
pub use layouts::*;
pub use msg_text::ros2msg;
pub use payloads::{MAX_PAYLOAD, PAYLOADS, payload_by_type_name};

#[cfg(test)]
mod tests {
    use super::msg_text::collect_nested;
    use super::payloads::PAYLOAD_SIZES;
    use super::*;
    use ipc_types::{HealthReport, NavState};

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
        /// The iceoryx2 type name of every payload, in the topic table's order.
        macro_rules! type_names {
            ($($payload:ident $kind:ident;)+) => {
                [$(name::<ipc_types::$payload>()),+]
            };
        }
        let expected = ipc_types::for_each_topic!(payloads => type_names);
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
        // The health report, with the GNSS line's counters, is the largest.
        assert_eq!(MAX_PAYLOAD, size_of::<HealthReport>());
        assert!(size_of::<HealthReport>() > size_of::<NavState>());
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
        assert!(text.contains("rins/ServiceHealth[10] services\n"));
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
