//! What ranging says about a triple beyond its order: each landmark's range in an interval, so
//! each ratio of two ranges in an interval too.
//!
//! The paper's observation is the range *order* (000 §IV assumption 2). A rover's ranging cues
//! (flat ground, stereo, apparent size) give intervals, and the order is only what their
//! separation says; the intervals also bound how much nearer. Every EDC boundary function is
//! homogeneous in the ranges, so only ratios can matter, and for three landmarks the pairwise
//! ratio bounds are exactly what the intervals allow: scaled ranges `λ·ρ_X` fit every interval
//! for some `λ` iff the intervals on `λ` meet pairwise (intervals on a line meet as a whole when
//! they meet two by two).

/// A landmark's range known to lie in `[low, high]` (any unit: only ratios are used);
/// [`RangeBounds::UNBOUNDED`] when ranging says nothing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RangeBounds {
    pub low: f64,
    pub high: f64,
}

impl RangeBounds {
    pub const UNBOUNDED: RangeBounds = RangeBounds {
        low: 0.0,
        high: f64::INFINITY,
    };
}

/// Bounds on `r_p / r_q` for the three landmarks `p, q` of a triple, from their range intervals
/// and the ordered pairs (`nearer`: the ratio at most 1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RangeRatios {
    bounds: [[(f64, f64); 3]; 3],
}

impl RangeRatios {
    pub fn new(ranges: [RangeBounds; 3], nearer: &[(usize, usize)]) -> RangeRatios {
        let mut bounds = [[(0.0, f64::INFINITY); 3]; 3];
        for (p, row) in bounds.iter_mut().enumerate() {
            for (q, bound) in row.iter_mut().enumerate() {
                *bound = if p == q {
                    (1.0, 1.0)
                } else {
                    (
                        quotient(ranges[p].low, ranges[q].high),
                        quotient(ranges[p].high, ranges[q].low),
                    )
                };
            }
        }
        for &(p, q) in nearer {
            bounds[p][q].1 = bounds[p][q].1.min(1.0);
            bounds[q][p].0 = bounds[q][p].0.max(1.0);
        }
        RangeRatios { bounds }
    }

    /// `(low, high)` bounds on `r_p / r_q`: `low` may be 0, `high` infinite.
    pub fn of(&self, p: usize, q: usize) -> (f64, f64) {
        self.bounds[p][q]
    }

    /// The same bounds with the landmarks relabelled: landmark `p` becomes `(p + 3 − k) % 3`,
    /// as for relation `k` of a triple's `[AB:C, BC:A, CA:B]`.
    pub fn rotated(&self, k: usize) -> RangeRatios {
        RangeRatios {
            bounds: std::array::from_fn(|p| {
                std::array::from_fn(|q| self.bounds[(p + k) % 3][(q + k) % 3])
            }),
        }
    }
}

/// `a / b` for non-negative bounds, with `0 / 0` and `∞ / ∞` (no information) as the widest
/// value the side needs: a lower bound 0, an upper bound ∞.
fn quotient(a: f64, b: f64) -> f64 {
    match (a, b) {
        (a, b) if a == 0.0 && b == 0.0 => 0.0,
        (a, b) if a.is_infinite() && b.is_infinite() => f64::INFINITY,
        (a, b) => a / b,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn intervals_and_order_bound_each_ratio() {
        let ranges = [
            RangeBounds {
                low: 4.0,
                high: 5.0,
            },
            RangeBounds {
                low: 8.0,
                high: 10.0,
            },
            RangeBounds::UNBOUNDED,
        ];
        let ratios = RangeRatios::new(ranges, &[(0, 1), (2, 0)]);
        assert_eq!(ratios.of(1, 0), (8.0 / 5.0, 10.0 / 4.0));
        assert_eq!(ratios.of(0, 1), (0.4, 0.625));
        // C is unranged: only the order bounds it (nearer than A).
        assert_eq!(ratios.of(2, 0), (0.0, 1.0));
        assert_eq!(ratios.of(0, 2), (1.0, f64::INFINITY));

        // Relation BC:A sees B as its A: the ratio of its first two is the old B over C.
        assert_eq!(ratios.rotated(1).of(0, 1), ratios.of(1, 2));
        assert_eq!(ratios.rotated(2).of(0, 1), ratios.of(2, 0));
        // Unranged landmarks and no order: any ratio.
        let one = RangeRatios::new([ranges[0], RangeBounds::UNBOUNDED, ranges[2]], &[]);
        assert_eq!(one.of(0, 1), (0.0, f64::INFINITY));
        assert_eq!(one.of(1, 2), (0.0, f64::INFINITY));
        // An order the intervals contradict leaves no ratio (the low bound above the high).
        let (lo, hi) = RangeRatios::new(ranges, &[(1, 0)]).of(1, 0);
        assert!(lo > hi);
    }
}
