//! Measurement with uncertain bearings by interval subdivision (000 §IV extended to bearing
//! intervals).
//!
//! Every boundary function is homogeneous of degree 2 in the ranges, so only their ratios
//! matter. The unknowns are the logarithms of two landmarks' ranges over a third's, the
//! *reference*, chosen so that the range order becomes bounds on them: a landmark nearer than
//! the reference has a ratio in `[1/K, 1]`, a farther one `[1, K]`, an unordered one
//! `[1/K, K]` ([`MAX_RANGE_RATIO`] = K). Every partial order of three landmarks is such a box
//! for some reference, so no box straddles an order constraint, and no box holds two
//! landmarks at one point (which the range simplex of an earlier version did at its corners:
//! there every boundary function vanishes, and 2.4 times the true regions were kept at 0.17°
//! of bearing uncertainty). Each bearing is an interval. On a box the boundary functions are
//! enclosed by interval arithmetic over the ranges *and* the bearing intervals; a region is
//! ruled out of the box when one of its signs is contradicted by a whole enclosure. Boxes are
//! halved (in log-ratio, so precision is relative) down to [`MAX_DEPTH`]; whatever is not ruled
//! out by then is kept. The result is therefore a sound superset of the regions the
//! observation allows — exactly it, up to the regions whose boundary lies within the
//! enclosures' width of an allowed arrangement.

use super::range_ratios::RangeRatios;
use super::Bearing;
use crate::calculus::RelationSet;
use crate::edc::SIGNS;
use std::f64::consts::FRAC_PI_2;
use std::ops::{Add, Sub};

/// Halvings of the log-ratio box: the smallest boxes are 2⁻¹⁴ of its sides, under 0.2 % in
/// each ratio on the widest side. `tests/measurement.rs` measures what is kept beyond sampled
/// arrangements (0.4 % of states at δ = 0.001 rad, 1.3 % at 0.003): depth 20 kept 4 %, 32
/// no fewer than 28 and cost 15 % more time on a marsyard run.
pub const MAX_DEPTH: u32 = 28;

/// Largest ratio of two landmarks' ranges at one station: 10⁶ (a rock a centimetre away with
/// another ten kilometres off). The bound is what keeps the box compact; it excludes nothing a
/// camera can see.
pub const MAX_RANGE_RATIO: f64 = 1e6;

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

    /// The products of `self`, which holds no negative number (a range, a sum or product of
    /// ranges), with `k`: the extremes are `k`'s ends times whichever of `self`'s ends the sign
    /// of that end picks, the same products the four-corner rule takes.
    fn scale(self, k: Interval) -> Interval {
        debug_assert!(self.lo >= 0.0, "scale of an interval reaching below zero");
        Interval::new(
            k.lo * if k.lo >= 0.0 { self.lo } else { self.hi },
            k.hi * if k.hi >= 0.0 { self.hi } else { self.lo },
        )
    }

    /// Entirely above (`sign > 0`) or below zero, beyond rounding. The arithmetic is not
    /// outward-rounded; every quantity is O(1) (ranges scaled to at most 1, cosines and sines), so
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
/// the range order `nearer` and the range ratios it and the ranging allow (`bounds`), and
/// that `known` are possible already (e.g. reached at the nominal bearings).
pub fn by_intervals(
    bearings: [Bearing; 3],
    nearer: &[(usize, usize)],
    bounds: &RangeRatios,
    candidates: [RelationSet; 3],
    known: [RelationSet; 3],
) -> [RelationSet; 3] {
    // The cosine and sine of the turn from each bearing to each other.
    let turns: [[(Interval, Interval); 3]; 3] = std::array::from_fn(|i| {
        std::array::from_fn(|j| {
            direction(&Bearing {
                angle: bearings[j].angle - bearings[i].angle,
                uncertainty: bearings[i].uncertainty + bearings[j].uncertainty,
            })
        })
    });
    let (others, start) = ratio_box(nearer, bounds);
    let mut kept = known;
    if start.iter().any(|r| r.lo > r.hi) {
        return kept;
    }
    let mut pending: [RelationSet; 3] = std::array::from_fn(|k| candidates[k].difference(known[k]));
    // Each box carries the regions its ancestors could not rule out: an enclosure over a
    // sub-box lies within the enclosure over the box, so what a box excludes stays excluded
    // below it, and only the relations with a region left need their enclosures. A box also
    // carries its ratios (the exponentials of its log-ratio bounds).
    let ratios = start.map(|r| Interval::new(r.lo.exp(), r.hi.exp()));
    let mut stack = vec![(start, ratios, 0u32, pending)];
    while let Some((log_ratios, ratios, depth, inherited)) = stack.pop() {
        if pending.iter().all(|p| p.is_empty()) {
            break;
        }
        let open: [RelationSet; 3] = std::array::from_fn(|k| inherited[k].intersection(pending[k]));
        if open.iter().all(|p| p.is_empty()) {
            continue;
        }
        // Ranges over the box, scaled so that the largest is at most 1 (signs do not change,
        // and every quantity stays O(1) for the rounding slack).
        let mut ranges = [Interval::new(1.0, 1.0); 3];
        for (slot, &i) in others.iter().enumerate() {
            ranges[i] = ratios[slot];
        }
        if nearer.iter().any(|&(p, q)| ranges[p].lo >= ranges[q].hi)
            || outside(&ranges, bounds, others)
        {
            continue;
        }
        let largest = ranges.iter().map(|r| r.hi).fold(0.0, f64::max);
        let ranges = ranges.map(|r| Interval::new(r.lo / largest, r.hi / largest));
        let mut alive = [RelationSet::EMPTY; 3];
        for k in (0..3).filter(|&k| !open[k].is_empty()) {
            let labelled = Labelled::new(&ranges, &turns, [k, (k + 1) % 3, (k + 2) % 3]);
            let natural = labelled.enclosures();
            let mut left = not_ruled_out(open[k], &natural);
            if !left.is_empty() {
                left = not_ruled_out(left, &tightened(&labelled, natural));
            }
            for region in left.iter() {
                if depth == MAX_DEPTH {
                    kept[k] = kept[k].with(region);
                    pending[k] = pending[k].without(region);
                } else {
                    alive[k] = alive[k].with(region);
                }
            }
        }
        if alive.iter().any(|a| !a.is_empty()) {
            let widths = log_ratios.map(|r| r.hi - r.lo);
            let axis = usize::from(widths[1] > widths[0]);
            let middle = 0.5 * (log_ratios[axis].lo + log_ratios[axis].hi);
            let at_middle = middle.exp();
            for (half, ratio) in [
                (
                    Interval::new(log_ratios[axis].lo, middle),
                    Interval::new(ratios[axis].lo, at_middle),
                ),
                (
                    Interval::new(middle, log_ratios[axis].hi),
                    Interval::new(at_middle, ratios[axis].hi),
                ),
            ] {
                let (mut next, mut next_ratios) = (log_ratios, ratios);
                next[axis] = half;
                next_ratios[axis] = ratio;
                stack.push((next, next_ratios, depth + 1, alive));
            }
        }
    }
    kept
}

/// The regions of `regions` whose signs no enclosure of `values` contradicts.
fn not_ruled_out(regions: RelationSet, values: &[Interval; 6]) -> RelationSet {
    RelationSet::from_relations(regions.iter().filter(|&region| {
        let signs = SIGNS[region as usize - 1];
        !values.iter().zip(signs).any(|(v, s)| v.excludes_sign(s))
    }))
}

/// The ranges of A, B, C (`r`, in that order) and the cosines and sines of the turns between
/// their bearings: what the boundary functions and their derivatives are written in.
#[derive(Clone, Copy)]
struct Labelled {
    r: [Interval; 3],
    cos_ab: Interval,
    sin_ab: Interval,
    cos_bc: Interval,
    sin_bc: Interval,
    cos_ac: Interval,
    sin_ca: Interval,
}

impl Labelled {
    /// A, B, C = the box's `ranges` and bearings at indices `[a, b, c]`.
    fn new(
        ranges: &[Interval; 3],
        turns: &[[(Interval, Interval); 3]; 3],
        [a, b, c]: [usize; 3],
    ) -> Labelled {
        Labelled {
            r: [ranges[a], ranges[b], ranges[c]],
            cos_ab: turns[a][b].0,
            sin_ab: turns[a][b].1,
            cos_bc: turns[b][c].0,
            sin_bc: turns[b][c].1,
            cos_ac: turns[a][c].0,
            sin_ca: turns[c][a].1,
        }
    }

    /// The same bearings with the ranges of A, B, C set to `r`.
    fn with_ranges(self, r: [Interval; 3]) -> Labelled {
        Labelled { r, ..self }
    }

    /// Enclosures of the six boundary functions of `C` relative to `AB`, in the order of
    /// `geometry::boundary_values`.
    fn enclosures(&self) -> [Interval; 6] {
        std::array::from_fn(|f| self.boundary(f))
    }

    /// B·C − A·C, which three of the functions share.
    fn towards_c(&self) -> Interval {
        let [ra, rb, _] = self.r;
        rb.scale(self.cos_bc) - ra.scale(self.cos_ac)
    }

    /// Enclosure of boundary function `f` (see [`Labelled::enclosures`]), written in the ranges
    /// and the cosines and sines of the turns between bearings, and grouped so that each range
    /// multiplies what it scales: expanded as differences of squared distances, a far landmark's
    /// range interval enters twice and its width swamps a value orders of magnitude smaller.
    fn boundary(&self, f: usize) -> Interval {
        let [ra, rb, rc] = self.r;
        match f {
            0 => {
                ra.scale(rb).scale(self.sin_ab)
                    + rc.scale(rb.scale(self.sin_bc) + ra.scale(self.sin_ca))
            }
            1 => ra.scale(ra - rb.scale(self.cos_ab)) + rc.scale(self.towards_c()),
            2 => rb.scale(ra.scale(self.cos_ab) - rb) + rc.scale(self.towards_c()),
            3 => (ra + rb).scale(ra - rb) + twice(rc.scale(self.towards_c())),
            4 => {
                rc.scale(rc - twice(ra.scale(self.cos_ac)))
                    + rb.scale(twice(ra.scale(self.cos_ab)) - rb)
            }
            _ => {
                rc.scale(rc - twice(rb.scale(self.cos_bc)))
                    + ra.scale(twice(rb.scale(self.cos_ab)) - ra)
            }
        }
    }

    /// Enclosures of the derivatives of boundary function `f` in the ranges of A, B and C over
    /// the box.
    fn slopes(&self, f: usize) -> [Interval; 3] {
        let [ra, rb, rc] = self.r;
        match f {
            0 => [
                rb.scale(self.sin_ab) + rc.scale(self.sin_ca),
                ra.scale(self.sin_ab) + rc.scale(self.sin_bc),
                rb.scale(self.sin_bc) + ra.scale(self.sin_ca),
            ],
            1 => [
                twice(ra) - rb.scale(self.cos_ab) - rc.scale(self.cos_ac),
                rc.scale(self.cos_bc) - ra.scale(self.cos_ab),
                self.towards_c(),
            ],
            2 => [
                rb.scale(self.cos_ab) - rc.scale(self.cos_ac),
                ra.scale(self.cos_ab) - twice(rb) + rc.scale(self.cos_bc),
                self.towards_c(),
            ],
            3 => [
                twice(ra - rc.scale(self.cos_ac)),
                twice(rc.scale(self.cos_bc) - rb),
                twice(self.towards_c()),
            ],
            4 => [
                twice(rb.scale(self.cos_ab) - rc.scale(self.cos_ac)),
                twice(ra.scale(self.cos_ab) - rb),
                twice(rc - ra.scale(self.cos_ac)),
            ],
            _ => [
                twice(rb.scale(self.cos_ab) - ra),
                twice(ra.scale(self.cos_ab) - rc.scale(self.cos_bc)),
                twice(rc - rb.scale(self.cos_bc)),
            ],
        }
    }
}

/// `x + x`.
fn twice(x: Interval) -> Interval {
    x + x
}

/// `values` (`labelled`'s [`Labelled::enclosures`]) tightened where one straddles zero, by
/// monotonicity: where an enclosure of a function's derivative in a range excludes zero over
/// the whole box (and every bearing in its interval), the function's least and greatest values
/// lie on the box's faces at that range's ends, where the range is a point.
/// The natural enclosure counts a range's width once for every time the range appears in the
/// function, so boxes near a region's boundary had to be halved much further before it could
/// rule the region out: on `qrm-bench --measure 30 --uncertainty 0.1`, 3.5 times fewer boxes.
fn tightened(labelled: &Labelled, values: [Interval; 6]) -> [Interval; 6] {
    std::array::from_fn(|f| {
        let value = values[f];
        if value.excludes_sign(1) || value.excludes_sign(-1) {
            return value;
        }
        let (mut low, mut high) = (labelled.r, labelled.r);
        for (role, slope) in labelled.slopes(f).iter().enumerate() {
            let range = labelled.r[role];
            let (lo, hi) = (
                Interval::new(range.lo, range.lo),
                Interval::new(range.hi, range.hi),
            );
            // Rising in this range over the whole box, or falling.
            if slope.excludes_sign(-1) {
                (low[role], high[role]) = (lo, hi);
            } else if slope.excludes_sign(1) {
                (low[role], high[role]) = (hi, lo);
            }
        }
        let least = labelled.with_ranges(low).boundary(f).lo;
        let greatest = labelled.with_ranges(high).boundary(f).hi;
        Interval::new(value.lo.max(least), value.hi.min(greatest))
    })
}

/// Whether the box's ranges (relative to the reference) break a bound on some ratio of two of
/// them everywhere: the pair of the two others, whose ratio is not one of the box's sides.
fn outside(ranges: &[Interval; 3], ratios: &RangeRatios, [p, q]: [usize; 2]) -> bool {
    let (lo, hi) = ratios.of(p, q);
    ranges[p].lo > hi * ranges[q].hi || ranges[p].hi < lo * ranges[q].lo
}

/// The two landmarks other than the reference, and the box of their log range ratios to it
/// that the range order `nearer` and the ranging (`ratios`) allow: for a reference that every
/// ordered pair involves (or whose pairs imply it), the order is the box's bounds. Any partial
/// order of three has one. A side is empty (`lo > hi`) when nothing fits.
fn ratio_box(nearer: &[(usize, usize)], ratios: &RangeRatios) -> ([usize; 2], [Interval; 2]) {
    let limit = MAX_RANGE_RATIO.ln();
    let ordered = |p: usize, q: usize| nearer.contains(&(p, q));
    let explained = |r: usize| {
        nearer
            .iter()
            .all(|&(p, q)| p == r || q == r || (ordered(p, r) && ordered(r, q)))
    };
    let reference = (0..3).find(|&r| explained(r)).unwrap_or(0);
    let others = [(reference + 1) % 3, (reference + 2) % 3];
    let bounds = others.map(|i| {
        let order = if ordered(i, reference) {
            Interval::new(-limit, 0.0)
        } else if ordered(reference, i) {
            Interval::new(0.0, limit)
        } else {
            Interval::new(-limit, limit)
        };
        let (lo, hi) = ratios.of(i, reference);
        Interval::new(order.lo.max(lo.ln()), order.hi.min(hi.ln()))
    });
    (others, bounds)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{boundary_values, Point};
    use proptest::prelude::*;

    proptest! {
        /// Every arrangement in a box of ranges and bearing intervals has its six boundary
        /// values (computed from its points, `geometry::boundary_values`) inside the
        /// enclosures, natural and tightened by monotonicity, for every labelling of A, B, C.
        #[test]
        fn tightened_enclosures_hold_sampled_arrangements(
            angles in proptest::collection::vec(0.0f64..std::f64::consts::TAU, 3),
            widths in proptest::collection::vec(0.0f64..0.05, 3),
            lows in proptest::collection::vec(0.01f64..1.0, 3),
            spans in proptest::collection::vec(0.0f64..1.0, 3),
            first in 0usize..3,
            samples in proptest::collection::vec(proptest::collection::vec(0.0f64..=1.0, 6), 40),
        ) {
            let bearings: [Bearing; 3] = std::array::from_fn(|i| Bearing {
                angle: angles[i],
                uncertainty: widths[i],
            });
            let turns: [[(Interval, Interval); 3]; 3] = std::array::from_fn(|i| {
                std::array::from_fn(|j| {
                    direction(&Bearing {
                        angle: bearings[j].angle - bearings[i].angle,
                        uncertainty: bearings[i].uncertainty + bearings[j].uncertainty,
                    })
                })
            });
            let ranges: [Interval; 3] =
                std::array::from_fn(|i| Interval::new(lows[i], lows[i] * (1.0 + spans[i])));
            let order = [first, (first + 1) % 3, (first + 2) % 3];
            let labelled = Labelled::new(&ranges, &turns, order);
            let natural = labelled.enclosures();
            let tight = tightened(&labelled, natural);
            for sample in &samples {
                let points: [Point; 3] = std::array::from_fn(|i| {
                    let range = ranges[i].lo + sample[i] * (ranges[i].hi - ranges[i].lo);
                    let angle = bearings[i].angle + (2.0 * sample[3 + i] - 1.0) * widths[i];
                    Point::new(range * angle.cos(), range * angle.sin())
                });
                let values = boundary_values(&points[order[0]], &points[order[1]], &points[order[2]]);
                for f in 0..6 {
                    let slack = 1e-12;
                    for (name, e) in [("natural", natural[f]), ("tightened", tight[f])] {
                        prop_assert!(
                            e.lo - slack <= values[f] && values[f] <= e.hi + slack,
                            "function {f}: {} outside the {name} enclosure [{}, {}]",
                            values[f], e.lo, e.hi
                        );
                    }
                    prop_assert!(tight[f].lo >= natural[f].lo && tight[f].hi <= natural[f].hi);
                }
            }
        }
    }

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
