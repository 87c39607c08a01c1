//! The table of top-level payloads, in the order of the topic table: the list itself, the
//! largest payload size, and the lookup by type name.

use super::description::StructLayout;
use super::field_type::layout_of;

/// Lists every payload of the topic table, in its order; each is named from the table, so a new
/// payload needs no line here.
macro_rules! payload_lists {
    ($($payload:ident $kind:ident;)+) => {
        /// Every top-level payload (each starts with `version`); the nested structs are reached
        /// through their fields.
        pub static PAYLOADS: [&StructLayout; PAYLOAD_COUNT] = [$(layout_of::<ipc_types::$payload>()),+];

        // A constant cannot read a static's fields, so the sizes are listed again from the types;
        // a test checks the list against `PAYLOADS`.
        pub(super) const PAYLOAD_SIZES: [usize; PAYLOAD_COUNT] = [$(size_of::<ipc_types::$payload>()),+];

        const PAYLOAD_COUNT: usize = [$(stringify!($payload)),+].len();
    };
}

ipc_types::for_each_topic!(payloads => payload_lists);

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
