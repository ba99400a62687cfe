//! The Sherali–Tunçbilek reformulation-linearisation (RLT) bound of 000 §V item 4, applied to a
//! whole conjunction at once.
//!
//! The paper bounds each constraint separately; a box straddling a boundary that two constraints
//! share (`q < 0` and `−q < 0`, or curves that touch) then never gets pruned. Here all
//! constraints of the box share one set of lifted variables `w_kl ≈ x_k x_l`, and one LP asks for
//! the largest common margin `t` with `lin_j(x, w) + t·s_j ≤ 0` for every `j`. If a dual bound
//! proves that even the relaxation has no margin above `Settings::margin`, neither has the box.
//!
//! The box is first mapped to `[−1, 1]ⁿ` (centre and half-widths) so that the LP is well
//! conditioned however small the box has become.

use super::quadratic::{Linear, Quadratic, Shape};
use crate::geometry::Coordinate;
use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus, SupportedConeT,
};

/// Result of the joint relaxation on one box.
pub struct RelaxationBound {
    /// Certified upper bound on the largest common margin of the relaxation, in units of each
    /// constraint's coefficient scale (from the LP dual, so solver inaccuracy cannot make it
    /// too small).
    pub margin: f64,
    /// The relaxation's optimal point in the original unknowns: a good witness candidate.
    pub point: Vec<f64>,
}

/// `q` in box-normalised coordinates `x = m + h∘u`, `u ∈ [−1, 1]ⁿ`.
fn normalise(q: &Quadratic, m: &[f64], h: &[f64]) -> Quadratic {
    let n = q.n;
    let mut r = Quadratic::zero(n);
    for i in 0..n {
        let mut grad = q.b[i];
        for j in 0..n {
            r.a[i * n + j] = q.a(i, j) * h[i] * h[j];
            grad += 2.0 * q.a(i, j) * m[j];
        }
        r.b[i] = grad * h[i];
    }
    r.c = q.eval(m);
    r
}

/// Solves the joint RLT relaxation of `constraints` over `[lo, hi]`; `None` when the LP solver
/// does not reach a certified optimum (callers must then keep the box).
pub fn joint_relaxation(
    constraints: &[&Quadratic],
    lo: &[f64],
    hi: &[f64],
) -> Option<RelaxationBound> {
    let n = lo.len();
    let m: Vec<f64> = lo.iter().zip(hi).map(|(l, u)| 0.5 * (l + u)).collect();
    let h: Vec<f64> = lo.iter().zip(hi).map(|(l, u)| 0.5 * (u - l)).collect();
    let normalised: Vec<Quadratic> = constraints.iter().map(|q| normalise(q, &m, &h)).collect();

    // Valid inequalities `p ≤ 0` from pairwise products of the linear constraints (ℓ_i < 0,
    // ℓ_j < 0 ⇒ ℓ_i ℓ_j ≥ 0): they let the LP use sign reasoning such as "C left of AB and D
    // below B, so their cross term is positive", which refutes boxes straddling boundaries
    // shared by two frames. (Products with the bound factors as well doubled the LP time
    // without saving boxes on the composition problems.)
    let linear: Vec<Linear> = normalised
        .iter()
        .filter(|q| q.shape() == Shape::Linear)
        .map(|q| Linear {
            b: q.b.clone(),
            c: q.c,
        })
        .collect();
    let mut products: Vec<Quadratic> = Vec::new();
    for (i, li) in linear.iter().enumerate() {
        for lj in &linear[i + 1..] {
            products.push(-li.mul(lj));
        }
    }

    // Lifted variables only for the products that occur.
    let mut pairs: Vec<(usize, usize)> = Vec::new();
    for k in 0..n {
        for l in k..n {
            if normalised.iter().chain(&products).any(|q| q.a(k, l) != 0.0) {
                pairs.push((k, l));
            }
        }
    }
    let nv = n + pairs.len() + 1; // u, w, t
    let t = nv - 1;
    let mut rows: Vec<Vec<(usize, f64)>> = Vec::new();
    let mut rhs: Vec<f64> = Vec::new();
    let linearise = |q: &Quadratic| -> Vec<(usize, f64)> {
        let mut row: Vec<(usize, f64)> = (0..n).map(|i| (i, q.b[i])).collect();
        for (p, &(k, l)) in pairs.iter().enumerate() {
            let coef = if k == l { q.a(k, k) } else { 2.0 * q.a(k, l) };
            row.push((n + p, coef));
        }
        row
    };

    for (q, original) in normalised.iter().zip(constraints) {
        // The margin is measured in units of each constraint's coefficient scale, as in the
        // per-constraint bounds, so one threshold means the same for both.
        let scale = original.scale().max(f64::MIN_POSITIVE);
        let mut row = linearise(q);
        row.push((t, scale));
        rows.push(row);
        rhs.push(-q.c);
    }
    for p in &products {
        rows.push(linearise(p));
        rhs.push(-p.c);
    }
    // RLT bound-factor products on [−1, 1]: (1 ± u_k)(1 ± u_l) ≥ 0.
    for (p, &(k, l)) in pairs.iter().enumerate() {
        let w = n + p;
        if k == l {
            // w ≤ 1 (from (1−u)(1+u) ≥ 0); w ≥ ±2u − 1; w ≥ 0 (tangent at the centre).
            rows.push(vec![(w, 1.0)]);
            rhs.push(1.0);
            rows.push(vec![(k, 2.0), (w, -1.0)]);
            rhs.push(1.0);
            rows.push(vec![(k, -2.0), (w, -1.0)]);
            rhs.push(1.0);
            rows.push(vec![(w, -1.0)]);
            rhs.push(0.0);
        } else {
            // w ≥ −1 + u_k + u_l,  w ≥ −1 − u_k − u_l,  w ≤ 1 + u_k − u_l,  w ≤ 1 − u_k + u_l.
            rows.push(vec![(k, 1.0), (l, 1.0), (w, -1.0)]);
            rhs.push(1.0);
            rows.push(vec![(k, -1.0), (l, -1.0), (w, -1.0)]);
            rhs.push(1.0);
            rows.push(vec![(k, -1.0), (l, 1.0), (w, 1.0)]);
            rhs.push(1.0);
            rows.push(vec![(k, 1.0), (l, -1.0), (w, 1.0)]);
            rhs.push(1.0);
        }
    }
    for i in 0..n {
        rows.push(vec![(i, 1.0)]);
        rhs.push(1.0);
        rows.push(vec![(i, -1.0)]);
        rhs.push(1.0);
    }
    rows.push(vec![(t, 1.0)]);
    rhs.push(1.0);

    let a = csc_from_rows(&rows, nv);
    let p = CscMatrix::zeros((nv, nv));
    let mut objective = vec![0.0; nv];
    objective[t] = -1.0;
    let cones = [SupportedConeT::NonnegativeConeT(rows.len())];
    let settings = DefaultSettingsBuilder::default()
        .verbose(false)
        .max_iter(60)
        .build()
        .ok()?;
    let mut solver = DefaultSolver::new(&p, &objective, &a, &rhs, &cones, settings).ok()?;
    solver.solve();
    // A rigorous upper bound on the relaxation's optimum from the (approximate) dual: for any
    // z ≥ 0 scaled so that (Aᵀz)_t = 1, every feasible y has
    // t = zᵀAy − Σ_{i≠t} r_i y_i ≤ zᵀb + Σ_{i≠t} |r_i|, with r = Aᵀz − e_t and |y_i| ≤ 1 for
    // every u and w (the box and McCormick rows imply it). Interior-point primal values lie
    // below the optimum by up to the solver's gap, so they must not be used to refute.
    if !matches!(
        solver.solution.status,
        SolverStatus::Solved | SolverStatus::AlmostSolved
    ) {
        return None;
    }
    let z: Vec<f64> = solver.solution.z.iter().map(|v| v.max(0.0)).collect();
    let mut residual = vec![0.0; nv];
    for (row, &zr) in rows.iter().zip(&z) {
        for &(c, v) in row {
            residual[c] += zr * v;
        }
    }
    let t_coefficient = residual[t];
    if t_coefficient <= 0.0 {
        return None;
    }
    let upper_bound = (z.iter().zip(&rhs).map(|(z, b)| z * b).sum::<f64>()
        + residual
            .iter()
            .enumerate()
            .filter(|&(i, _)| i != t)
            .map(|(_, r)| r.abs())
            .sum::<f64>())
        / t_coefficient;
    let x = &solver.solution.x;
    let point = (0..n)
        .map(|i| m[i] + h[i] * x[i].clamp(-1.0, 1.0))
        .collect();
    Some(RelaxationBound {
        margin: upper_bound,
        point,
    })
}

fn csc_from_rows(rows: &[Vec<(usize, f64)>], ncols: usize) -> CscMatrix<f64> {
    let mut columns: Vec<Vec<(usize, f64)>> = vec![Vec::new(); ncols];
    for (r, row) in rows.iter().enumerate() {
        for &(c, v) in row {
            if v != 0.0 {
                columns[c].push((r, v));
            }
        }
    }
    let mut colptr = Vec::with_capacity(ncols + 1);
    let mut rowval = Vec::new();
    let mut nzval = Vec::new();
    colptr.push(0);
    for col in columns {
        for (r, v) in col {
            rowval.push(r);
            nzval.push(v);
        }
        colptr.push(rowval.len());
    }
    CscMatrix::new(rows.len(), ncols, colptr, rowval, nzval)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn opposite_constraints_have_no_margin() {
        // x − y < 0 and y − x < 0 touch along a line: every box straddling it has margin 0.
        let d = Linear::variable(2, 0) - Linear::variable(2, 1);
        let q1 = Quadratic::from_linear(&d);
        let q2 = -q1.clone();
        let r = joint_relaxation(&[&q1, &q2], &[-1.0, -1.0], &[1.0, 1.0]).unwrap();
        assert!(r.margin.abs() < 1e-6, "{}", r.margin);
    }

    #[test]
    fn roomy_system_has_positive_margin() {
        // x² + y² − 1 < 0 inside the unit disc.
        let mut q = Quadratic::zero(2);
        q.a = vec![1.0, 0.0, 0.0, 1.0];
        q.c = -1.0;
        let r = joint_relaxation(&[&q], &[-0.5, -0.5], &[0.5, 0.5]).unwrap();
        assert!(r.margin > 0.1);
    }
}
