//! One measured triple: the dispatch to the sweep (exact bearings) or the interval method
//! (uncertain bearings), and the paper's feasibility formulation (000 §IV, Fig. 4, Table III),
//! generalised to uncertain bearings and partial range orders, decided by branch and bound
//! ([`by_search`], the reference the tests compare the fast methods with).
//!
//! The camera sits at the origin; landmark `X` lies at `s_X·u_X + t_X·v_X`, where `u_X` is the
//! unit vector of its measured bearing, `v_X ⊥ u_X`, `s_X > 0` its range along `u_X` and
//! `|t_X| ≤ s_X·tan δ_X` its offset within the bearing interval of half-width `δ_X`. Every EDC
//! boundary function is a quadratic form in `(s, t)` that is homogeneous of degree 2, so scale
//! can be fixed by `s_A + s_B + s_C = 1`: the unknowns are `s_A, s_B` and the `t` of each
//! landmark with uncertain bearing, in a compact box. (000 fixes `|A| = 1` and bounds the other
//! ranges by a "problem-specific" constant instead; the simplex needs no such bound, so no
//! arrangement is lost however different the ranges are.) With exact bearings this is the
//! paper's two-unknown problem; each uncertain bearing adds one unknown.

use super::interval::by_intervals;
use super::range_ratios::{RangeBounds, RangeRatios};
use super::sweep::sweep_regions;
use super::Bearing;
use crate::calculus::{Calculus, RelationSet};
use crate::edc;
use crate::edc::region_constraints;
use crate::feasibility::{BranchAndBound, Linear, Problem, Quadratic};
use crate::geometry::{Coordinate, Point, Point2};

/// The three relations of a triple `(A, B, C)` stored in a map edge: `AB:C`, `BC:A`, `CA:B`.
pub type TripleRelations = [RelationSet; 3];

/// The EDC regions of `AB:C`, `BC:A`, `CA:B` (in that order) consistent with the bearings of
/// `A`, `B`, `C`, the ordered pairs `nearer` (`(p, q)`: landmark `p` of the triple is nearer
/// than `q`) and the range intervals `ranges`, restricted to `candidates`: by [`by_sweep`] for
/// exact bearings, otherwise the regions reached at the nominal bearings plus those
/// [`by_intervals`] cannot rule out. `None` when the bearings are exact and collinear: every
/// arrangement then lies on the line AB, where no EDC region is defined, and nothing is learnt.
pub fn measure_triple_edc(
    bearings: [Bearing; 3],
    nearer: &[(usize, usize)],
    ranges: [RangeBounds; 3],
    candidates: TripleRelations,
) -> Option<TripleRelations> {
    if all_collinear(&bearings) {
        return None;
    }
    // The relations do not depend on where the bearings' zero is; measuring in A's frame makes
    // the result depend on the bearings' differences only, so that turning the rover (or the
    // calibration's zero column) cannot change what is measured.
    let bearings = bearings.map(|b| Bearing {
        angle: b.angle - bearings[0].angle,
        ..b
    });
    let tables = edc::Edc::tables();
    let candidates = [
        candidates[0]
            .intersection(tables.left(candidates[2]))
            .intersection(tables.right(candidates[1])),
        candidates[1]
            .intersection(tables.left(candidates[0]))
            .intersection(tables.right(candidates[2])),
        candidates[2]
            .intersection(tables.left(candidates[1]))
            .intersection(tables.right(candidates[0])),
    ];
    let nominal = by_sweep(
        bearings.map(|b| Bearing::exact(b.angle)),
        nearer,
        ranges,
        candidates,
    );
    Some(if bearings.iter().all(|b| b.uncertainty == 0.0) {
        nominal
    } else {
        let ratios = RangeRatios::new(ranges, nearer);
        by_intervals(bearings, nearer, &ratios, candidates, nominal)
    })
}

/// Exact bearings: each relation decided by [`sweep_regions`].
pub fn by_sweep(
    bearings: [Bearing; 3],
    nearer: &[(usize, usize)],
    ranges: [RangeBounds; 3],
    candidates: TripleRelations,
) -> TripleRelations {
    let u = bearings.map(|b| Point::new(b.angle.cos(), b.angle.sin()));
    let ratios = RangeRatios::new(ranges, nearer);
    std::array::from_fn(|k| {
        if candidates[k].is_empty() {
            return RelationSet::EMPTY;
        }
        sweep_regions(
            [u[k], u[(k + 1) % 3], u[(k + 2) % 3]],
            &ratios.rotated(k),
            candidates[k],
        )
    })
}

/// Any bearings, the paper's way: one branch-and-bound search decides the candidate regions of
/// all three relations (undecided ones are kept). About 10 ms per triple, so the pipeline uses
/// the sweep and the interval method; this is their independent reference in the tests.
pub fn by_search(
    bearings: [Bearing; 3],
    nearer: &[(usize, usize)],
    ranges: [RangeBounds; 3],
    candidates: TripleRelations,
    engine: &BranchAndBound,
) -> TripleRelations {
    let formulation = Formulation::new(&bearings, nearer, &RangeRatios::new(ranges, nearer));
    let mut index = Vec::new();
    let mut alternatives = Vec::new();
    for (k, set) in candidates.iter().enumerate() {
        let [p, q, w] = formulation.rotated(k);
        for region in set.iter() {
            index.push((k, region));
            alternatives.push(region_constraints(p, q, w, region));
        }
    }
    let mut result = [RelationSet::EMPTY; 3];
    if alternatives.is_empty() {
        return result;
    }
    let problem = Problem {
        lower: formulation.lower.clone(),
        upper: formulation.upper.clone(),
        common: formulation.common.clone(),
        alternatives,
    };
    let (outcomes, _) = engine.solve(&problem);
    for ((k, region), outcome) in index.into_iter().zip(outcomes) {
        if outcome.possibly_feasible() {
            result[k] = result[k].with(region);
        }
    }
    result
}

/// Whether the three bearings are exact and lie on one line through the camera, so that the
/// landmarks are collinear whatever their ranges.
fn all_collinear(bearings: &[Bearing; 3]) -> bool {
    const TOLERANCE: f64 = 1e-12;
    bearings.iter().all(|b| b.uncertainty == 0.0)
        && (bearings[1].angle - bearings[0].angle).sin().abs() < TOLERANCE
        && (bearings[2].angle - bearings[0].angle).sin().abs() < TOLERANCE
}

/// Symbolic landmark positions, the search box and the constraints common to all regions.
struct Formulation {
    points: [Point2<Linear>; 3],
    lower: Vec<f64>,
    upper: Vec<f64>,
    common: Vec<Quadratic>,
}

impl Formulation {
    fn new(
        bearings: &[Bearing; 3],
        nearer: &[(usize, usize)],
        ratios: &RangeRatios,
    ) -> Formulation {
        let uncertain: Vec<usize> = (0..3).filter(|&i| bearings[i].uncertainty > 0.0).collect();
        let n = 2 + uncertain.len();
        let mut lower = vec![0.0; n];
        let mut upper = vec![1.0; n];
        let mut common = Vec::new();

        // s_A = x0, s_B = x1, s_C = 1 − x0 − x1 > 0.
        let s = [
            Linear::variable(n, 0),
            Linear::variable(n, 1),
            Linear::constant(n, 1.0) - Linear::variable(n, 0) - Linear::variable(n, 1),
        ];
        common.push(-Quadratic::from_linear(&s[2]));

        let mut t: [Linear; 3] = std::array::from_fn(|_| Linear::constant(n, 0.0));
        for (slot, &i) in uncertain.iter().enumerate() {
            let var = 2 + slot;
            let tan = bearings[i].uncertainty.tan();
            lower[var] = -tan;
            upper[var] = tan;
            t[i] = Linear::variable(n, var);
            // |t| < s·tan δ.
            common.push(Quadratic::from_linear(&(t[i].clone() - s[i].scaled(tan))));
            common.push(Quadratic::from_linear(
                &(t[i].scaled(-1.0) - s[i].scaled(tan)),
            ));
        }

        let points: [Point2<Linear>; 3] = std::array::from_fn(|i| {
            let (sin, cos) = bearings[i].angle.sin_cos();
            Point2::new(
                s[i].scaled(cos) - t[i].scaled(sin),
                s[i].scaled(sin) + t[i].scaled(cos),
            )
        });

        for &(p, q) in nearer {
            let exact = bearings[p].uncertainty == 0.0 && bearings[q].uncertainty == 0.0;
            common.push(if exact {
                Quadratic::from_linear(&(s[p].clone() - s[q].clone()))
            } else {
                squared_norm(&points[p]) - squared_norm(&points[q])
            });
        }
        // Ranging's bounds lo ≤ |P| / |Q| ≤ hi, as lo²·|Q|² − |P|² ≤ 0 and |P|² − hi²·|Q|² ≤ 0.
        for p in 0..3 {
            for q in (0..3).filter(|&q| q != p) {
                let (lo, hi) = ratios.of(p, q);
                if hi.is_finite() {
                    common.push(squared_norm(&points[p]) - squared_norm(&points[q]) * (hi * hi));
                }
                if lo > 0.0 {
                    common.push(squared_norm(&points[q]) * (lo * lo) - squared_norm(&points[p]));
                }
            }
        }
        Formulation {
            points,
            lower,
            upper,
            common,
        }
    }

    /// `(A, B, C)`, `(B, C, A)` or `(C, A, B)` for relation `k` of [`TripleRelations`].
    fn rotated(&self, k: usize) -> [&Point2<Linear>; 3] {
        [
            &self.points[k],
            &self.points[(k + 1) % 3],
            &self.points[(k + 2) % 3],
        ]
    }
}

fn squared_norm(p: &Point2<Linear>) -> Quadratic {
    p.x.mul(&p.x) + p.y.mul(&p.y)
}
