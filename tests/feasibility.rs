//! The feasibility engine on systems with known answers (000 §V), and witness soundness.

use proptest::prelude::*;
use qrm_core::feasibility::{BranchAndBound, Linear, Outcome, Problem, Quadratic, Settings};

fn linear(b: &[f64], c: f64) -> Quadratic {
    Quadratic::from_linear(&Linear { b: b.to_vec(), c })
}

/// `(x − cx)² + (y − cy)² − r² < 0`.
fn disc(cx: f64, cy: f64, r: f64) -> Quadratic {
    let mut q = Quadratic::zero(2);
    q.a = vec![1.0, 0.0, 0.0, 1.0];
    q.b = vec![-2.0 * cx, -2.0 * cy];
    q.c = cx * cx + cy * cy - r * r;
    q
}

fn engine() -> BranchAndBound {
    BranchAndBound::default()
}

#[test]
fn roomy_system_is_feasible_with_a_strict_witness() {
    let cs = vec![disc(0.0, 0.0, 1.0), linear(&[-1.0, 0.0], 0.2)]; // disc and x > 0.2
    match engine().decide(&[-10.0, -10.0], &[10.0, 10.0], &cs) {
        Outcome::Feasible(x) => assert!(cs.iter().all(|q| q.eval(&x) < 0.0)),
        o => panic!("{o:?}"),
    }
}

#[test]
fn thin_sliver_is_found() {
    // 0 < x − y < 10⁻⁶ inside the unit disc.
    let cs = vec![
        linear(&[-1.0, 1.0], 0.0),
        linear(&[1.0, -1.0], -1e-6),
        disc(0.0, 0.0, 1.0),
    ];
    assert!(matches!(
        engine().decide(&[-4.0, -4.0], &[4.0, 4.0], &cs),
        Outcome::Feasible(_)
    ));
}

#[test]
fn thin_lens_between_two_discs_is_found() {
    // Two unit discs whose centres are 2 − 10⁻⁴ apart overlap in a lens 10⁻⁴ wide.
    let cs = vec![disc(-1.0, 0.3, 1.0), disc(1.0 - 1e-4, 0.3, 1.0)];
    assert!(matches!(
        engine().decide(&[-5.0, -5.0], &[5.0, 5.0], &cs),
        Outcome::Feasible(_)
    ));
}

#[test]
fn opposite_half_planes_touching_along_a_line_are_infeasible() {
    let cs = vec![linear(&[1.0, -1.0], 0.1), linear(&[-1.0, 1.0], -0.1)];
    assert_eq!(
        engine().decide(&[-3.0, -3.0], &[3.0, 3.0], &cs),
        Outcome::Infeasible
    );
}

#[test]
fn externally_tangent_discs_are_infeasible() {
    // Open discs touching at the single point (0, 0).
    let cs = vec![disc(-1.0, 0.0, 1.0), disc(1.0, 0.0, 1.0)];
    assert_eq!(
        engine().decide(&[-3.0, -3.0], &[3.0, 3.0], &cs),
        Outcome::Infeasible
    );
}

#[test]
fn disc_outside_its_own_circle_is_infeasible() {
    let inside = disc(0.3, -0.2, 1.5);
    let cs = vec![inside.clone(), -inside];
    assert_eq!(
        engine().decide(&[-4.0, -4.0], &[4.0, 4.0], &cs),
        Outcome::Infeasible
    );
}

#[test]
fn budget_exhaustion_is_undecided_not_infeasible() {
    // A tiny disc off every dyadic point: three boxes with centre-only witness candidates can
    // neither find it nor refute the boxes around it.
    let settings = Settings {
        max_boxes: 3,
        samples_per_box: 0,
        use_relaxation: false,
        ..Settings::default()
    };
    let cs = vec![disc(2.3, -1.7, 1e-3)];
    let o = BranchAndBound::new(settings).decide(&[-3.0, -3.0], &[3.0, 3.0], &cs);
    assert_eq!(o, Outcome::Undecided);
    assert!(matches!(
        engine().decide(&[-3.0, -3.0], &[3.0, 3.0], &cs),
        Outcome::Feasible(_)
    ));
}

#[test]
fn four_variable_bilinear_system() {
    // x0·x1 > 1 and x2·x3 > 1 on [0, 4]⁴ force x0, x2 > ¼: x0 + x2 < 1 is feasible,
    // x0 + x2 < 0.4 is not.
    let mut p = Quadratic::zero(4);
    p.a[1] = -0.5;
    p.a[4] = -0.5;
    p.c = 1.0;
    let mut r = Quadratic::zero(4);
    r.a[2 * 4 + 3] = -0.5;
    r.a[3 * 4 + 2] = -0.5;
    r.c = 1.0;
    let feasible = vec![p.clone(), r.clone(), linear(&[1.0, 0.0, 1.0, 0.0], -1.0)];
    let infeasible = vec![p, r, linear(&[1.0, 0.0, 1.0, 0.0], -0.4)];
    let lo = [0.0; 4];
    let hi = [4.0; 4];
    assert!(matches!(
        engine().decide(&lo, &hi, &feasible),
        Outcome::Feasible(_)
    ));
    assert_eq!(engine().decide(&lo, &hi, &infeasible), Outcome::Infeasible);
}

#[test]
fn same_seed_same_witness() {
    let cs = vec![disc(0.5, 0.5, 0.7), linear(&[1.0, 1.0], -0.9)];
    let a = engine().decide(&[-2.0, -2.0], &[2.0, 2.0], &cs);
    let b = engine().decide(&[-2.0, -2.0], &[2.0, 2.0], &cs);
    assert_eq!(a, b);
}

#[test]
fn multi_alternative_search_agrees_with_single_searches() {
    let common = vec![disc(0.0, 0.0, 2.0)];
    let alternatives = vec![
        vec![linear(&[-1.0, 0.0], 1.0)],                      // x > 1
        vec![linear(&[-1.0, 0.0], 3.0)],                      // x > 3: outside the disc
        vec![disc(2.0, 0.0, 0.5), linear(&[0.0, -1.0], 0.0)], // lens, y > 0
    ];
    let problem = Problem {
        lower: vec![-4.0, -4.0],
        upper: vec![4.0, 4.0],
        common: common.clone(),
        alternatives: alternatives.clone(),
    };
    let (outcomes, _) = engine().solve(&problem);
    for (k, alt) in alternatives.iter().enumerate() {
        let mut cs = common.clone();
        cs.extend(alt.iter().cloned());
        let single = engine().decide(&problem.lower, &problem.upper, &cs);
        assert_eq!(
            single.possibly_feasible(),
            outcomes[k].possibly_feasible(),
            "alternative {k}"
        );
        if let Outcome::Feasible(x) = &outcomes[k] {
            assert!(problem.satisfies(k, x));
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// Every `Feasible` witness lies in the box and satisfies all constraints strictly; an
    /// `Infeasible` answer is never contradicted by a dense grid of the box.
    #[test]
    fn witnesses_are_strict_and_refutations_survive_sampling(
        n in 2usize..=3,
        coefs in proptest::collection::vec(-2.0f64..2.0, 30),
        m in 1usize..=3,
    ) {
        let per = n * (n + 1) / 2 + n + 1;
        let cs: Vec<Quadratic> = (0..m).map(|j| Quadratic::from_packed(n, &coefs[(j * 7) % (30 - per)..][..per])).collect();
        let lo = vec![-2.0; n];
        let hi = vec![2.0; n];
        match engine().decide(&lo, &hi, &cs) {
            Outcome::Feasible(x) => {
                prop_assert!(x.iter().all(|v| (-2.0..=2.0).contains(v)));
                prop_assert!(cs.iter().all(|q| q.eval(&x) < 0.0));
            }
            Outcome::Infeasible => {
                let steps = 24usize;
                let total = (steps + 1).pow(n as u32);
                for idx in 0..total {
                    let mut x = vec![0.0; n];
                    let mut r = idx;
                    for v in x.iter_mut() {
                        *v = -2.0 + 4.0 * (r % (steps + 1)) as f64 / steps as f64;
                        r /= steps + 1;
                    }
                    prop_assert!(!cs.iter().all(|q| q.eval(&x) < -1e-6), "grid point {x:?} satisfies all");
                }
            }
            Outcome::Undecided => {}
        }
    }
}
