//! Interval constraint propagation: shrinks a box to the hull of the points that can still
//! satisfy `q(x) < 0` for every constraint, one unknown at a time (an HC4-style projection of
//! each quadratic onto each unknown). Cheap, and it removes whole slabs that bisection would
//! otherwise cut away one half at a time.

use super::quadratic::Quadratic;

/// Relative widening applied to every projected interval so rounding never removes a point.
pub(crate) const WIDEN: f64 = 1e-12;

/// Interval of `a x² + p x` for `p ∈ [p_lo, p_hi]`: the set `{x ∈ [lo, hi] : a x² + p x + r ≤ 0
/// for some p}` as a hull `[lo', hi']`, or `None` if empty.
fn project(a: f64, p_lo: f64, p_hi: f64, r: f64, lo: f64, hi: f64) -> Option<(f64, f64)> {
    // For x ≥ 0 the most permissive p is p_lo, for x ≤ 0 it is p_hi.
    let pieces = [
        solve_quadratic_le(a, p_lo, r, lo.max(0.0), hi),
        solve_quadratic_le(a, p_hi, r, lo, hi.min(0.0)),
    ];
    let mut hull: Option<(f64, f64)> = None;
    for (l, u) in pieces.into_iter().flatten() {
        hull = Some(match hull {
            None => (l, u),
            Some((hl, hu)) => (hl.min(l), hu.max(u)),
        });
    }
    hull
}

/// Hull of `{x ∈ [lo, hi] : a x² + b x + c ≤ 0}`.
fn solve_quadratic_le(a: f64, b: f64, c: f64, lo: f64, hi: f64) -> Option<(f64, f64)> {
    if lo > hi {
        return None;
    }
    let f = |x: f64| a * x * x + b * x + c;
    if a == 0.0 {
        if b == 0.0 {
            return (c <= 0.0).then_some((lo, hi));
        }
        let root = -c / b;
        return if b > 0.0 {
            (root >= lo).then_some((lo, root.min(hi)))
        } else {
            (root <= hi).then_some((root.max(lo), hi))
        };
    }
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 {
        // No real roots: the sign of a decides everywhere.
        return (a < 0.0).then_some((lo, hi));
    }
    let sq = disc.sqrt();
    // Numerically stable roots.
    let qv = -0.5 * (b + b.signum() * sq);
    let (mut r1, mut r2) = if qv != 0.0 {
        (qv / a, c / qv)
    } else {
        (0.0, 0.0)
    };
    if r1 > r2 {
        std::mem::swap(&mut r1, &mut r2);
    }
    if a > 0.0 {
        let (l, u) = (r1.max(lo), r2.min(hi));
        (l <= u).then_some((l, u))
    } else {
        // Outside (r1, r2): keep the hull of the parts of [lo, hi] at or beyond the roots.
        let left = (lo <= r1).then_some((lo, r1.min(hi)));
        let right = (hi >= r2).then_some((r2.max(lo), hi));
        match (left, right) {
            (Some((l, _)), Some((_, u))) => Some((l, u)),
            (Some(p), None) | (None, Some(p)) => Some(p),
            (None, None) => (f(lo) <= 0.0 || f(hi) <= 0.0).then_some((lo, hi)),
        }
    }
}

/// Interval product bounds.
fn product_range(a: f64, lo1: f64, hi1: f64, lo2: f64, hi2: f64) -> (f64, f64) {
    let p = [a * lo1 * lo2, a * lo1 * hi2, a * hi1 * lo2, a * hi1 * hi2];
    (
        p.iter().copied().fold(f64::INFINITY, f64::min),
        p.iter().copied().fold(f64::NEG_INFINITY, f64::max),
    )
}

fn square_min(a: f64, lo: f64, hi: f64) -> f64 {
    if a >= 0.0 {
        let m = if lo <= 0.0 && hi >= 0.0 {
            0.0
        } else {
            lo.abs().min(hi.abs())
        };
        a * m * m
    } else {
        a * lo.abs().max(hi.abs()).powi(2)
    }
}

/// Shrinks `[lo, hi]` in place to the hull of the points where every constraint can still hold
/// with the search's margin, `q ≤ −margin·scale(q)` (see `Settings::margin`); bounds are padded
/// by a few ulps against rounding. Returns false when the box is proved empty.
pub fn contract(constraints: &[&Quadratic], lo: &mut [f64], hi: &mut [f64], margin: f64) -> bool {
    let n = lo.len();
    for _round in 0..3 {
        let mut shrunk = false;
        for q in constraints {
            for i in 0..n {
                if !q.involves(i) {
                    continue;
                }
                // q = a x_i² + p x_i + rest, p = b_i + 2 Σ_{j≠i} a_ij x_j.
                let (mut p_lo, mut p_hi) = (q.b[i], q.b[i]);
                let mut rest = q.c + margin.abs() * q.scale();
                for j in 0..n {
                    if j == i {
                        continue;
                    }
                    let aij = 2.0 * q.a(i, j);
                    if aij != 0.0 {
                        p_lo += (aij * lo[j]).min(aij * hi[j]);
                        p_hi += (aij * lo[j]).max(aij * hi[j]);
                    }
                    rest += square_min(q.a(j, j), lo[j], hi[j]);
                    rest += (q.b[j] * lo[j]).min(q.b[j] * hi[j]);
                    for k in j + 1..n {
                        if k != i && q.a(j, k) != 0.0 {
                            rest += product_range(2.0 * q.a(j, k), lo[j], hi[j], lo[k], hi[k]).0;
                        }
                    }
                }
                let Some((l, u)) = project(q.a(i, i), p_lo, p_hi, rest, lo[i], hi[i]) else {
                    return false;
                };
                let pad = WIDEN * (1.0 + l.abs().max(u.abs()));
                let (l, u) = ((l - pad).max(lo[i]), (u + pad).min(hi[i]));
                if l > lo[i] + 0.05 * (hi[i] - lo[i]) || u < hi[i] - 0.05 * (hi[i] - lo[i]) {
                    shrunk = true;
                }
                lo[i] = l;
                hi[i] = u;
                if lo[i] > hi[i] {
                    return false;
                }
            }
        }
        if !shrunk {
            break;
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::feasibility::quadratic::Linear;

    #[test]
    fn disc_shrinks_the_box_to_its_hull() {
        let mut q = Quadratic::zero(2);
        q.a = vec![1.0, 0.0, 0.0, 1.0];
        q.c = -1.0;
        let (mut lo, mut hi) = (vec![-5.0, -5.0], vec![5.0, 5.0]);
        assert!(contract(&[&q], &mut lo, &mut hi, 0.0));
        for i in 0..2 {
            assert!((lo[i] + 1.0).abs() < 1e-9 && (hi[i] - 1.0).abs() < 1e-9);
        }
    }

    #[test]
    fn disjoint_half_planes_are_empty() {
        let x = Quadratic::from_linear(&(Linear::variable(1, 0) - Linear::constant(1, 1.0)));
        let y = Quadratic::from_linear(&(Linear::constant(1, 2.0) - Linear::variable(1, 0)));
        let (mut lo, mut hi) = (vec![-5.0], vec![5.0]);
        assert!(!contract(&[&x, &y], &mut lo, &mut hi, 0.0));
    }

    #[test]
    fn outside_of_a_disc_keeps_the_hull() {
        // 1 − x² < 0 on [−3, 3]: x ∈ [−3, −1] ∪ [1, 3], hull unchanged.
        let mut q = Quadratic::zero(1);
        q.a = vec![-1.0];
        q.c = 1.0;
        let (mut lo, mut hi) = (vec![-3.0], vec![3.0]);
        assert!(contract(&[&q], &mut lo, &mut hi, 0.0));
        assert_eq!((lo[0], hi[0]), (-3.0, 3.0));
        let (mut lo, mut hi) = (vec![0.0], vec![3.0]);
        assert!(contract(&[&q], &mut lo, &mut hi, 0.0));
        assert!((lo[0] - 1.0).abs() < 1e-9);
    }
}
