//! The operator tables of the EDC and FDC calculi (000 §III-B, 003 §1.2), generated offline by
//! `tools/gen-tables` and embedded here as text so that `qrm-core` ships them with no files to
//! find at run time. Format: `tables/README.md`; parsed by `qrm_core::calculus`.

/// LEFT, RIGHT, INVERSE of the 20 EDC regions (000 Table I).
pub const EDC_UNARY: &str = include_str!("../edc_unary.txt");
/// COMPOSE(AB:C, BC:D) → AB:D over the EDC regions, with a witness per possible entry.
pub const EDC_COMPOSITION: &str = include_str!("../edc_composition.txt");
/// LEFT, RIGHT, INVERSE of the 15 FDC relations.
pub const FDC_UNARY: &str = include_str!("../fdc_unary.txt");
/// COMPOSE over the FDC relations, with a witness per possible entry.
pub const FDC_COMPOSITION: &str = include_str!("../fdc_composition.txt");
/// 002's probabilistic composition tensor `K[i][j][k]` over the EDC regions as sampled counts,
/// both operands truncated to `|L| ≤ 3 |AB|` (002 §III-E; seed digest C.5).
pub const EDC_PROBABILISTIC_COMPOSITION: &str =
    include_str!("../edc_probabilistic_composition.txt");
/// The same tensor truncated to `|L| ≤ 10 |AB|`, published to show the truncation's effect.
pub const EDC_PROBABILISTIC_COMPOSITION_R10: &str =
    include_str!("../edc_probabilistic_composition_r10.txt");
/// The centroid of each EDC region under 002's scenario generator, for gmd (seed digest C.6).
pub const EDC_REGION_CENTROIDS: &str = include_str!("../edc_region_centroids.txt");
