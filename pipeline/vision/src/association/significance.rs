//! How surprising a registration's fit would be by chance: the a-contrario test of rigid point
//! matching (Moisan & Stival 2004, "A probabilistic criterion to detect rigid point matches
//! between two images and estimate the fundamental matrix", ORSA).
//!
//! The null model drops each of the current station's detections anywhere among the frame's
//! landmarks, independently. A motion hypothesised from two seed correspondences that also
//! brings `j − 2` more detections within `r` of a frame landmark would do so by chance with
//! probability at most the binomial tail of `j − 2` hits among the other detections, each with
//! probability `density · π r²`. The density is taken where the landmarks lie densest (rock
//! fields cluster: the mean density would understate chance there), and counts only the
//! landmarks a detection looks like, the only ones a fit pairs it with (as in a-contrario
//! matching of descriptors: Rabin, Delon & Gousseau 2008, "A contrario matching of SIFT-like
//! descriptors"). Multiplied by the number of hypotheses tried, this is the expected number of
//! chance fits as tight as the one seen, its *number of false alarms* (NFA). A fit whose NFA is
//! far below one is no accident, whatever the sensor's error bounds: the test uses the
//! residuals the fit achieved, not the worst case the placements allow. A residual is a
//! [`super::placement::Separation`] distance: for elongated placements, the radius of a disc
//! as large as the ellipse of the residual, so `π r²` stays its area.

use std::f64::consts::PI;

/// The null model of one registration: how many hypotheses were tried, how densely the frame's
/// landmarks lie, and how many detections could fall near them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Chance {
    /// Motions hypothesised (pairs of seed correspondences).
    pub tests: f64,
    /// Landmarks a detection looks like, per m² where the landmarks lie densest: a chance
    /// detection near a cluster is more likely to land near some landmark than the frame's
    /// mean density says.
    pub density: f64,
    /// Detections of the current station that could pair with one.
    pub detections: usize,
}

impl Chance {
    /// The NFA of a fit whose inliers lie `residuals` (metres, any order) from their landmarks,
    /// and the number of tightest inliers it was reached with: the least NFA over every prefix
    /// of at least `min_inliers` of the sorted residuals (a fit's loosest inliers may be chance
    /// pairs the tight core does not need).
    pub fn nfa(&self, residuals: &[f64], min_inliers: usize) -> (f64, usize) {
        let mut sorted = residuals.to_vec();
        sorted.sort_by(f64::total_cmp);
        let others = self.detections.saturating_sub(2);
        (min_inliers.max(3)..=sorted.len())
            .map(|j| {
                let r = sorted[j - 1];
                let p = (self.density * PI * r * r).min(1.0);
                (self.tests * binomial_tail(others, j - 2, p), j)
            })
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .unwrap_or((f64::INFINITY, 0))
    }
}

/// `P(X ≥ k)` for `X ~ Binomial(n, p)`.
fn binomial_tail(n: usize, k: usize, p: f64) -> f64 {
    if k == 0 {
        return 1.0;
    }
    if k > n || p <= 0.0 {
        return 0.0;
    }
    if p >= 1.0 {
        return 1.0;
    }
    // Terms C(n, i) pᶦ (1 − p)ⁿ⁻ᶦ from i = k up, each from the one before.
    let q = 1.0 - p;
    let mut term = choose(n, k) * p.powi(k as i32) * q.powi((n - k) as i32);
    let mut sum = 0.0;
    for i in k..=n {
        sum += term;
        term *= (n - i) as f64 / (i + 1) as f64 * p / q;
    }
    sum.min(1.0)
}

fn choose(n: usize, k: usize) -> f64 {
    (0..k).fold(1.0, |c, i| c * (n - i) as f64 / (i + 1) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_binomial_tail_matches_its_definition() {
        assert_eq!(binomial_tail(5, 0, 0.3), 1.0);
        assert_eq!(binomial_tail(3, 4, 0.3), 0.0);
        // P(X ≥ 2), n = 4, p = 0.5: (6 + 4 + 1) / 16.
        assert!((binomial_tail(4, 2, 0.5) - 11.0 / 16.0).abs() < 1e-12);
        assert!((binomial_tail(10, 10, 0.2) - 0.2f64.powi(10)).abs() < 1e-18);
        assert_eq!(binomial_tail(6, 3, 1.0), 1.0);
        assert_eq!(binomial_tail(6, 3, 0.0), 0.0);
    }

    /// Four inliers a few centimetres off in a field of six landmarks are no accident; the same
    /// four half a metre off are, and so is anything in a field packed with landmarks.
    #[test]
    fn tight_fits_are_significant_and_loose_ones_are_not() {
        let chance = Chance {
            tests: 700.0,
            density: 6.0 / 400.0,
            detections: 10,
        };
        let (tight, used) = chance.nfa(&[0.03, 0.07, 0.05, 0.04], 4);
        assert!(tight < 0.01, "{tight}");
        assert_eq!(used, 4);
        let (loose, _) = chance.nfa(&[0.5, 0.4, 0.6, 0.45], 4);
        assert!(loose > 1.0, "{loose}");
        let packed = Chance {
            density: 1.0,
            ..chance
        };
        assert!(packed.nfa(&[0.03, 0.07, 0.05, 0.04], 4).0 > 1.0);
    }

    /// A loose fifth inlier does not spoil a tight core of four.
    #[test]
    fn the_tightest_prefix_decides() {
        let chance = Chance {
            tests: 700.0,
            density: 6.0 / 400.0,
            detections: 10,
        };
        let core = chance.nfa(&[0.03, 0.07, 0.05, 0.04], 4).0;
        let (with_loose, used) = chance.nfa(&[0.03, 0.07, 1.5, 0.05, 0.04], 4);
        assert_eq!(used, 4);
        assert!((with_loose - core).abs() < 1e-15);
        assert_eq!(chance.nfa(&[0.1, 0.2], 4).0, f64::INFINITY);
    }
}
