//! Exact enumeration of FDC configurations with rational arithmetic.
//!
//! With A=(0,0), B=(0,1) fixed and C given, the FDC relations `BC:D` and `AB:D` depend on D only
//! through the signs of six affine functions of D (three lines of each frame). Every face of that
//! line arrangement — vertex, edge or open cell — is realised by one rational point computed
//! here, so for a given C the set of `(BC:D, AB:D)` pairs is found exactly.
//!
//! The arrangement's combinatorics change with C only where three lines meet or two become
//! parallel. Inside an FDC relation of C that happens only on the lines of the relation itself
//! and on the Thales circle over AB (C sees AB at a right angle, where the perpendicular to BC
//! through C passes through A). [`candidate_third_points`] samples every relation of C on, inside
//! and outside that circle, so the union over candidates is the complete composition table.

use crate::geometry::Point2;
use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::{Signed, Zero};

type Q = BigRational;

fn q(n: i64, d: i64) -> Q {
    BigRational::new(BigInt::from(n), BigInt::from(d))
}

/// `a x + b y + c`.
#[derive(Clone, Debug)]
struct Line {
    a: Q,
    b: Q,
    c: Q,
}

impl Line {
    /// `u · (D − p) = 0`.
    fn through(u: (Q, Q), p: &Point2<Q>) -> Line {
        let c = -(&u.0 * &p.x + &u.1 * &p.y);
        Line { a: u.0, b: u.1, c }
    }

    fn eval(&self, p: &Point2<Q>) -> Q {
        &self.a * &p.x + &self.b * &p.y + &self.c
    }
}

/// The six FDC lines around AB and BC as affine functions of D.
fn lines(a: &Point2<Q>, b: &Point2<Q>, c: &Point2<Q>) -> Vec<Line> {
    let mut out = Vec::with_capacity(6);
    for (p, r) in [(a, b), (b, c)] {
        let v = (&r.x - &p.x, &r.y - &p.y);
        out.push(Line::through((-v.1.clone(), v.0.clone()), p)); // side
        out.push(Line::through(v.clone(), p)); // perpendicular at the first point
        out.push(Line::through(v, r)); // perpendicular at the second point
    }
    out
}

fn intersection(l: &Line, m: &Line) -> Option<Point2<Q>> {
    let det = &l.a * &m.b - &m.a * &l.b;
    if det.is_zero() {
        return None;
    }
    let x = (&l.b * &m.c - &m.b * &l.c) / &det;
    let y = (&l.c * &m.a - &m.c * &l.a) / &det;
    Some(Point2::new(x, y))
}

fn push_unique(points: &mut Vec<Point2<Q>>, p: Point2<Q>) {
    if !points.contains(&p) {
        points.push(p);
    }
}

/// One rational point on every face (vertex, edge, open cell) of the arrangement of the six FDC
/// lines of `a → b` and `b → c`. Requires `b != c`.
pub fn faces_of_fourth_point(a: &Point2<Q>, b: &Point2<Q>, c: &Point2<Q>) -> Vec<Point2<Q>> {
    let lines = lines(a, b, c);
    let mut vertices: Vec<Point2<Q>> = Vec::new();
    for i in 0..lines.len() {
        for j in i + 1..lines.len() {
            if let Some(p) = intersection(&lines[i], &lines[j]) {
                push_unique(&mut vertices, p);
            }
        }
    }
    let mut faces = vertices.clone();
    for line in &lines {
        // Base point and direction of the line.
        let base = if !line.b.is_zero() {
            Point2::new(Q::zero(), -&line.c / &line.b)
        } else {
            Point2::new(-&line.c / &line.a, Q::zero())
        };
        let dir = (-line.b.clone(), line.a.clone());
        let at = |t: &Q| Point2::new(&base.x + t * &dir.0, &base.y + t * &dir.1);
        let norm2 = &dir.0 * &dir.0 + &dir.1 * &dir.1;
        let mut params: Vec<Q> = vertices
            .iter()
            .filter(|v| line.eval(v).is_zero())
            .map(|v| ((&v.x - &base.x) * &dir.0 + (&v.y - &base.y) * &dir.1) / &norm2)
            .collect();
        params.sort();
        params.dedup();
        let mut edge_params: Vec<Q> = Vec::new();
        match (params.first(), params.last()) {
            (Some(first), Some(last)) => {
                edge_params.push(first - Q::from_integer(1.into()));
                edge_params.push(last + Q::from_integer(1.into()));
                for w in params.windows(2) {
                    edge_params.push((&w[0] + &w[1]) / Q::from_integer(2.into()));
                }
            }
            _ => edge_params.push(Q::zero()),
        }
        for t in edge_params {
            let e = at(&t);
            // Step off the line along its normal, less than half-way to any other line.
            let normal = (line.a.clone(), line.b.clone());
            let mut eps = Q::from_integer(1.into());
            for other in &lines {
                let value = other.eval(&e);
                let rate = &other.a * &normal.0 + &other.b * &normal.1;
                if !value.is_zero() && !rate.is_zero() {
                    let limit = value.abs() / (rate.abs() * Q::from_integer(2.into()));
                    if limit < eps {
                        eps = limit;
                    }
                }
            }
            for s in [eps.clone(), -eps] {
                push_unique(
                    &mut faces,
                    Point2::new(&e.x + &s * &normal.0, &e.y + &s * &normal.1),
                );
            }
            push_unique(&mut faces, e);
        }
    }
    faces
}

/// Candidate positions of C: a rational grid (quarters and thirds) through every FDC relation,
/// plus rational points on the Thales circle x² + y² = y over AB.
pub fn candidate_third_points() -> Vec<Point2<Q>> {
    let mut values: Vec<Q> = (-8..=8).map(|k| q(k, 4)).collect();
    for k in -6..=6 {
        let v = q(k, 3);
        if !values.contains(&v) {
            values.push(v);
        }
    }
    values.sort();
    let mut points = Vec::new();
    for x in &values {
        for y in &values {
            points.push(Point2::new(x.clone(), y.clone()));
        }
    }
    // x = t/(1+t²), y = 1/(1+t²) lies on x² + y² = y.
    for (n, d) in [
        (1, 2),
        (2, 1),
        (1, 3),
        (3, 1),
        (2, 3),
        (3, 2),
        (1, 4),
        (4, 1),
    ] {
        for sign in [1, -1] {
            let t = q(sign * n, d);
            let den = Q::from_integer(1.into()) + &t * &t;
            points.push(Point2::new(&t / &den, Q::from_integer(1.into()) / &den));
        }
    }
    points
}

/// FDC relation with exact arithmetic.
pub fn classify_exact(a: &Point2<Q>, b: &Point2<Q>, c: &Point2<Q>) -> Option<u8> {
    super::classify_generic(a, b, c)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn faces_cover_all_cells_of_a_generic_arrangement() {
        // Six lines in general-ish position: B is a 4-fold point, parallels in pairs; the
        // faces found must include the points A, B and C themselves.
        let a = Point2::new(q(0, 1), q(0, 1));
        let b = Point2::new(q(0, 1), q(1, 1));
        let c = Point2::new(q(-1, 1), q(2, 1));
        let faces = faces_of_fourth_point(&a, &b, &c);
        for p in [&a, &b, &c] {
            assert!(faces.contains(p));
        }
        let relations: std::collections::BTreeSet<(u8, u8)> = faces
            .iter()
            .map(|d| {
                (
                    classify_exact(&b, &c, d).unwrap(),
                    classify_exact(&a, &b, d).unwrap(),
                )
            })
            .collect();
        // Every BC:D relation occurs (D ranges over the whole plane).
        for r in 1..=15 {
            assert!(relations.iter().any(|(x, _)| *x == r), "BC:D = {r} missing");
        }
    }
}
