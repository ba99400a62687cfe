//! Figures of the paper's evaluation (000 §VIII): Monte-Carlo statistics per image as in
//! Fig. 7 ([`write_panels`]) and RNG snapshots over the landmark field as in Fig. 11
//! ([`write_rng`]); and the pictures of a run: annotated panoramas ([`write_panorama`]) and a
//! contact sheet of the landmarks ([`write_contact_sheet`]). Plain data in, PNG or SVG files
//! out (format by extension, written atomically), so that experiments and tools can plot
//! without knowing the map types.
//!
//! Text is rendered with an embedded DejaVu Sans (`pipeline/plot/assets/fonts/`) so that no
//! fontconfig/freetype is needed on the machine that draws.

mod contact_sheet;
mod cost_colour;
mod error;
mod flow;
mod font;
mod layout;
mod legend;
mod output;
mod palette;
mod panels;
mod panorama;
mod reliability;
mod rng;
mod ticks;

pub use contact_sheet::{write_contact_sheet, ContactSheet, Tile, TILE};
pub use error::PlotError;
pub use flow::{write_flow, FlowPicture};
pub use layout::spring_layout;
pub use panels::{write_panels, Curve, Panel};
pub use panorama::{write_panorama, AnnotatedPanorama, Mark, MarkKind, RgbImage};
pub use reliability::{
    write_reliability, CalibrationPoint, CalibrationSeries, ReliabilityPicture, SelectionSeries,
};
pub use rng::{write_rng, Axes, RngPicture};

#[cfg(test)]
mod test_support;
