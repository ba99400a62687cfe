//! FDC (003 §1.2) tables: regeneration reproduces the committed files, witnesses are exact, and
//! random configurations — generic ones and ones placed exactly on lines — fall inside.

use num_bigint::BigInt;
use num_rational::BigRational;
use qrm_core::calculus::{Calculus, CompositionFile, RelationSet, UnaryFile};
use qrm_core::fdc::{classify_exact, Fdc, COMPOSITION_TABLE, UNARY_TABLE};
use qrm_core::geometry::{Point, Point2};
use qrm_tests::{random_point, rng};
use qrm_tools::{fdc_composition, fdc_unary};
use rand::Rng;

type Q = BigRational;

fn q(s: &str) -> Q {
    s.parse().expect("rational")
}

fn int(n: i64) -> Q {
    Q::from_integer(BigInt::from(n))
}

#[test]
fn regeneration_reproduces_the_committed_files() {
    assert_eq!(fdc_unary(), UnaryFile::parse(UNARY_TABLE).unwrap());
    assert_eq!(
        fdc_composition(),
        CompositionFile::parse(COMPOSITION_TABLE).unwrap()
    );
}

#[test]
fn exact_witnesses_classify_to_their_triples() {
    let f = CompositionFile::parse(COMPOSITION_TABLE).unwrap();
    let a = Point2::new(int(0), int(0));
    let b = Point2::new(int(0), int(1));
    for e in &f.entries {
        let w: Vec<Q> = e.witness.iter().map(|s| q(s)).collect();
        let c = Point2::new(w[0].clone(), w[1].clone());
        let d = Point2::new(w[2].clone(), w[3].clone());
        assert_eq!(classify_exact(&a, &b, &c), Some(e.ab_c), "{e:?}");
        assert_eq!(classify_exact(&b, &c, &d), Some(e.bc_d), "{e:?}");
        assert_eq!(classify_exact(&a, &b, &d), Some(e.ab_d), "{e:?}");
    }
}

#[test]
fn random_configurations_fall_inside_the_table() {
    let t = Fdc::tables();
    let mut rng = rng(5);
    let mut checked = 0;
    for i in 0..300_000 {
        // Small-integer coordinates hit lines and points exactly; floats are generic.
        let (a, b, c, d) = if i % 2 == 0 {
            let mut p = || {
                Point::new(
                    rng.random_range(-4..=4) as f64,
                    rng.random_range(-4..=4) as f64,
                )
            };
            (p(), p(), p(), p())
        } else {
            (
                random_point(&mut rng),
                random_point(&mut rng),
                random_point(&mut rng),
                random_point(&mut rng),
            )
        };
        let (Some(r1), Some(r2), Some(r3)) = (
            Fdc::classify(a, b, c),
            Fdc::classify(b, c, d),
            Fdc::classify(a, b, d),
        ) else {
            continue;
        };
        assert!(
            t.compose_base(r1, r2).contains(r3),
            "{r1} {r2} {r3} at {a:?} {b:?} {c:?} {d:?}"
        );
        checked += 1;
    }
    assert!(checked > 200_000);
}

#[test]
fn unary_operators_match_sampled_geometry_and_degenerate_frames() {
    let t = Fdc::tables();
    // C = B: BC is degenerate, so LEFT(5) = ∅; CA:B then has B at the frame's start: 11.
    assert_eq!(t.left(RelationSet::single(5)), RelationSet::EMPTY);
    assert_eq!(t.right(RelationSet::single(5)), RelationSet::single(11));
    assert_eq!(t.right(RelationSet::single(11)), RelationSet::EMPTY);
    assert_eq!(t.inverse(RelationSet::single(2)), RelationSet::single(14));
    let mut rng = rng(9);
    for _ in 0..100_000 {
        let mut p = || {
            Point::new(
                rng.random_range(-3..=3) as f64,
                rng.random_range(-3..=3) as f64,
            )
        };
        let (a, b, c) = (p(), p(), p());
        let Some(r) = Fdc::classify(a, b, c) else {
            continue;
        };
        let s = RelationSet::single(r);
        if let Some(l) = Fdc::classify(b, c, a) {
            assert!(t.left(s).contains(l));
        }
        if let Some(x) = Fdc::classify(c, a, b) {
            assert!(t.right(s).contains(x));
        }
        assert!(t.inverse(s).contains(Fdc::classify(b, a, c).unwrap()));
    }
    // Table entries are exact: the composition of a point relation with anything is determined.
    assert_eq!(t.compose_base(11, 11), RelationSet::single(5));
}
