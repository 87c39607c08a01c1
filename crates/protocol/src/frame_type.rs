//! [`FrameType`], the type byte of the wire, generated from the frame list
//! ([`for_each_frame!`](crate::for_each_frame)) alone: the errors and the wire access name a frame
//! type without depending on the frame types' contents. What a type's contents decide (payload
//! lengths, decoding) is added in `frames/mod.rs`.

/// Generates [`FrameType`] from the frame list.
macro_rules! frame_type_enum {
    ($($(#[$doc:meta])* $variant:ident = $byte:literal => $module:ident :: $frame:ident,)+) => {
        /// Frame type byte on the wire.
        #[repr(u8)]
        #[derive(Debug, Clone, Copy, PartialEq, Eq)]
        pub enum FrameType {
            $($(#[$doc])* $variant = $byte,)+
        }

        impl FrameType {
            /// Number of frame types: the length of per-type arrays.
            pub const COUNT: usize = [$(FrameType::$variant),+].len();

            /// Every type, in [`FrameType::index`] order.
            pub const ALL: [FrameType; Self::COUNT] = [$(FrameType::$variant),+];

            /// The type a wire type byte names; `None` for a byte that names none.
            pub fn from_u8(v: u8) -> Option<Self> {
                match v {
                    $($byte => Some(FrameType::$variant),)+
                    _ => None,
                }
            }

            /// Lower-case name, for messages.
            pub const fn name(self) -> &'static str {
                match self {
                    $(FrameType::$variant => stringify!($module),)+
                }
            }
        }
    };
}

crate::frame_list::for_each_frame!(frame_type_enum);

impl FrameType {
    /// Index 0..COUNT, for per-type counters.
    pub fn index(self) -> usize {
        self as usize - 1
    }
}

// Type bytes run 1..=COUNT in list order: `FrameType::index` is the byte minus one.
const _: () = {
    let mut i = 0;
    while i < FrameType::COUNT {
        assert!(FrameType::ALL[i] as usize == i + 1);
        i += 1;
    }
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_list_gives_the_wire_type_bytes_and_names() {
        let listed: Vec<(u8, &str)> = FrameType::ALL
            .iter()
            .map(|&t| (t as u8, t.name()))
            .collect();
        assert_eq!(
            listed,
            [
                (1, "imu"),
                (2, "baro"),
                (3, "mag"),
                (4, "aux"),
                (5, "airspeed")
            ]
        );
        for (i, &t) in FrameType::ALL.iter().enumerate() {
            assert_eq!((FrameType::from_u8(t as u8), t.index()), (Some(t), i));
        }
        assert_eq!(FrameType::from_u8(0), None);
        assert_eq!(FrameType::from_u8(FrameType::COUNT as u8 + 1), None);
    }
}
