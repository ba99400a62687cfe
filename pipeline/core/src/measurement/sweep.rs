//! Exact-bearing measurement by sweeping (000 §IV with exact bearings, decided without branch
//! and bound).
//!
//! Fix `A = u_A` (scale), `B = r·u_B`, `C = s·u_C`. For one `r`, C runs along its ray and each
//! EDC boundary function is a quadratic in `s`, so the ray splits into at most 13 intervals of
//! constant region, found from the roots. The sequence of regions along the ray can only change
//! at *critical* values of `r` where
//! - the ray passes through a vertex of the EDC arrangement of `AB` (two roots meet): each
//!   vertex is a fixed similarity-covariant point, affine in `r` — one linear equation;
//! - a circle becomes tangent to the ray (a double root): a quadratic in `r`;
//! - a line becomes parallel to the ray (a root escapes to infinity): linear in `r`;
//! - a root meets an end of the allowed `s` interval: the camera (`s = 0`), a bound on C's
//!   range ratio to A (`s = c`, e.g. `|C| = |A|` at 1) or to B (`s = k·r`): quadratics in `r`;
//! - the two kinds of end swap (`c = k·r`): linear in `r`.
//!
//! Between consecutive critical values the sequence is constant, and a region met exactly at a
//! critical value is met just beside it too (regions are open). So one `r` inside every gap and
//! one `s` inside every ray interval visit every region the observation allows. Each sample is
//! classified with a tolerance: a boundary value within rounding of zero counts as both signs,
//! so sampling a numerically tiny interval can add a neighbour but never lose a region; and no
//! gap is skipped, however narrow.

use super::range_ratios::RangeRatios;
use crate::calculus::RelationSet;
use crate::edc::region_of_signs;
use crate::geometry::{boundary_values, Coordinate, Point, Point2};
use std::ops::{Add, Sub};

/// Vertices of the EDC arrangement in the frame `A = (0,0)`, `B = (0,1)` as `(α, β)` with
/// `V = A + α·(B − A) + β·rot90(B − A)`: A, B, the midpoint, the far ends of the circles on the
/// line AB, the feet of the perpendiculars on the circles, and the two lune corners.
const VERTICES: [(f64, f64); 11] = [
    (0.0, 0.0),
    (1.0, 0.0),
    (0.5, 0.0),
    (-1.0, 0.0),
    (2.0, 0.0),
    (0.0, 1.0),
    (0.0, -1.0),
    (1.0, 1.0),
    (1.0, -1.0),
    (0.5, 0.866_025_403_784_438_6),
    (0.5, -0.866_025_403_784_438_6),
];

/// Relative size below which a boundary value counts as zero when classifying a sample.
const ZERO_TOLERANCE: f64 = 1e-9;

/// Coefficients of a critical-value polynomial within this fraction of its largest coefficient
/// are rounding noise of an exact cancellation (e.g. `|u_B|² − |u_C|²` for two unit vectors,
/// one ulp from 0 at most bearings and exactly 0 at a few): taken at face value they put a
/// critical range near 0 or beyond 10¹⁴, whose gap is sampled where one landmark vanishes in
/// rounding and every neighbouring region is classified in. A genuine coefficient this small
/// would mean bearings within ~10⁻¹⁴ rad of a degenerate case, below what f64 angles resolve;
/// the sweep does not distinguish range ratios beyond that (docs/MEASUREMENT.md).
const COEFFICIENT_NOISE: f64 = 64.0 * f64::EPSILON;

/// The EDC regions of `AB:C` reachable when A, B, C lie on the rays `u` (unit vectors, camera
/// at the origin) with range ratios within `ratios` (which holds the range order: a landmark
/// nearer than another has a ratio to it below 1), among `wanted` (the sweep stops once all
/// are found).
pub fn sweep_regions(u: [Point; 3], ratios: &RangeRatios, wanted: RelationSet) -> RelationSet {
    let functions = BoundaryPolynomials::new(u);

    // Allowed r: B vs A.
    let (r_lo, r_hi) = ratios.of(1, 0);

    // A few typical ranges first: when every wanted region shows up there (the usual case once
    // the map is tight), the critical values are never needed.
    let mut found = RelationSet::EMPTY;
    let mut roots = Vec::with_capacity(16);
    for r in PROBE_RANGES {
        if r > r_lo && r < r_hi {
            found = found.union(regions_along_ray(&functions, ratios, r, &mut roots));
            if wanted.is_subset(found) {
                return wanted;
            }
        }
    }
    let mut critical = critical_ranges(u, &functions, ratios);
    for r in gap_samples(&mut critical, r_lo, r_hi) {
        found = found.union(regions_along_ray(&functions, ratios, r, &mut roots));
        if wanted.is_subset(found) {
            break;
        }
    }
    found.intersection(wanted)
}

/// Range ratios the sweep resolves. A critical value or root beyond `[10⁻¹², 10¹²]` is the
/// rounding noise of one at 0 or ∞ (a vertex equation or boundary value that cancels to an ulp):
/// its gap would be sampled with a landmark 10⁻¹⁴ from the camera, where terms of that size
/// drown in the classification tolerance and a region no arrangement reaches is classified in
/// (region 2 of `CA:B` at bearings 153.09°, 216.92°, 89.06° with `B < C`, found by the
/// rotation-invariance property test). Such values are dropped, so the gap merges with its
/// neighbour and is sampled at a resolvable ratio.
const RESOLVED_RATIO: f64 = 1e12;

/// Ratios `|B| / |A|` tried before the exact sweep.
const PROBE_RANGES: [f64; 6] = [0.3, 0.6, 0.9, 1.1, 1.6, 3.0];

/// The regions C meets on its ray (within the allowed ranges) when `|B| = r·|A|`.
fn regions_along_ray(
    functions: &BoundaryPolynomials,
    ratios: &RangeRatios,
    r: f64,
    roots: &mut Vec<f64>,
) -> RelationSet {
    let [s_lo, s_hi] = allowed_s(ratios, r);
    let mut found = RelationSet::EMPTY;
    if s_lo >= s_hi {
        return found;
    }
    roots.clear();
    for f in &functions.0 {
        push_roots(roots, f.ss, f.rs * r + f.s, (f.rr * r + f.r) * r + f.c);
    }
    for s in gap_samples(roots, s_lo, s_hi) {
        found = found.union(functions.regions_at(r, s));
    }
    found
}

/// Allowed `s = |C| / |A|` when `|B| = r·|A|`: C's ratio to A, and to B times `r`.
fn allowed_s(ratios: &RangeRatios, r: f64) -> [f64; 2] {
    let (to_a_lo, to_a_hi) = ratios.of(2, 0);
    let (to_b_lo, to_b_hi) = ratios.of(2, 1);
    [to_a_lo.max(to_b_lo * r), to_a_hi.min(to_b_hi * r)]
}

/// The values of `r` at which the sequence of regions along C's ray can change (module doc).
fn critical_ranges(
    u: [Point; 3],
    functions: &BoundaryPolynomials,
    ratios: &RangeRatios,
) -> Vec<f64> {
    let mut critical = vec![1.0];
    // Where the end set by C's ratio to A and the end set by its ratio to B swap.
    let (to_a_lo, to_a_hi) = ratios.of(2, 0);
    let (to_b_lo, to_b_hi) = ratios.of(2, 1);
    let to_a = [to_a_lo, to_a_hi, 1.0]
        .into_iter()
        .filter(|c| c.is_finite() && *c > 0.0);
    let to_b: Vec<f64> = [to_b_lo, to_b_hi, 1.0]
        .into_iter()
        .filter(|k| k.is_finite() && *k > 0.0)
        .collect();
    for c in to_a.clone() {
        critical.extend(to_b.iter().map(|k| c / k));
    }
    for &(alpha, beta) in &VERTICES {
        // V(r) = P + r·Q with A = u_A, B = r·u_B; on the ray ⇔ cross(u_C, V) = 0.
        let p = Point::new(
            (1.0 - alpha) * u[0].x + beta * u[0].y,
            (1.0 - alpha) * u[0].y - beta * u[0].x,
        );
        let q = Point::new(
            alpha * u[1].x - beta * u[1].y,
            alpha * u[1].y + beta * u[1].x,
        );
        push_roots(&mut critical, 0.0, cross(u[2], q), cross(u[2], p));
    }
    for f in &functions.0 {
        // f = ss·s² + (rs·r + s1)·s + (rr·r² + r1·r + c).
        push_roots(&mut critical, 0.0, f.rs, f.s); // parallel line: the s-coefficient vanishes
        push_roots(&mut critical, f.rr, f.r, f.c); // camera on the boundary
                                                   // A root at an end of the allowed s: s = c (a ratio to A) or s = k·r (to B).
        for c in to_a.clone() {
            push_roots(
                &mut critical,
                f.rr,
                f.r + f.rs * c,
                f.c + (f.s + f.ss * c) * c,
            );
        }
        for &k in &to_b {
            push_roots(
                &mut critical,
                f.rr + (f.rs + f.ss * k) * k,
                f.r + f.s * k,
                f.c,
            );
        }
        // Discriminant (rs·r + s1)² − 4·ss·(rr·r² + r1·r + c) = 0.
        push_roots(
            &mut critical,
            f.rs * f.rs - 4.0 * f.ss * f.rr,
            2.0 * f.rs * f.s - 4.0 * f.ss * f.r,
            f.s * f.s - 4.0 * f.ss * f.c,
        );
    }
    critical
}

/// A point inside every gap between the sorted `points` within `(lo, hi)`, including the end
/// gaps. Every gap that holds an `f64` is sampled, however narrow: a narrow gap may be a genuine sliver of a region
/// (e.g. the cusp between circle B and the perpendicular at A, both through A, is ε² wide on a
/// ray ε from A's bearing), and a sample that falls on a boundary in rounding is classified
/// into both neighbours by [`BoundaryPolynomials::regions_at`].
fn gap_samples(points: &mut Vec<f64>, lo: f64, hi: f64) -> Vec<f64> {
    points.retain(|&x| x > lo && x < hi && (1.0 / RESOLVED_RATIO..=RESOLVED_RATIO).contains(&x));
    points.sort_by(f64::total_cmp);
    points.dedup();
    let mut samples = Vec::with_capacity(points.len() + 1);
    let mut last = lo;
    for &x in points.iter() {
        samples.extend(inside(last, x));
        last = x;
    }
    if hi.is_finite() {
        samples.extend(inside(last, hi));
    } else {
        samples.push(2.0 * last.max(1.0));
    }
    samples
}

/// A point well inside `(a, b)`. Across orders of magnitude, the point nearest to 1 that stays
/// a factor 2 from both ends: the landmarks' ranges are then of comparable size, and a gap that
/// ends at a huge (often spurious) critical value is not sampled where the nearer landmarks
/// vanish in rounding.
///
/// `None` when no `f64` lies strictly between the ends: a sample rounded onto an end would sit
/// on a root or on a bound of the range order (`|C| = |A|`), where rounding classifies regions
/// the open interval never reaches (region 15 of `CA:B` at bearings 72.91°, 67.17°, 65.90°
/// with `B < C`, turned by 196.4°).
fn inside(a: f64, b: f64) -> Option<f64> {
    let x = if a > 0.0 && b > 4.0 * a {
        1.0f64.clamp(2.0 * a, 0.5 * b)
    } else {
        0.5 * (a + b)
    };
    (x > a && x < b).then_some(x)
}

/// Appends the positive real roots of `a·x² + b·x + c` (a linear or constant polynomial when
/// the leading coefficients vanish); nothing when the polynomial vanishes identically.
fn push_roots(out: &mut Vec<f64>, a: f64, b: f64, c: f64) {
    let scale = a.abs().max(b.abs()).max(c.abs());
    if scale == 0.0 || !scale.is_finite() {
        return;
    }
    let denoise = |x: f64| {
        let x = x / scale;
        if x.abs() <= COEFFICIENT_NOISE {
            0.0
        } else {
            x
        }
    };
    let (a, b, c) = (denoise(a), denoise(b), denoise(c));
    if a == 0.0 {
        if b != 0.0 {
            out.push(-c / b);
        }
        return;
    }
    let mut disc = b * b - 4.0 * a * c;
    if disc < 0.0 {
        // A double root perturbed by rounding still marks a tangency.
        if disc > -1e-12 {
            disc = 0.0;
        } else {
            return;
        }
    }
    // Numerically stable pair of roots; with a tiny `a` one is huge and the other is the root
    // of the nearly linear polynomial.
    let q = -0.5 * (b + b.signum() * disc.sqrt());
    let roots = if q != 0.0 { [q / a, c / q] } else { [0.0, 0.0] };
    out.extend(roots.into_iter().filter(|x| x.is_finite()));
}

fn cross(u: Point, v: Point) -> f64 {
    u.x * v.y - u.y * v.x
}

/// A number affine in `(r, s)`: `r·r_coef + s·s_coef + c`.
#[derive(Clone, Copy, Debug, Default)]
struct Affine {
    r: f64,
    s: f64,
    c: f64,
}

impl Sub for Affine {
    type Output = Affine;
    fn sub(self, o: Affine) -> Affine {
        Affine {
            r: self.r - o.r,
            s: self.s - o.s,
            c: self.c - o.c,
        }
    }
}

/// A quadratic polynomial in `(r, s)`.
#[derive(Clone, Copy, Debug, Default)]
struct Bivariate {
    rr: f64,
    rs: f64,
    ss: f64,
    r: f64,
    s: f64,
    c: f64,
}

impl Bivariate {
    /// Value and the sum of the magnitudes of its terms (the scale of rounding errors).
    fn eval(&self, r: f64, s: f64) -> (f64, f64) {
        let terms = [
            self.rr * r * r,
            self.rs * r * s,
            self.ss * s * s,
            self.r * r,
            self.s * s,
            self.c,
        ];
        (terms.iter().sum(), terms.iter().map(|t| t.abs()).sum())
    }
}

impl Add for Bivariate {
    type Output = Bivariate;
    fn add(self, o: Bivariate) -> Bivariate {
        Bivariate {
            rr: self.rr + o.rr,
            rs: self.rs + o.rs,
            ss: self.ss + o.ss,
            r: self.r + o.r,
            s: self.s + o.s,
            c: self.c + o.c,
        }
    }
}

impl Sub for Bivariate {
    type Output = Bivariate;
    fn sub(self, o: Bivariate) -> Bivariate {
        Bivariate {
            rr: self.rr - o.rr,
            rs: self.rs - o.rs,
            ss: self.ss - o.ss,
            r: self.r - o.r,
            s: self.s - o.s,
            c: self.c - o.c,
        }
    }
}

impl Coordinate for Affine {
    type Product = Bivariate;
    fn mul(&self, o: &Affine) -> Bivariate {
        Bivariate {
            rr: self.r * o.r,
            rs: self.r * o.s + self.s * o.r,
            ss: self.s * o.s,
            r: self.r * o.c + self.c * o.r,
            s: self.s * o.c + self.c * o.s,
            c: self.c * o.c,
        }
    }
}

/// The six boundary functions of `AB:C` as polynomials in `(r, s)`.
struct BoundaryPolynomials([Bivariate; 6]);

impl BoundaryPolynomials {
    fn new(u: [Point; 3]) -> BoundaryPolynomials {
        let fixed = |p: Point| {
            Point2::new(
                Affine {
                    c: p.x,
                    ..Affine::default()
                },
                Affine {
                    c: p.y,
                    ..Affine::default()
                },
            )
        };
        let a = fixed(u[0]);
        let b = Point2::new(
            Affine {
                r: u[1].x,
                ..Affine::default()
            },
            Affine {
                r: u[1].y,
                ..Affine::default()
            },
        );
        let c = Point2::new(
            Affine {
                s: u[2].x,
                ..Affine::default()
            },
            Affine {
                s: u[2].y,
                ..Affine::default()
            },
        );
        BoundaryPolynomials(boundary_values(&a, &b, &c))
    }

    /// Every region whose sign vector agrees with the boundary values at `(r, s)`, a value
    /// within rounding of zero matching either sign.
    fn regions_at(&self, r: f64, s: f64) -> RelationSet {
        let mut signs = [0i8; 6];
        let mut ambiguous = [0usize; 6];
        let mut count = 0;
        for (i, f) in self.0.iter().enumerate() {
            let (value, scale) = f.eval(r, s);
            if value.abs() <= ZERO_TOLERANCE * scale {
                ambiguous[count] = i;
                count += 1;
                signs[i] = 1;
            } else {
                signs[i] = if value > 0.0 { 1 } else { -1 };
            }
        }
        let mut out = RelationSet::EMPTY;
        for pattern in 0u32..1 << count {
            for (bit, &i) in ambiguous[..count].iter().enumerate() {
                signs[i] = if pattern >> bit & 1 == 1 { 1 } else { -1 };
            }
            if let Some(region) = region_of_signs(signs) {
                out = out.with(region);
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn polynomials_match_the_boundary_functions() {
        let u = [0.3f64, 2.0, -1.1].map(|t| Point::new(t.cos(), t.sin()));
        let polys = BoundaryPolynomials::new(u);
        for (r, s) in [(0.5, 2.0), (3.0, 0.1), (1.0, 1.0)] {
            let b = Point::new(r * u[1].x, r * u[1].y);
            let c = Point::new(s * u[2].x, s * u[2].y);
            let direct = boundary_values(&u[0], &b, &c);
            for (p, d) in polys.0.iter().zip(direct) {
                assert!((p.eval(r, s).0 - d).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn roots_of_degenerate_polynomials() {
        let mut out = Vec::new();
        push_roots(&mut out, 1.0, -3.0, 2.0);
        out.sort_by(f64::total_cmp);
        assert_eq!(out.len(), 2);
        assert!(
            (out[0] - 1.0).abs() < 1e-12 && (out[1] - 2.0).abs() < 1e-12,
            "{out:?}"
        );
        out.clear();
        push_roots(&mut out, 0.0, 2.0, -1.0);
        assert_eq!(out, vec![0.5]);
        out.clear();
        push_roots(&mut out, 0.0, 0.0, 0.0);
        push_roots(&mut out, 1.0, 0.0, 1.0);
        assert!(out.is_empty());
    }
}
