use qrm::calculus::Calculus;
use qrm::edc::Edc;
use qrm::feasibility::{BranchAndBound, Settings};
use qrm::measurement::*;
use rand::{Rng, SeedableRng};
#[test]
fn probe() {
    for (boxes, relax) in [(500, true), (2000, true), (2000, false), (20000, true)] {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let engine = BranchAndBound::new(Settings {
            max_boxes: boxes,
            use_relaxation: relax,
            ..Settings::default()
        });
        let t0 = std::time::Instant::now();
        let (mut nominal, mut total) = (0, 0);
        for _ in 0..40 {
            let b: [Bearing; 3] = std::array::from_fn(|_| Bearing {
                angle: rng.random_range(0.0..6.28),
                uncertainty: 0.01,
            });
            let nearer = [(0, 1), (1, 2), (0, 2)];
            let s = by_sweep(
                b.map(|x| Bearing::exact(x.angle)),
                &nearer,
                [Edc::universe(); 3],
            );
            let t = by_search(b, &nearer, [Edc::universe(); 3], &engine);
            for k in 0..3 {
                nominal += s[k].len();
                total += t[k].len();
            }
        }
        println!(
            "boxes {boxes} relax {relax}: nominal {nominal} uncertain {total} in {:?}",
            t0.elapsed()
        );
    }
}
