//! Branch and bound over boxes (000 §V, Algorithm 1), extended:
//! - exact per-constraint minima on each box ([`minimum_over_box`]),
//! - interval constraint propagation before bounding ([`contract`]),
//! - a joint RLT relaxation of the whole conjunction ([`joint_relaxation`]) for boxes that the
//!   per-constraint bounds cannot prune (straddled or touching boundaries),
//! - many alternatives decided in one search, each dropped from a box as soon as it is refuted
//!   there, each finished globally as soon as a witness is found.

use super::box_minimum::minimum_over_box;
use super::propagation::{contract, WIDEN};
use super::relaxation::joint_relaxation;
use super::{Outcome, Problem, Quadratic};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Knobs of the search. The defaults decide every EDC composition and measurement problem.
#[derive(Clone, Debug)]
pub struct Settings {
    /// Seed of the random witness candidates: same seed, same answers and witnesses.
    pub seed: u64,
    /// Boxes processed before giving up (→ [`Outcome::Undecided`]).
    pub max_boxes: usize,
    /// Boxes narrower than this fraction of the initial box in every unknown are not split.
    pub min_relative_width: f64,
    /// A box is refuted when every point of it misses some constraint `q_j` by less than
    /// `margin × scale(q_j)`: feasible sets thinner than that are treated as empty.
    pub margin: f64,
    /// Use the joint relaxation at all.
    pub use_relaxation: bool,
    /// Use interval propagation.
    pub use_propagation: bool,
    /// Random witness candidates tried per box, besides its centre.
    pub samples_per_box: usize,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            seed: 0x9E37_79B9_7F4A_7C15,
            max_boxes: 200_000,
            min_relative_width: 1e-9,
            margin: 1e-7,
            use_relaxation: true,
            use_propagation: true,
            samples_per_box: 2,
        }
    }
}

/// Work counters of one search.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Statistics {
    pub boxes: usize,
    pub relaxations: usize,
    pub relaxation_refutations: usize,
    pub propagation_refutations: usize,
}

/// The feasibility engine. Cheap to construct; holds only settings.
#[derive(Clone, Debug, Default)]
pub struct BranchAndBound {
    pub settings: Settings,
}

struct Cell {
    lo: Vec<f64>,
    hi: Vec<f64>,
    /// Alternatives not yet refuted in this box.
    open: u64,
}

impl BranchAndBound {
    pub fn new(settings: Settings) -> Self {
        BranchAndBound { settings }
    }

    /// Decides a single conjunction.
    pub fn decide(&self, lower: &[f64], upper: &[f64], constraints: &[Quadratic]) -> Outcome {
        let problem = Problem::single(lower.to_vec(), upper.to_vec(), constraints.to_vec());
        self.solve(&problem).0.remove(0)
    }

    /// Decides every alternative of `problem` (at most 64) in one search.
    pub fn solve(&self, problem: &Problem) -> (Vec<Outcome>, Statistics) {
        let k = problem.alternatives.len();
        assert!(k <= 64, "at most 64 alternatives per search");
        let n = problem.dimension();
        let s = &self.settings;
        let mut rng = ChaCha8Rng::seed_from_u64(s.seed);
        let mut stats = Statistics::default();
        let mut witnesses: Vec<Option<Vec<f64>>> = vec![None; k];
        let mut unresolved: u64 = 0; // alternatives left open in boxes that may not be split
        let all: u64 = if k == 64 { u64::MAX } else { (1u64 << k) - 1 };
        let mut pending = all; // alternatives without a witness yet
        let widths: Vec<f64> = (0..n)
            .map(|i| problem.upper[i] - problem.lower[i])
            .collect();
        let mut stack = vec![Cell {
            lo: problem.lower.clone(),
            hi: problem.upper.clone(),
            open: all,
        }];
        let mut candidate = vec![0.0; n];

        while let Some(mut cell) = stack.pop() {
            cell.open &= pending;
            if cell.open == 0 {
                continue;
            }
            if stats.boxes >= s.max_boxes {
                unresolved |= cell.open;
                continue;
            }
            stats.boxes += 1;

            // Shrink by propagation: common constraints, plus the alternative's own when only
            // one is left in this box.
            if s.use_propagation {
                let mut active: Vec<&Quadratic> = problem.common.iter().collect();
                if cell.open.count_ones() == 1 {
                    active.extend(&problem.alternatives[cell.open.trailing_zeros() as usize]);
                }
                if !contract(&active, &mut cell.lo, &mut cell.hi, s.margin) {
                    stats.propagation_refutations += 1;
                    continue;
                }
                snap_outward(&mut cell, problem, &widths);
            }
            if refuted(problem.common.iter(), &cell, s.margin) {
                continue;
            }

            // Witness candidates: centre and random points.
            for t in 0..=s.samples_per_box {
                for (i, v) in candidate.iter_mut().enumerate() {
                    *v = if t == 0 {
                        0.5 * (cell.lo[i] + cell.hi[i])
                    } else {
                        rng.random_range(cell.lo[i]..=cell.hi[i])
                    };
                }
                record_witnesses(
                    problem,
                    &candidate,
                    &mut cell.open,
                    &mut pending,
                    &mut witnesses,
                );
            }

            // Per-constraint exact minima, then the joint relaxation.
            let mut open = cell.open;
            while open != 0 {
                let a = open.trailing_zeros() as usize;
                open &= open - 1;
                let alternative = &problem.alternatives[a];
                let bit = 1u64 << a;
                if refuted(alternative.iter(), &cell, s.margin) {
                    cell.open &= !bit;
                    continue;
                }
                if s.use_relaxation {
                    let joint: Vec<&Quadratic> = problem.common.iter().chain(alternative).collect();
                    stats.relaxations += 1;
                    if let Some(bound) = joint_relaxation(&joint, &cell.lo, &cell.hi) {
                        if bound.margin <= s.margin {
                            stats.relaxation_refutations += 1;
                            cell.open &= !bit;
                            continue;
                        }
                        record_witnesses(
                            problem,
                            &bound.point,
                            &mut cell.open,
                            &mut pending,
                            &mut witnesses,
                        );
                    }
                }
            }
            cell.open &= pending;
            if cell.open == 0 {
                continue;
            }

            // Split the relatively widest unknown at its simplest dyadic value (see `split_point`).
            let (axis, rel) = (0..n)
                .map(|i| {
                    (
                        i,
                        (cell.hi[i] - cell.lo[i]) / widths[i].max(f64::MIN_POSITIVE),
                    )
                })
                .max_by(|a, b| a.1.total_cmp(&b.1))
                .expect("at least one unknown");
            if rel < s.min_relative_width {
                unresolved |= cell.open;
                continue;
            }
            let mid = split_point(cell.lo[axis], cell.hi[axis], widths[axis]);
            let mut upper = Cell {
                lo: cell.lo.clone(),
                hi: cell.hi.clone(),
                open: cell.open,
            };
            upper.lo[axis] = mid;
            cell.hi[axis] = mid;
            stack.push(upper);
            stack.push(cell);
        }

        let outcomes = (0..k)
            .map(|a| match witnesses[a].take() {
                Some(x) => Outcome::Feasible(x),
                None if unresolved >> a & 1 == 1 => Outcome::Undecided,
                None => Outcome::Infeasible,
            })
            .collect();
        (outcomes, stats)
    }
}

/// The simplest dyadic value (fewest bits on the grid of the initial box) in the middle 80 % of
/// `[lo, hi]`, nearest the midpoint. A box straddling 0, 1 or ½ — values where EDC boundaries
/// of different frames meet — is cut exactly there, so both halves can be refuted by sign.
fn split_point(lo: f64, hi: f64, total: f64) -> f64 {
    let mid = 0.5 * (lo + hi);
    let (a, b) = (lo + 0.1 * (hi - lo), hi - 0.1 * (hi - lo));
    let mut step = total;
    while step > (hi - lo) * 1e-3 {
        let k = (mid / step).round() * step;
        let candidates = [k, k - step, k + step];
        if let Some(v) = candidates
            .into_iter()
            .filter(|v| *v >= a && *v <= b)
            .min_by(|x, y| (x - mid).abs().total_cmp(&(y - mid).abs()))
        {
            return v;
        }
        step *= 0.5;
    }
    mid
}

/// Rounds a contracted box outward to a dyadic grid of the initial box (spacing about 1/64 of
/// the box's width). Midpoint splits then keep landing on simple values such as 0, 1 and ½,
/// which are where EDC boundaries meet: boxes that end exactly on a shared boundary can be
/// refuted by exact bounds instead of straddling it forever.
fn snap_outward(cell: &mut Cell, problem: &Problem, widths: &[f64]) {
    for (i, &total) in widths.iter().enumerate() {
        let w = cell.hi[i] - cell.lo[i];
        if w <= 0.0 || total <= 0.0 {
            continue;
        }
        let step = total * 2f64.powi((w / total / 64.0).log2().floor() as i32);
        if step > 0.0 && step.is_finite() {
            // Propagation pads its bounds by `WIDEN` against rounding; a bound within that pad
            // of a grid point snaps to it rather than a whole step outward.
            let snap = |v: f64, outward: fn(f64) -> f64| {
                let k = (v / step).round();
                if (v - k * step).abs() <= 2.0 * WIDEN * (1.0 + v.abs()) {
                    k * step
                } else {
                    outward(v / step) * step
                }
            };
            cell.lo[i] = snap(cell.lo[i], f64::floor).max(problem.lower[i]);
            cell.hi[i] = snap(cell.hi[i], f64::ceil).min(problem.upper[i]);
        }
    }
}

/// Whether some constraint stays at or above `−margin·scale` on the whole box.
fn refuted<'a>(
    mut constraints: impl Iterator<Item = &'a Quadratic>,
    cell: &Cell,
    margin: f64,
) -> bool {
    constraints.any(|q| minimum_over_box(q, &cell.lo, &cell.hi) >= -margin * q.scale())
}

fn record_witnesses(
    problem: &Problem,
    x: &[f64],
    open: &mut u64,
    pending: &mut u64,
    witnesses: &mut [Option<Vec<f64>>],
) {
    if !problem.common.iter().all(|q| q.eval(x) < 0.0) {
        return;
    }
    let mut candidates = *open & *pending;
    while candidates != 0 {
        let a = candidates.trailing_zeros() as usize;
        candidates &= candidates - 1;
        if problem.alternatives[a].iter().all(|q| q.eval(x) < 0.0) {
            witnesses[a] = Some(x.to_vec());
            *pending &= !(1u64 << a);
            *open &= !(1u64 << a);
        }
    }
}
