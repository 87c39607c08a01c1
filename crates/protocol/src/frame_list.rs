//! The one list of the protocol's frame types. It names each type's variant, type byte, module
//! and struct, and nothing else: it imports nothing, so that every file generated from it
//! ([`FrameType`](crate::FrameType) in `frame_type.rs`, [`Payload`](crate::Payload) and the
//! dispatch in `frames/mod.rs`, acquisition's publishers) can depend on it without depending on
//! one another.

/// Calls `$callback! { list }` with the list of frame types, one line per type, in type-byte
/// order; the callback is a `macro_rules!` macro in scope where this is invoked. Grammar:
///
/// ```text
/// /// What the frame carries (the doc of its FrameType and Payload variants).
/// Variant = TYPE_BYTE => module::FrameStruct,
/// ```
///
/// - `Variant`: its name in [`FrameType`](crate::FrameType) and [`Payload`](crate::Payload).
/// - `TYPE_BYTE`: its type byte on the wire; the bytes run 1, 2, 3, … down the list (checked at
///   compile time), as [`FrameType::index`](crate::FrameType::index) and per-type arrays rely on
///   it.
/// - `module`: its file under `frames/`, and its lower-case name
///   ([`FrameType::name`](crate::FrameType::name), and the field name of per-type tables a
///   callback builds).
/// - `FrameStruct`: its contents' struct in that module, implementing
///   [`SensorFrame`](crate::SensorFrame); reachable as `rins_protocol::frames::module::FrameStruct`
///   and `rins_protocol::FrameStruct`.
///
/// Doc links in the lines are absolute (`crate::…`), as they are expanded in several modules.
#[macro_export]
macro_rules! for_each_frame {
    ($callback:ident) => {
        $callback! {
            /// Gyro and accelerometer counts with module temperatures
            /// ([`ImuFrame`](crate::ImuFrame)).
            Imu = 1 => imu::ImuFrame,
            /// Barometric pressure and temperature ([`BaroFrame`](crate::BaroFrame)).
            Baro = 2 => baro::BaroFrame,
            /// Three-axis magnetic field ([`MagFrame`](crate::MagFrame)).
            Mag = 3 => mag::MagFrame,
            /// Foot-pressure sensor ([`AuxFrame`](crate::AuxFrame)).
            Aux = 4 => aux::AuxFrame,
            /// Pitot differential pressure and temperature ([`AirspeedFrame`](crate::AirspeedFrame)).
            Airspeed = 5 => airspeed::AirspeedFrame,
        }
    };
}

// The path this crate's generators name it by (`crate::frame_list::for_each_frame!`); other
// crates name it at the crate root (`rins_protocol::for_each_frame!`).
pub(crate) use for_each_frame;
