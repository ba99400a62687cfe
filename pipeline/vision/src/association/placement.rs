//! Where a detection may lie around its station: an ellipse along its bearing.
//!
//! A detection's bearing is known to milliradians, its range only to an interval (about 0.12 of
//! the range wide by colour, 0.32 by luminance, whose ground cue cannot see a rock's lowest
//! rows). A disc covering both is as loose across the line of sight as along it: by luminance
//! every far placement was metres wide, and true fits were no tighter than chance gives. An
//! ellipse long along the bearing and narrow across it keeps what the bearing knows; where two
//! stations see a rock from different directions, their ellipses cross, and the sketch's
//! estimate ([`super::Sketch`]) is tight both ways. With ellipses, marsyard seed 7 fused 55.2 %
//! of its correct detections instead of 51.4 %, and its grayscale rendering, with one
//! registration enough to anchor, 29.1 % instead of 10.2 % (`docs/RUN.md`, stop 35).
//!
//! A placement is the ellipse `{x : (x − point)ᵀ shape⁻¹ (x − point) ≤ 1}`: `shape` holds
//! the squared semi-axes in their directions. Whether two placements may be one rock is
//! tested against their Minkowski sum, grown by a slack for the rocks' extent, bounded by one
//! ellipse (the [`Separation`]).

use nalgebra::{Matrix2, Vector2};

/// A point around a station and the ellipse of its uncertainty (metres).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placed {
    pub point: [f64; 2],
    /// Squared semi-axes, as the symmetric matrix of the ellipse.
    pub shape: Matrix2<f64>,
}

impl Placed {
    /// A placement within `radius` of `point` every way.
    pub fn disc(point: [f64; 2], radius: f64) -> Placed {
        Placed {
            point,
            shape: Matrix2::identity() * radius * radius,
        }
    }

    /// A placement reaching `along` metres either way in the direction `angle` (radians) and
    /// `across` metres either way across it.
    pub fn along(point: [f64; 2], angle: f64, along: f64, across: f64) -> Placed {
        let (sin, cos) = angle.sin_cos();
        let axis = Vector2::new(cos, sin);
        let side = Vector2::new(-sin, cos);
        Placed {
            point,
            shape: axis * axis.transpose() * along * along
                + side * side.transpose() * across * across,
        }
    }

    /// How far the placement reaches from its point in the unit direction `direction`: the
    /// ellipse's support, `√(uᵀ shape u)`.
    pub fn extent(&self, direction: [f64; 2]) -> f64 {
        let u = Vector2::from(direction);
        (u.transpose() * self.shape * u)[(0, 0)].max(0.0).sqrt()
    }

    /// The longest semi-axis: how far the placement reaches at most.
    pub fn reach(&self) -> f64 {
        semi_axes(&self.shape)[1]
    }

    /// The placement turned by the rotation `turn` (`[cos, sin]`) and moved to `point`.
    pub(super) fn turned(&self, turn: [f64; 2], point: [f64; 2]) -> Placed {
        Placed {
            point,
            shape: turned_shape(&self.shape, turn),
        }
    }

    /// The same placement with every semi-axis at least `least` metres long.
    pub(super) fn at_least(&self, least: f64) -> Placed {
        Placed {
            point: self.point,
            shape: with_semi_axes(&self.shape, |a| a.max(least)),
        }
    }

    /// The placement's ellipse with every semi-axis `grown` metres longer.
    pub(super) fn grown(&self, grown: f64) -> Matrix2<f64> {
        with_semi_axes(&self.shape, |a| a + grown)
    }
}

/// How far apart two placements lie for their uncertainty: the offset between their points
/// measured against the ellipse that bounds both placements' sum and a slack.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Separation {
    /// The offset in units of that ellipse's mean radius (metres): the Mahalanobis distance
    /// times `gate`. For two discs it is the points' distance.
    pub distance: f64,
    /// The ellipse's mean radius `(det)^¼`, metres: for two discs, the sum of their radii and
    /// the slack.
    pub gate: f64,
}

impl Separation {
    /// Whether the two placements may be one rock: the offset lies within the ellipse.
    pub fn within(&self) -> bool {
        self.distance <= self.gate
    }

    /// How tightly they fit, `1 − (distance / gate)²`: 1 at the same point, 0 at the edge.
    pub fn fit(&self) -> f64 {
        1.0 - (self.distance / self.gate).powi(2)
    }
}

/// How far `p` and `q` (in one coordinate system) lie apart for their placements, each grown
/// by half of `slack` (rocks are not points: a bearing and a range point at different parts of
/// one rock), their sum bounded by one ellipse.
pub(super) fn separation(p: &Placed, q: &Placed, slack: f64) -> Separation {
    let offset = Vector2::new(p.point[0] - q.point[0], p.point[1] - q.point[1]);
    separation_of(
        offset,
        &bound_of_sum(&p.grown(0.5 * slack), &q.grown(0.5 * slack)),
    )
}

/// The separation of `offset` against the ellipse `gate`.
pub(super) fn separation_of(offset: Vector2<f64>, gate: &Matrix2<f64>) -> Separation {
    let det = gate.determinant();
    let radius = det.max(0.0).sqrt().sqrt();
    // shape⁻¹ of a symmetric 2 × 2 by its adjugate.
    let inverse = Matrix2::new(gate[(1, 1)], -gate[(0, 1)], -gate[(1, 0)], gate[(0, 0)]) / det;
    let squared = (offset.transpose() * inverse * offset)[(0, 0)];
    Separation {
        distance: squared.max(0.0).sqrt() * radius,
        gate: radius,
    }
}

/// An ellipse holding the Minkowski sum of ellipses `a` and `b`: `(1 + 1/t) a + (1 + t) b`
/// holds it for every `t > 0`; `t = √(tr a / tr b)` makes it exact for two discs and for
/// two ellipses of one shape and direction.
pub(super) fn bound_of_sum(a: &Matrix2<f64>, b: &Matrix2<f64>) -> Matrix2<f64> {
    let (ta, tb) = (a.trace(), b.trace());
    if ta <= 0.0 {
        return *b;
    }
    if tb <= 0.0 {
        return *a;
    }
    let t = (ta / tb).sqrt();
    a * (1.0 + 1.0 / t) + b * (1.0 + t)
}

/// The ellipse `shape` turned by the rotation `[cos, sin]`.
pub(super) fn turned_shape(shape: &Matrix2<f64>, [cos, sin]: [f64; 2]) -> Matrix2<f64> {
    let rotation = Matrix2::new(cos, -sin, sin, cos);
    rotation * shape * rotation.transpose()
}

/// The semi-axes of an ellipse, shortest first.
fn semi_axes(shape: &Matrix2<f64>) -> [f64; 2] {
    let [low, high] = eigenvalues(shape);
    [low.max(0.0).sqrt(), high.max(0.0).sqrt()]
}

/// The eigenvalues of a symmetric 2 × 2 matrix, least first.
fn eigenvalues(shape: &Matrix2<f64>) -> [f64; 2] {
    let mean = 0.5 * shape.trace();
    let spread = (0.5 * (shape[(0, 0)] - shape[(1, 1)])).hypot(shape[(0, 1)]);
    [mean - spread, mean + spread]
}

/// The ellipse with each semi-axis `a` replaced by `change(a)`, in the same directions: by the
/// projectors onto the two eigenvectors, `(shape − λ₋ I) / (λ₊ − λ₋)` and its complement (in
/// closed form: registration grows every placement it compares, and a general eigensolver
/// took a tenth of a run's time).
fn with_semi_axes(shape: &Matrix2<f64>, change: impl Fn(f64) -> f64) -> Matrix2<f64> {
    let [low, high] = eigenvalues(shape);
    let changed = |value: f64| change(value.max(0.0).sqrt()).powi(2);
    let spread = high - low;
    if spread <= 1e-12 * high.abs().max(f64::MIN_POSITIVE) {
        return Matrix2::identity() * changed(0.5 * (low + high));
    }
    let major = (shape - Matrix2::identity() * low) / spread;
    let minor = Matrix2::identity() - major;
    major * changed(high) + minor * changed(low)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// A point of the ellipse `shape` around the origin, at parameter `t`.
    fn on_ellipse(shape: &Matrix2<f64>, t: f64) -> Vector2<f64> {
        let eigen = shape.symmetric_eigen();
        let axes = eigen.eigenvalues.map(|v| v.max(0.0).sqrt());
        eigen.eigenvectors * Vector2::new(axes[0] * t.cos(), axes[1] * t.sin())
    }

    #[test]
    fn two_discs_are_separated_by_their_distance_within_their_radii_and_the_slack() {
        let (p, q) = (Placed::disc([1.0, 2.0], 0.4), Placed::disc([4.0, 6.0], 0.7));
        let s = separation(&p, &q, 0.3);
        assert!((s.distance - 5.0).abs() < 1e-12, "{s:?}");
        assert!((s.gate - 1.4).abs() < 1e-12, "{s:?}");
        assert!(!s.within());
        assert!((s.fit() - (1.0 - (5.0f64 / 1.4).powi(2))).abs() < 1e-12);
    }

    #[test]
    fn a_placement_along_its_bearing_reaches_far_along_it_and_little_across() {
        let p = Placed::along([3.0, 4.0], 4f64.atan2(3.0), 1.5, 0.05);
        let [cos, sin] = [0.6, 0.8];
        assert!((p.extent([cos, sin]) - 1.5).abs() < 1e-12);
        assert!((p.extent([-sin, cos]) - 0.05).abs() < 1e-12);
        assert!((p.reach() - 1.5).abs() < 1e-12);
        let turned = p.turned([0.0, 1.0], [0.0, 0.0]);
        assert!((turned.extent([-sin, cos]) - 1.5).abs() < 1e-12);
        let floored = p.at_least(0.25);
        assert!((floored.extent([-sin, cos]) - 0.25).abs() < 1e-12);
        assert!((floored.extent([cos, sin]) - 1.5).abs() < 1e-12);
    }

    proptest! {
        /// The closed-form growth of an ellipse agrees with growing its eigen-decomposition's
        /// semi-axes.
        #[test]
        fn growing_an_ellipse_grows_its_semi_axes(
            along in 0.0f64..3.0, across in 0.0f64..3.0, angle in 0.0f64..6.3, grown in 0.0f64..1.0,
        ) {
            let shape = Placed::along([0.0, 0.0], angle, along, across).shape;
            let eigen = shape.symmetric_eigen();
            let axes = eigen.eigenvalues.map(|v| (v.max(0.0).sqrt() + grown).powi(2));
            let expected =
                eigen.eigenvectors * Matrix2::from_diagonal(&axes) * eigen.eigenvectors.transpose();
            let got = with_semi_axes(&shape, |a| a + grown);
            prop_assert!((got - expected).norm() < 1e-9 * (1.0 + expected.norm()), "{got} {expected}");
        }

        /// Every point of the sum of two ellipses lies within their bound: sampled over both
        /// ellipses' boundaries, for ellipses of any size, thinness and direction.
        #[test]
        fn the_bound_of_a_sum_holds_every_point_of_it(
            a in (0.01f64..3.0, 0.01f64..3.0, 0.0f64..3.2),
            b in (0.01f64..3.0, 0.01f64..3.0, 0.0f64..3.2),
        ) {
            let ea = Placed::along([0.0, 0.0], a.2, a.0, a.1).shape;
            let eb = Placed::along([0.0, 0.0], b.2, b.0, b.1).shape;
            let bound = bound_of_sum(&ea, &eb);
            for i in 0..48 {
                for j in 0..48 {
                    let x = on_ellipse(&ea, i as f64 * 0.1309) + on_ellipse(&eb, j as f64 * 0.1309);
                    let s = separation_of(x, &bound);
                    prop_assert!(s.distance <= s.gate * (1.0 + 1e-9), "{x} outside {bound}");
                }
            }
        }

        /// A separation does not depend on the frame it is measured in.
        #[test]
        fn a_separation_is_the_same_in_every_frame(
            along in 0.05f64..3.0, across in 0.01f64..0.5, angle in 0.0f64..6.3,
            x in -5.0f64..5.0, y in -5.0f64..5.0, turn in 0.0f64..6.3,
        ) {
            let p = Placed::along([x, y], angle, along, across);
            let q = Placed::along([1.0, -2.0], angle + 1.0, 0.7, 0.1);
            let (sin, cos) = turn.sin_cos();
            let rotate = |v: [f64; 2]| [cos * v[0] - sin * v[1], sin * v[0] + cos * v[1]];
            let (p2, q2) = (
                p.turned([cos, sin], rotate(p.point)),
                q.turned([cos, sin], rotate(q.point)),
            );
            let (s, s2) = (separation(&p, &q, 0.3), separation(&p2, &q2, 0.3));
            prop_assert!((s.distance - s2.distance).abs() < 1e-9 * (1.0 + s.distance));
            prop_assert!((s.gate - s2.gate).abs() < 1e-9);
        }
    }
}
