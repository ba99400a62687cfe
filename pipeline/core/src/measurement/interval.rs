//! Measurement with uncertain bearings by interval subdivision (000 §IV extended to bearing
//! intervals).
//!
//! Ranges are normalised to `ρ_A + ρ_B + ρ_C = 1` (every boundary function is homogeneous of
//! degree 2 in the ranges), so the unknowns `(ρ_A, ρ_B)` fill a triangle and the range order is
//! a set of linear cuts. Each bearing is an interval. On a box of `(ρ_A, ρ_B)` the boundary
//! functions are enclosed by interval arithmetic over the ranges *and* the bearing intervals;
//! a region is ruled out of the box when one of its signs is contradicted by a whole enclosure.
//! Boxes are halved down to [`MAX_DEPTH`]; whatever is not ruled out by then is kept. The result
//! is therefore a sound superset of the regions the observation allows — exactly it, up to the
//! regions whose boundary lies within the enclosures' width of an allowed arrangement.

use super::Bearing;
use crate::calculus::RelationSet;
use crate::edc::SIGNS;
use crate::geometry::{boundary_values, Coordinate, Point2};
use std::f64::consts::FRAC_PI_2;
use std::ops::{Add, Sub};

/// Halvings of the range box: the smallest boxes are 2⁻⁷ wide in each range. Deeper boxes
/// (2⁻¹⁰) doubled the mapping time of `pipeline run` on real bearing intervals; shallower ones
/// keep more regions, never fewer than the truth needs.
pub const MAX_DEPTH: u32 = 14;

/// A closed interval of reals.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Interval {
    lo: f64,
    hi: f64,
}

impl Interval {
    fn new(lo: f64, hi: f64) -> Interval {
        Interval { lo, hi }
    }

    fn scale(self, k: Interval) -> Interval {
        let p = [
            self.lo * k.lo,
            self.lo * k.hi,
            self.hi * k.lo,
            self.hi * k.hi,
        ];
        Interval::new(
            p.iter().copied().fold(f64::INFINITY, f64::min),
            p.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        )
    }

    /// Entirely above (`sign > 0`) or below zero, beyond rounding. The arithmetic is not
    /// outward-rounded; every quantity is O(1) (ranges on the unit simplex, unit directions), so
    /// an absolute slack of 10⁻¹³ plus 10⁻¹² relative exceeds what a boundary function's dozen
    /// operations can lose.
    fn excludes_sign(self, sign: i8) -> bool {
        let slack = 1e-13 + 1e-12 * (self.lo.abs() + self.hi.abs());
        if sign > 0 {
            self.hi < -slack
        } else {
            self.lo > slack
        }
    }
}

impl Add for Interval {
    type Output = Interval;
    fn add(self, o: Interval) -> Interval {
        Interval::new(self.lo + o.lo, self.hi + o.hi)
    }
}

impl Sub for Interval {
    type Output = Interval;
    fn sub(self, o: Interval) -> Interval {
        Interval::new(self.lo - o.hi, self.hi - o.lo)
    }
}

impl Coordinate for Interval {
    type Product = Interval;
    fn mul(&self, o: &Interval) -> Interval {
        self.scale(*o)
    }
}

/// `cos` and `sin` over the bearing interval: the values at its ends and at every multiple of
/// a right angle inside it.
fn direction(b: &Bearing) -> (Interval, Interval) {
    let (lo, hi) = (b.angle - b.uncertainty, b.angle + b.uncertainty);
    let mut cos = Interval::new(lo.cos().min(hi.cos()), lo.cos().max(hi.cos()));
    let mut sin = Interval::new(lo.sin().min(hi.sin()), lo.sin().max(hi.sin()));
    let mut k = (lo / FRAC_PI_2).ceil();
    while k * FRAC_PI_2 <= hi {
        let (c, s) = match (k as i64).rem_euclid(4) {
            0 => (1.0, 0.0),
            1 => (0.0, 1.0),
            2 => (-1.0, 0.0),
            _ => (0.0, -1.0),
        };
        cos = Interval::new(cos.lo.min(c), cos.hi.max(c));
        sin = Interval::new(sin.lo.min(s), sin.hi.max(s));
        k += 1.0;
    }
    (cos, sin)
}

/// The regions of `AB:C`, `BC:A`, `CA:B` among `candidates` that cannot be ruled out, given
/// that `known` are possible already (e.g. reached at the nominal bearings).
pub fn by_intervals(
    bearings: [Bearing; 3],
    nearer: &[(usize, usize)],
    candidates: [RelationSet; 3],
    known: [RelationSet; 3],
) -> [RelationSet; 3] {
    let directions = bearings.map(|b| direction(&b));
    let mut kept = known;
    let mut pending: [RelationSet; 3] = std::array::from_fn(|k| candidates[k].difference(known[k]));
    let mut stack = vec![(Interval::new(0.0, 1.0), Interval::new(0.0, 1.0), 0u32)];
    while let Some((ra, rb, depth)) = stack.pop() {
        if pending.iter().all(|p| p.is_empty()) {
            break;
        }
        let rc = Interval::new(1.0 - ra.hi - rb.hi, 1.0 - ra.lo - rb.lo);
        if rc.hi <= 0.0 {
            continue;
        }
        let rc = Interval::new(rc.lo.max(0.0), rc.hi);
        let ranges = [ra, rb, rc];
        if nearer.iter().any(|&(p, q)| ranges[p].lo >= ranges[q].hi) {
            continue;
        }
        let points: [Point2<Interval>; 3] = std::array::from_fn(|i| {
            let (cos, sin) = directions[i];
            Point2::new(ranges[i].scale(cos), ranges[i].scale(sin))
        });
        let mut alive = false;
        for k in 0..3 {
            let values = boundary_values(&points[k], &points[(k + 1) % 3], &points[(k + 2) % 3]);
            for region in pending[k].iter() {
                let signs = SIGNS[region as usize - 1];
                if values.iter().zip(signs).any(|(v, s)| v.excludes_sign(s)) {
                    continue;
                }
                if depth == MAX_DEPTH {
                    kept[k] = kept[k].with(region);
                    pending[k] = pending[k].without(region);
                } else {
                    alive = true;
                }
            }
        }
        if alive {
            let (ma, mb) = (0.5 * (ra.lo + ra.hi), 0.5 * (rb.lo + rb.hi));
            let split_a = ra.hi - ra.lo >= rb.hi - rb.lo;
            let halves = if split_a {
                [
                    (Interval::new(ra.lo, ma), rb),
                    (Interval::new(ma, ra.hi), rb),
                ]
            } else {
                [
                    (ra, Interval::new(rb.lo, mb)),
                    (ra, Interval::new(mb, rb.hi)),
                ]
            };
            for (a, b) in halves {
                stack.push((a, b, depth + 1));
            }
        }
    }
    kept
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn direction_encloses_sampled_angles() {
        for (angle, delta) in [(0.0, 0.1), (1.5, 0.3), (3.1, 0.2), (-2.0, 0.7), (4.7, 0.01)] {
            let (cos, sin) = direction(&Bearing {
                angle,
                uncertainty: delta,
            });
            for i in 0..=100 {
                let t: f64 = angle - delta + 2.0 * delta * i as f64 / 100.0;
                assert!(cos.lo <= t.cos() && t.cos() <= cos.hi);
                assert!(sin.lo <= t.sin() && t.sin() <= sin.hi);
            }
        }
    }
}
