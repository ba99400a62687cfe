//! Affine and quadratic functions of `n` unknowns: the constraints `xᵀAx + bᵀx + c < 0` of
//! 000 §V, eq. (1), built symbolically from point coordinates that are affine in the unknowns.

use crate::geometry::Coordinate;
use std::ops::{Add, Mul, Neg, Sub};

/// `bᵀx + c`.
#[derive(Clone, Debug, PartialEq)]
pub struct Linear {
    pub b: Vec<f64>,
    pub c: f64,
}

impl Linear {
    pub fn constant(n: usize, c: f64) -> Linear {
        Linear { b: vec![0.0; n], c }
    }

    /// The unknown `x_i` itself.
    pub fn variable(n: usize, i: usize) -> Linear {
        let mut b = vec![0.0; n];
        b[i] = 1.0;
        Linear { b, c: 0.0 }
    }

    pub fn scaled(&self, k: f64) -> Linear {
        Linear {
            b: self.b.iter().map(|v| v * k).collect(),
            c: self.c * k,
        }
    }

    pub fn eval(&self, x: &[f64]) -> f64 {
        self.c + self.b.iter().zip(x).map(|(b, x)| b * x).sum::<f64>()
    }
}

impl Sub for Linear {
    type Output = Linear;
    fn sub(self, o: Linear) -> Linear {
        Linear {
            b: self.b.iter().zip(&o.b).map(|(a, b)| a - b).collect(),
            c: self.c - o.c,
        }
    }
}

impl Add for Linear {
    type Output = Linear;
    fn add(self, o: Linear) -> Linear {
        Linear {
            b: self.b.iter().zip(&o.b).map(|(a, b)| a + b).collect(),
            c: self.c + o.c,
        }
    }
}

/// `xᵀAx + bᵀx + c` with `A` symmetric, stored row-major `n × n`.
#[derive(Clone, Debug, PartialEq)]
pub struct Quadratic {
    pub n: usize,
    pub a: Vec<f64>,
    pub b: Vec<f64>,
    pub c: f64,
}

/// The algebraic shape of a quadratic, which decides how its minimum over a box is found
/// (000 §V, items 1–4).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shape {
    /// No quadratic terms.
    Linear,
    /// Only products of distinct unknowns, each unknown at most linear: multilinear, so the
    /// minimum over a box is at a corner.
    Multilinear,
    /// Squares but no cross terms: minimised unknown by unknown.
    Separable,
    /// Anything else.
    General,
}

impl Quadratic {
    pub fn zero(n: usize) -> Quadratic {
        Quadratic {
            n,
            a: vec![0.0; n * n],
            b: vec![0.0; n],
            c: 0.0,
        }
    }

    /// From packed coefficients: the upper triangle of `A` row by row (`a_00, a_01, …, a_11, …`),
    /// then `b`, then `c`; `n(n+1)/2 + n + 1` numbers in all.
    pub fn from_packed(n: usize, coefs: &[f64]) -> Quadratic {
        assert_eq!(
            coefs.len(),
            n * (n + 1) / 2 + n + 1,
            "packed quadratic length"
        );
        let mut q = Quadratic::zero(n);
        let mut k = 0;
        for i in 0..n {
            for j in i..n {
                q.a[i * n + j] = coefs[k];
                q.a[j * n + i] = coefs[k];
                k += 1;
            }
        }
        q.b.copy_from_slice(&coefs[k..k + n]);
        q.c = coefs[k + n];
        q
    }

    pub fn from_linear(l: &Linear) -> Quadratic {
        Quadratic {
            n: l.b.len(),
            a: vec![0.0; l.b.len() * l.b.len()],
            b: l.b.clone(),
            c: l.c,
        }
    }

    pub fn a(&self, i: usize, j: usize) -> f64 {
        self.a[i * self.n + j]
    }

    pub fn eval(&self, x: &[f64]) -> f64 {
        let n = self.n;
        let mut v = self.c;
        for i in 0..n {
            let row = &self.a[i * n..(i + 1) * n];
            let ax: f64 = row.iter().zip(x).map(|(a, x)| a * x).sum();
            v += x[i] * (ax + self.b[i]);
        }
        v
    }

    /// Largest absolute coefficient: the unit in which margins are measured.
    pub fn scale(&self) -> f64 {
        self.a
            .iter()
            .chain(&self.b)
            .chain(std::iter::once(&self.c))
            .fold(0.0f64, |m, v| m.max(v.abs()))
    }

    pub fn shape(&self) -> Shape {
        let n = self.n;
        let diagonal = (0..n).any(|i| self.a(i, i) != 0.0);
        let cross = (0..n).any(|i| (0..n).any(|j| i != j && self.a(i, j) != 0.0));
        match (diagonal, cross) {
            (false, false) => Shape::Linear,
            (false, true) => Shape::Multilinear,
            (true, false) => Shape::Separable,
            (true, true) => Shape::General,
        }
    }

    /// Whether unknown `i` appears at all.
    pub fn involves(&self, i: usize) -> bool {
        self.b[i] != 0.0 || (0..self.n).any(|j| self.a(i, j) != 0.0)
    }
}

impl Add for Quadratic {
    type Output = Quadratic;
    fn add(self, o: Quadratic) -> Quadratic {
        Quadratic {
            n: self.n,
            a: self.a.iter().zip(&o.a).map(|(a, b)| a + b).collect(),
            b: self.b.iter().zip(&o.b).map(|(a, b)| a + b).collect(),
            c: self.c + o.c,
        }
    }
}

impl Neg for Quadratic {
    type Output = Quadratic;
    fn neg(self) -> Quadratic {
        self * -1.0
    }
}

impl Mul<f64> for Quadratic {
    type Output = Quadratic;
    fn mul(self, k: f64) -> Quadratic {
        Quadratic {
            n: self.n,
            a: self.a.iter().map(|v| v * k).collect(),
            b: self.b.iter().map(|v| v * k).collect(),
            c: self.c * k,
        }
    }
}

impl Sub for Quadratic {
    type Output = Quadratic;
    fn sub(self, o: Quadratic) -> Quadratic {
        self + (-o)
    }
}

impl Coordinate for Linear {
    type Product = Quadratic;

    /// `(pᵀx + p0)(qᵀx + q0)`, symmetrised.
    fn mul(&self, o: &Linear) -> Quadratic {
        let n = self.b.len();
        let mut q = Quadratic::zero(n);
        for i in 0..n {
            for j in 0..n {
                q.a[i * n + j] = 0.5 * (self.b[i] * o.b[j] + self.b[j] * o.b[i]);
            }
            q.b[i] = self.b[i] * o.c + o.b[i] * self.c;
        }
        q.c = self.c * o.c;
        q
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn product_of_affine_expressions_evaluates_pointwise() {
        let x = Linear::variable(2, 0);
        let y = Linear::variable(2, 1);
        let p = x.clone() - Linear::constant(2, 1.0);
        let q = y.clone() + x.scaled(2.0);
        let prod = p.mul(&q);
        for pt in [[0.3, -1.2], [2.0, 5.0], [-3.0, 0.5]] {
            let expect = p.eval(&pt) * q.eval(&pt);
            assert!((prod.eval(&pt) - expect).abs() < 1e-12);
        }
        assert_eq!(prod.shape(), Shape::General);
        assert_eq!(Quadratic::from_linear(&p).shape(), Shape::Linear);
    }
}
