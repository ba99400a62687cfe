//! The probabilistic composition tensor and region centroids of 002 (seed digest C.5–C.6):
//! regeneration reproduces the committed files, every sampled outcome is one the deterministic
//! composition table allows, and the tensor has the mirror symmetry of the EDC.

use qrm_core::calculus::{Calculus, RelationSet};
use qrm_core::edc::{mirror, Edc};
use qrm_core::probabilistic::{CompositionTensor, RegionCentroids, STATES};
use qrm_tables::{
    EDC_PROBABILISTIC_COMPOSITION, EDC_PROBABILISTIC_COMPOSITION_R10, EDC_REGION_CENTROIDS,
};
use qrm_tools::{probabilistic_composition, region_centroids, SAMPLES_PER_REGION};

fn committed() -> [(CompositionTensor, f64, &'static str); 2] {
    [
        (
            CompositionTensor::parse(EDC_PROBABILISTIC_COMPOSITION).unwrap(),
            3.0,
            "3",
        ),
        (
            CompositionTensor::parse(EDC_PROBABILISTIC_COMPOSITION_R10).unwrap(),
            10.0,
            "10",
        ),
    ]
}

#[test]
fn regeneration_reproduces_the_committed_tables() {
    for (tensor, r_max, text) in committed() {
        assert_eq!(
            probabilistic_composition(r_max, text),
            tensor,
            "r_max {text}"
        );
    }
    let fresh = region_centroids();
    let stored = RegionCentroids::parse(EDC_REGION_CENTROIDS).unwrap();
    for (f, s) in fresh.rows.iter().zip(&stored.rows) {
        assert_eq!(f.1, s.1);
        assert!((f.0.x - s.0.x).abs() < 1e-6 && (f.0.y - s.0.y).abs() < 1e-6);
    }
}

/// 002 §III-E's support must lie in 000's COMPOSE: the samples are real configurations, so an
/// outcome outside the deterministic table would be a defect of one of the two.
#[test]
fn the_tensors_support_lies_in_the_composition_table() {
    let tables = Edc::tables();
    for (tensor, _, text) in committed() {
        for i in 1..=STATES as u8 {
            for j in 1..=STATES as u8 {
                let row = tensor.row(i, j).expect("every cell sampled");
                let allowed = tables.compose(RelationSet::single(i), RelationSet::single(j));
                assert!(
                    row.support().is_subset(allowed),
                    "r_max {text}: K[{i}][{j}] has {:?}, COMPOSE allows {:?}",
                    row.support(),
                    allowed
                );
            }
        }
    }
}

/// Mirroring the plane across the line AB maps region r to mirror(r) in every frame, so
/// K[i][j][k] = K[m(i)][m(j)][m(k)]; the sampled tensors agree within 5 standard errors. The
/// operands are drawn from pools of `SAMPLES_PER_REGION` points per region, whose own sampling
/// noise dominates: the errors are taken at that many samples.
#[test]
fn the_tensor_has_the_mirror_symmetry_of_the_edc() {
    for (tensor, _, text) in committed() {
        for i in 1..=STATES as u8 {
            for j in 1..=STATES as u8 {
                let (row, mirrored) = (
                    tensor.row(i, j).unwrap(),
                    tensor.row(mirror(i), mirror(j)).unwrap(),
                );
                let n = f64::from(tensor.total(i, j).min(tensor.total(mirror(i), mirror(j))))
                    .min(SAMPLES_PER_REGION as f64);
                for k in 1..=STATES as u8 {
                    let (p, q) = (row.probability(k), mirrored.probability(mirror(k)));
                    let se = ((p * (1.0 - p) + q * (1.0 - q)) / n).sqrt().max(1.0 / n);
                    assert!(
                        (p - q).abs() <= 5.0 * se,
                        "r_max {text}: K[{i}][{j}][{k}] = {p}, mirrored {q}"
                    );
                }
            }
        }
    }
}
