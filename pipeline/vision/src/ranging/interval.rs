//! Closed intervals of horizontal range, the currency of every range cue.

use serde::{Deserialize, Serialize};

/// `[low, high]` metres; `high` may be `f64::INFINITY` (a cue that bounds only from below).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct RangeInterval {
    pub low: f64,
    pub high: f64,
}

impl RangeInterval {
    /// The interval between two bounds in either order, clamped at 0.
    pub fn new(a: f64, b: f64) -> RangeInterval {
        RangeInterval {
            low: a.min(b).max(0.0),
            high: a.max(b).max(0.0),
        }
    }

    pub fn unbounded() -> RangeInterval {
        RangeInterval {
            low: 0.0,
            high: f64::INFINITY,
        }
    }

    pub fn intersection(self, other: RangeInterval) -> Option<RangeInterval> {
        let low = self.low.max(other.low);
        let high = self.high.min(other.high);
        (low <= high).then_some(RangeInterval { low, high })
    }

    pub fn hull(self, other: RangeInterval) -> RangeInterval {
        RangeInterval {
            low: self.low.min(other.low),
            high: self.high.max(other.high),
        }
    }

    pub fn contains(self, range: f64) -> bool {
        (self.low..=self.high).contains(&range)
    }

    /// Whether every range of `self` is below every range of `other`: the evidence separates
    /// the two, so "nearer than" may be asserted.
    pub fn entirely_below(self, other: RangeInterval) -> bool {
        self.high < other.low
    }

    pub fn as_array(self) -> [f64; 2] {
        [self.low, self.high]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn intersection_hull_and_separation() {
        let a = RangeInterval::new(3.0, 1.0);
        let b = RangeInterval::new(2.0, 5.0);
        assert_eq!(a.intersection(b), Some(RangeInterval::new(2.0, 3.0)));
        assert_eq!(a.hull(b), RangeInterval::new(1.0, 5.0));
        assert!(!a.entirely_below(b));
        assert!(a.entirely_below(RangeInterval::new(3.5, f64::INFINITY)));
        assert_eq!(a.intersection(RangeInterval::new(4.0, 6.0)), None);
        assert_eq!(RangeInterval::new(-1.0, 2.0).low, 0.0);
    }
}
