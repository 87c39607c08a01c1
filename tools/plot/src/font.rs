//! The one font every rins plot draws its text with.
//!
//! The drawing library renders text only with a font it is given (it is built without the system
//! font libraries), and a headless machine may have no font at all: DejaVu Sans is embedded
//! (Bitstream Vera licence, `assets/DejaVuSans-LICENSE.txt`).

use plotters::style::FontStyle;

/// DejaVu Sans, the TrueType file.
pub const FONT: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");

/// The family name plots ask for: [`register_font`] makes it DejaVu Sans.
pub const FAMILY: &str = "sans-serif";

/// Registers [`FONT`] as the [`FAMILY`] font of the drawing library. Call it before drawing any
/// text; calling it again (a second plot in the same process) keeps the first copy: harmless.
pub fn register_font() {
    // The only failure is a font file that does not parse, which the embedded one does (a unit
    // test draws text with it); there is nothing else to do about it than draw without text.
    let _ = plotters::style::register_font(FAMILY, FontStyle::Normal, FONT);
}
