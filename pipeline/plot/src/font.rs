//! The embedded text font. With plotters' `ab_glyph` feature text is rasterised from fonts
//! registered at run time instead of system fonts found through fontconfig, which a fresh CI
//! machine lacks; so DejaVu Sans (license in `pipeline/plot/assets/fonts/README.md`) is compiled in
//! and registered once as the `sans-serif` family that every figure uses.

use plotters::style::{register_font, FontStyle};
use std::sync::OnceLock;

/// The family name under which the font is registered and by which figures request it.
pub(super) const FAMILY: &str = "sans-serif";

const DEJAVU_SANS: &[u8] = include_bytes!("../assets/fonts/DejaVuSans.ttf");

/// Registers the embedded font on first call; `false` if the font data was rejected.
pub(super) fn ensure_registered() -> bool {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    *REGISTERED.get_or_init(|| register_font(FAMILY, FontStyle::Normal, DEJAVU_SANS).is_ok())
}
