//! Renders one figure of each kind from synthetic data, to check by eye that `qrm_plot`
//! draws legible figures in the style of 000 Fig. 7 and Fig. 11:
//!
//! ```text
//! cargo run --release -p qrm-plot --example plot_demo -- /tmp/plot-example.png /tmp/rng-example.png
//! ```

use qrm_plot::{write_panels, write_rng, Axes, Curve, Panel, RngPicture};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::path::PathBuf;

/// Saturating curves like Fig. 7a: more landmarks per image converge faster.
fn panels() -> Vec<Panel> {
    let sizes = [6, 9, 12, 18, 24, 30];
    let images = 50;
    let curve = |n: usize, f: &dyn Fn(f64, f64) -> (f64, f64)| {
        let (mean, std) = (1..=images).map(|k| f(k as f64, n as f64 / 30.0)).unzip();
        Curve {
            label: format!("n = {n}"),
            mean,
            std,
            band: None,
        }
    };
    let panel = |title: &str, y_label: &str, f: &dyn Fn(f64, f64) -> (f64, f64)| Panel {
        title: title.into(),
        y_label: y_label.into(),
        curves: sizes.iter().map(|&n| curve(n, f)).collect(),
        x: Vec::new(),
    };
    vec![
        panel(
            "(a) incorrect EDC states removed",
            "removed [%]",
            &|k, r| {
                let m = 100.0 * (1.0 - (-k * r / 6.0).exp());
                (m, 8.0 * (-k * r / 12.0).exp() + 1.0)
            },
        ),
        panel(
            "(b) open states not adjacent to truth",
            "not adjacent [%]",
            &|k, r| (75.0 - 60.0 * r * (1.0 - (-k / 8.0).exp()), 6.0),
        ),
        panel("(c) total cost of RNG edges", "total edge cost", &|k, r| {
            (40.0 * r * k / 5.0 * (-k * r / 5.0).exp() + 1.0, 3.0 * r)
        }),
        Panel {
            title: "(d) computation time per update".into(),
            y_label: "time [s]".into(),
            curves: sizes
                .iter()
                .map(|&n| Curve {
                    label: format!("n = {n}"),
                    mean: (1..=images)
                        .map(|k| {
                            (n as f64).powf(1.5) * (1.0 + 3.0 * (-(k as f64) / 4.0).exp()) / 20.0
                        })
                        .collect(),
                    std: Vec::new(),
                    band: None,
                })
                .collect(),
            x: Vec::new(),
        },
    ]
}

/// The relative neighbourhood graph (000 §VII): `ab` is an edge unless some `c` is closer to
/// both `a` and `b` than they are to each other.
fn true_rng(points: &[(f64, f64)]) -> Vec<(usize, usize)> {
    let d = |a: usize, b: usize| (points[a].0 - points[b].0).hypot(points[a].1 - points[b].1);
    let mut edges = Vec::new();
    for a in 0..points.len() {
        for b in a + 1..points.len() {
            if !(0..points.len()).any(|c| c != a && c != b && d(a, c).max(d(b, c)) < d(a, b)) {
                edges.push((a, b));
            }
        }
    }
    edges
}

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let panels_path = PathBuf::from(args.next().unwrap_or("/tmp/plot-example.png".into()));
    let rng_path = PathBuf::from(args.next().unwrap_or("/tmp/rng-example.png".into()));

    write_panels(&panels_path, "image number", &panels())?;

    let mut random = ChaCha8Rng::seed_from_u64(11);
    let landmarks: Vec<(f64, f64)> = (0..30)
        .map(|_| {
            (
                random.random_range(0.0..20.0),
                random.random_range(0.0..14.0),
            )
        })
        .collect();
    let true_edges = true_rng(&landmarks);
    // Most true edges found, some still contested, plus a few spurious contested edges.
    let mut edges: Vec<(usize, usize, f64)> = Vec::new();
    for &(a, b) in &true_edges {
        if random.random_bool(0.85) {
            let w = if random.random_bool(0.6) {
                0.0
            } else {
                random.random()
            };
            edges.push((a, b, w));
        }
    }
    for _ in 0..8 {
        let (a, b) = (random.random_range(0..30), random.random_range(0..30));
        if a != b {
            edges.push((a, b, random.random_range(0.1..1.0)));
        }
    }
    let stations: Vec<(f64, f64)> = (0..15)
        .map(|k| {
            (
                19.0 - k as f64 * 1.1,
                13.0 - (k as f64 * 0.5).sin() * 3.0 - k as f64 * 0.4,
            )
        })
        .collect();
    let labels: Vec<String> = (0..landmarks.len()).map(|i| i.to_string()).collect();
    write_rng(
        &rng_path,
        &RngPicture {
            title: "RNG estimate after image 15".into(),
            landmarks: &landmarks,
            labels: &labels,
            axes: Axes::Metres,
            edges: &edges,
            true_edges: &true_edges,
            pruned: &[],
            stations: &stations,
        },
    )?;
    println!("{}\n{}", panels_path.display(), rng_path.display());
    Ok(())
}
