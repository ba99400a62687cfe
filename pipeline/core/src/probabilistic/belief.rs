//! A belief over the EDC states of one triple `AB:C` (002 §II: `S^{AB:C}`, a distribution over
//! the `m = 20` regions).

use crate::calculus::RelationSet;

/// Number of EDC states.
pub const STATES: usize = 20;

/// A normalized probability over EDC states `1..=20` (index `r − 1`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Belief([f64; STATES]);

impl Belief {
    /// All states equally likely.
    pub fn uniform() -> Belief {
        Belief([1.0 / STATES as f64; STATES])
    }

    /// State `state` (1..=20) for certain.
    ///
    /// # Panics
    /// If `state` is not an EDC state.
    pub fn certain(state: u8) -> Belief {
        assert!((1..=STATES as u8).contains(&state), "EDC states are 1..=20");
        let mut p = [0.0; STATES];
        p[state as usize - 1] = 1.0;
        Belief(p)
    }

    /// `weights` normalized; `None` when they are not finite and non-negative with a positive
    /// sum.
    pub fn from_weights(weights: [f64; STATES]) -> Option<Belief> {
        if weights.iter().any(|w| !(w.is_finite() && *w >= 0.0)) {
            return None;
        }
        let total: f64 = weights.iter().sum();
        (total > 0.0 && total.is_finite()).then(|| Belief(weights.map(|w| w / total)))
    }

    /// `P(state)`.
    pub fn probability(&self, state: u8) -> f64 {
        self.0[state as usize - 1]
    }

    pub fn probabilities(&self) -> &[f64; STATES] {
        &self.0
    }

    /// The states of positive probability: the set the deterministic map would hold.
    pub fn support(&self) -> RelationSet {
        RelationSet::from_relations((1..=STATES as u8).filter(|&r| self.probability(r) > 0.0))
    }

    /// The most probable state (the lowest-numbered one on a tie).
    pub fn most_likely(&self) -> u8 {
        (1..=STATES as u8)
            .max_by(|&a, &b| {
                self.probability(a)
                    .total_cmp(&self.probability(b))
                    .then(b.cmp(&a))
            })
            .expect("20 states")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn beliefs_are_normalized_and_refuse_bad_weights() {
        let mut w = [0.0; STATES];
        w[2] = 3.0;
        w[7] = 1.0;
        let b = Belief::from_weights(w).unwrap();
        assert!((b.probabilities().iter().sum::<f64>() - 1.0).abs() < 1e-12);
        assert_eq!(b.probability(3), 0.75);
        assert_eq!(b.support(), RelationSet::from_relations([3, 8]));
        assert_eq!(b.most_likely(), 3);
        assert!(Belief::from_weights([0.0; STATES]).is_none());
        w[0] = f64::NAN;
        assert!(Belief::from_weights(w).is_none());
        w[0] = -1.0;
        assert!(Belief::from_weights(w).is_none());
        assert_eq!(Belief::uniform().support().len(), 20);
    }
}
