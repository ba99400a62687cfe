//! The metrics of 002 §IV with the definitions resolved in seed digest C.6: DMSE as the L2
//! distance to the ground-truth indicator, the GT rating (pessimistic and optimistic on ties),
//! gmd over region centroids in `|AB|` units, and entropy (nats; ÷ ln 20 to normalize).

use super::belief::{Belief, STATES};
use super::tensor::RegionCentroids;

/// `‖p − e_GT‖₂` (002's DMSE, read with `P(s_GT)` as the indicator of the true state).
pub fn dmse(belief: &Belief, truth: u8) -> f64 {
    (1..=STATES as u8)
        .map(|r| {
            let target = if r == truth { 1.0 } else { 0.0 };
            (belief.probability(r) - target).powi(2)
        })
        .sum::<f64>()
        .sqrt()
}

/// Where the true state ranks when states are sorted by probability (1 = most likely).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Rating {
    /// `1 + #{other states at least as probable}`.
    pub pessimistic: usize,
    /// `1 + #{other states more probable}`.
    pub optimistic: usize,
}

pub fn gt_rating(belief: &Belief, truth: u8) -> Rating {
    let p = belief.probability(truth);
    let others = (1..=STATES as u8).filter(|&r| r != truth);
    Rating {
        pessimistic: 1 + others
            .clone()
            .filter(|&r| belief.probability(r) >= p)
            .count(),
        optimistic: 1 + others.filter(|&r| belief.probability(r) > p).count(),
    }
}

/// `Σ_i P(s_i)·‖c_i − c_GT‖`: the expected distance between region centroids.
pub fn gmd(belief: &Belief, truth: u8, centroids: &RegionCentroids) -> f64 {
    let c = centroids.centroid(truth);
    (1..=STATES as u8)
        .map(|r| belief.probability(r) * centroids.centroid(r).distance(c))
        .sum()
}

/// `−Σ p ln p`, nats (002 leaves the base open: ln 20 = 3.00 nats for the uniform belief).
pub fn entropy(belief: &Belief) -> f64 {
    let sum: f64 = belief
        .probabilities()
        .iter()
        .filter(|&&p| p > 0.0)
        .map(|&p| p * p.ln())
        .sum();
    // A point mass sums to −0 (or a rounding hair below 0 nats).
    (-sum).max(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Seed digest C.6's reference values.
    #[test]
    fn reference_values() {
        assert_eq!(dmse(&Belief::certain(4), 4), 0.0);
        assert!((dmse(&Belief::certain(5), 4) - 2f64.sqrt()).abs() < 1e-12);
        let uniform = dmse(&Belief::uniform(), 4);
        assert!((uniform - (0.95f64.powi(2) + 19.0 * 0.05f64.powi(2)).sqrt()).abs() < 1e-12);
        assert!((uniform - 0.975).abs() < 1e-3);
        assert!((entropy(&Belief::uniform()) - 20f64.ln()).abs() < 1e-12);
        assert_eq!(entropy(&Belief::certain(7)), 0.0);
        assert_eq!(
            gt_rating(&Belief::uniform(), 3),
            Rating {
                pessimistic: 20,
                optimistic: 1
            }
        );
        let mut w = [0.0; STATES];
        w[0] = 0.5;
        w[1] = 0.3;
        w[2] = 0.2;
        let b = Belief::from_weights(w).unwrap();
        assert_eq!(gt_rating(&b, 2).pessimistic, 2);
        assert_eq!(gt_rating(&b, 3).optimistic, 3);
        let centroids = RegionCentroids::committed();
        assert_eq!(gmd(&Belief::certain(9), 9, &centroids), 0.0);
        let far = gmd(&Belief::certain(1), 20, &centroids);
        assert!(
            far > 1.0,
            "regions 1 and 20 lie on opposite sides of AB: {far}"
        );
    }
}
