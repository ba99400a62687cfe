//! Subcommands of the `pipeline` binary beyond the calculus tools in `main.rs`.

pub mod directions;
pub mod drive;
pub mod eval;
pub mod flowfield;
pub mod locate;
pub mod map;
pub mod measure;
pub mod navigate;
pub mod output;
pub mod pictures;
pub mod probabilistic;
pub mod rng_picture;
pub mod run;
pub mod simulate;
pub mod synth;

use clap::ValueEnum;
use qrm_core::calculus::Calculus;
use qrm_core::map::Hypergraph;
use qrm_core::neighborhood::RngEstimate;
use serde_json::json;

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum CalculusName {
    Edc,
    Fdc,
}

/// The value at fraction `q` of ascending `sorted` (nearest rank; NaN when empty): the
/// medians and 90th percentiles the navigation commands report.
pub fn quantile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        f64::NAN
    } else {
        sorted[((sorted.len() - 1) as f64 * q).round() as usize]
    }
}

/// The RNG estimate as JSON (format in docs/MAP_FORMAT.md).
pub fn rng_json<C: Calculus>(map: &Hypergraph<C>, rng: &RngEstimate) -> String {
    let edges: Vec<_> = rng
        .edges
        .iter()
        .map(|e| json!({"a": e.a, "b": e.b, "cost": e.cost}))
        .collect();
    let value = json!({
        "format": "qrm-rng",
        "version": 1,
        "calculus": C::NAME,
        "landmarks": map.landmarks(),
        "pruned": rng.pruned,
        "total_cost": rng.total_cost(),
        "edges": edges,
    });
    serde_json::to_string_pretty(&value).expect("JSON values serialise") + "\n"
}
