//! `wire_enum!`: one declaration for every enum that travels as a number in a payload field.
//!
//! A payload carries an enum as its discriminant (a `u8` field), so a consumer must turn a number
//! it read from shared memory back into a variant. The numbers, the names that tools print and
//! parse, and the list of variants are written once, in the declaration, and the conversions are
//! generated from it, so they cannot drift apart.
//!
//! Decoding never guesses: `from_u8` answers `None` for a number this build does not know (a
//! newer writer, a corrupted sample). What an unknown value means — an unusable solution, an
//! invalid integrity, a channel that is not Ok — is decided where it is read, because only the
//! reader knows which reading is the safe one.

/// Declares a fieldless enum carried on the wire as its discriminant, with its conversions.
///
/// ```text
/// wire_enum! {
///     /// Doc of the enum.
///     #[derive(Default)]
///     pub enum Example: u8 {
///         /// Doc of the variant.
///         #[default]
///         First = 0 => "first",
///         Second = 1 => "second",
///     }
/// }
/// ```
///
/// declares `#[repr(u8)] pub enum Example` deriving `Debug, Clone, Copy, PartialEq, Eq` (plus the
/// attributes given, e.g. `#[derive(Default)]` with a `#[default]` variant) and generates:
///
/// - `COUNT`: the number of variants; `ALL`: every variant in declaration order;
/// - `name(self)`: the name given after `=>`, as tools print it; `from_name(&str)`: its inverse;
/// - for `u8`: `from_u8(u8) -> Option<Self>`, `None` for a number no variant has;
///   for `usize` (an enum that indexes an array rather than travelling as a byte):
///   `from_index(usize) -> Option<Self>`.
macro_rules! wire_enum {
    (
        $(#[$meta:meta])*
        $vis:vis enum $name:ident: $repr:ident {
            $(
                $(#[$variant_meta:meta])*
                $variant:ident = $value:literal => $text:literal
            ),+ $(,)?
        }
    ) => {
        $(#[$meta])*
        #[repr($repr)]
        #[derive(Debug, Clone, Copy, PartialEq, Eq)]
        $vis enum $name {
            $(
                $(#[$variant_meta])*
                $variant = $value,
            )+
        }

        impl $name {
            /// Number of variants.
            pub const COUNT: usize = [$(Self::$variant),+].len();

            /// Every variant, in declaration (and wire value) order.
            pub const ALL: [Self; Self::COUNT] = [$(Self::$variant),+];

            /// The variant's name as tools print it and accept it.
            pub const fn name(self) -> &'static str {
                match self {
                    $(Self::$variant => $text,)+
                }
            }

            /// The variant named `name` (see [`Self::name`]); `None` for any other text.
            pub fn from_name(name: &str) -> Option<Self> {
                Self::ALL.into_iter().find(|v| v.name() == name)
            }
        }

        wire_enum!(@decode $name $repr $($variant = $value),+);
    };

    (@decode $name:ident u8 $($variant:ident = $value:literal),+) => {
        impl $name {
            /// The variant whose wire value is `value`; `None` for a value this build does not
            /// know, which the reader maps to whatever is safe in its place.
            pub const fn from_u8(value: u8) -> Option<Self> {
                match value {
                    $($value => Some(Self::$variant),)+
                    _ => None,
                }
            }
        }
    };

    (@decode $name:ident usize $($variant:ident = $value:literal),+) => {
        impl $name {
            /// The variant whose index is `index`; `None` past the last one.
            pub const fn from_index(index: usize) -> Option<Self> {
                match index {
                    $($value => Some(Self::$variant),)+
                    _ => None,
                }
            }
        }
    };
}
