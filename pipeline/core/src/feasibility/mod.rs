//! Feasibility of conjunctions of strict quadratic inequalities in a box (000 §V, Algorithm 1).
//!
//! [`BranchAndBound`] decides `∃x ∈ [lo, hi]: q_j(x) < 0 ∀j` with three honest outcomes:
//! a checked witness, a proof of infeasibility, or "undecided" when the budget runs out.
//! Callers must treat [`Outcome::Undecided`] as feasible: excluding a possible state would make
//! a map unsound, including an impossible one only makes it weaker.

mod box_minimum;
mod branch_and_bound;
mod propagation;
mod quadratic;
mod relaxation;

pub use box_minimum::{interval_minimum, minimum_over_box, EXACT_FACE_LIMIT};
pub use branch_and_bound::{BranchAndBound, Settings, Statistics};
pub use propagation::contract;
pub use quadratic::{Linear, Quadratic, Shape};
pub use relaxation::{joint_relaxation, RelaxationBound};

/// The answer for one conjunction.
#[derive(Clone, Debug, PartialEq)]
pub enum Outcome {
    /// A point inside the box at which every constraint is strictly negative.
    Feasible(Vec<f64>),
    /// No point of the box satisfies all constraints (up to the documented margin).
    Infeasible,
    /// The budget ran out first; treat as feasible.
    Undecided,
}

impl Outcome {
    /// Whether a sound caller must keep the state this problem stands for.
    pub fn possibly_feasible(&self) -> bool {
        !matches!(self, Outcome::Infeasible)
    }
}

/// A family of conjunctions sharing a box and `common` constraints: alternative `k` asks for
/// `common ∧ alternatives[k]`. Deciding them together shares every box's work, e.g. the 20
/// candidate regions of one measured triple. (Alternatives are only propagated on boxes where a
/// single one is left, so problems whose alternatives contract the box strongly — like the
/// composition table's — are faster decided one by one.)
#[derive(Clone, Debug)]
pub struct Problem {
    pub lower: Vec<f64>,
    pub upper: Vec<f64>,
    pub common: Vec<Quadratic>,
    pub alternatives: Vec<Vec<Quadratic>>,
}

impl Problem {
    /// A single conjunction.
    pub fn single(lower: Vec<f64>, upper: Vec<f64>, constraints: Vec<Quadratic>) -> Problem {
        Problem {
            lower,
            upper,
            common: Vec::new(),
            alternatives: vec![constraints],
        }
    }

    pub fn dimension(&self) -> usize {
        self.lower.len()
    }

    /// Whether `x` lies in the box and satisfies `common ∧ alternatives[k]` strictly.
    pub fn satisfies(&self, k: usize, x: &[f64]) -> bool {
        x.iter()
            .zip(self.lower.iter().zip(&self.upper))
            .all(|(v, (l, u))| v >= l && v <= u)
            && self
                .common
                .iter()
                .chain(&self.alternatives[k])
                .all(|q| q.eval(x) < 0.0)
    }
}
