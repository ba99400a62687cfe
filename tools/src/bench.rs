//! Benchmarks of the calculus core (figures in docs/BENCHMARKS.md):
//! - median time of one 2-unknown feasibility decision (all 3 × 20 × 20 EDC unary problems),
//! - median time of one 4-unknown decision (a deterministic sample of composition triples),
//! - wall time to regenerate each table.

use clap::Parser;
use qrm::edc::{fixed_point, free_point, region_constraints};
use qrm::feasibility::{BranchAndBound, Outcome, Quadratic};
use qrm::generation::{edc_composition, edc_unary, fdc_composition, fdc_unary};
use std::time::Instant;

#[derive(Parser, Debug)]
#[command(about = "Time feasibility decisions and table generation")]
struct Args {
    /// Skip regenerating the full EDC composition table (the slow part).
    #[arg(long)]
    quick: bool,
    /// Only time the EDC composition cells `R1 R2` (repeatable), with their search counts.
    #[arg(long, num_args = 2, value_names = ["AB_C", "BC_D"], value_parser = clap::value_parser!(u8).range(1..=20))]
    cell: Vec<u8>,
}

/// Median and 90th percentile in microseconds, with the outcome counts.
fn time_decisions(problems: &[(Vec<f64>, Vec<f64>, Vec<Quadratic>)]) -> (f64, f64, [usize; 3]) {
    let engine = BranchAndBound::default();
    let mut times = Vec::with_capacity(problems.len());
    let mut counts = [0usize; 3];
    for (lo, hi, cs) in problems {
        let start = Instant::now();
        let outcome = engine.decide(lo, hi, cs);
        times.push(start.elapsed().as_secs_f64() * 1e6);
        counts[match outcome {
            Outcome::Feasible(_) => 0,
            Outcome::Infeasible => 1,
            Outcome::Undecided => 2,
        }] += 1;
    }
    times.sort_by(f64::total_cmp);
    (times[times.len() / 2], times[times.len() * 9 / 10], counts)
}

fn main() {
    let args = Args::parse();
    if !args.cell.is_empty() {
        for pair in args.cell.chunks(2) {
            let start = Instant::now();
            let (entries, report) = qrm::generation::edc_composition_cell(
                pair[0],
                pair[1],
                &qrm::feasibility::Settings::default(),
            );
            println!(
                "cell ({},{}): {} possible, {} by sampling, {} by search, {} impossible, {} undecided, {} boxes, {:.2} s",
                pair[0], pair[1], entries.len(), report.sampled, report.searched_feasible,
                report.proved_infeasible, report.undecided, report.boxes, start.elapsed().as_secs_f64()
            );
        }
        return;
    }

    let n = 2;
    let (a, b, c) = (
        fixed_point(n, 0.0, 0.0),
        fixed_point(n, 0.0, 1.0),
        free_point(n, 0, 1),
    );
    let mut two = Vec::new();
    for r in 1..=20u8 {
        for s in 1..=20u8 {
            for (p, q, t) in [(&b, &c, &a), (&c, &a, &b), (&b, &a, &c)] {
                let mut cs = region_constraints(&a, &b, &c, r);
                cs.extend(region_constraints(p, q, t, s));
                two.push((vec![-8.0; 2], vec![8.0; 2], cs));
            }
        }
    }
    let (median, p90, counts) = time_decisions(&two);
    println!(
        "2 unknowns: {} decisions (EDC unary), median {median:.1} µs, p90 {p90:.1} µs; feasible {} infeasible {} undecided {}",
        two.len(), counts[0], counts[1], counts[2]
    );

    let n = 4;
    let (a, b, c, d) = (
        fixed_point(n, 0.0, 0.0),
        fixed_point(n, 0.0, 1.0),
        free_point(n, 0, 1),
        free_point(n, 2, 3),
    );
    let mut four = Vec::new();
    for k in 0..300u32 {
        let (r1, r2, r3) = (
            (k * 7 % 20 + 1) as u8,
            (k * 13 % 20 + 1) as u8,
            (k * 3 % 20 + 1) as u8,
        );
        let mut cs = region_constraints(&a, &b, &c, r1);
        cs.extend(region_constraints(&b, &c, &d, r2));
        cs.extend(region_constraints(&a, &b, &d, r3));
        four.push((vec![-8.0; 4], vec![8.0; 4], cs));
    }
    let (median, p90, counts) = time_decisions(&four);
    println!(
        "4 unknowns: {} decisions (EDC composition triples), median {median:.1} µs, p90 {p90:.1} µs; feasible {} infeasible {} undecided {}",
        four.len(), counts[0], counts[1], counts[2]
    );

    let settings = qrm::feasibility::Settings::default();
    let start = Instant::now();
    let (_, undecided) = edc_unary(&settings);
    println!(
        "EDC unary table: {:.2} s, {undecided} undecided",
        start.elapsed().as_secs_f64()
    );
    let start = Instant::now();
    fdc_unary();
    println!("FDC unary table: {:.2} s", start.elapsed().as_secs_f64());
    let start = Instant::now();
    let file = fdc_composition();
    println!(
        "FDC composition table: {:.2} s, {} entries",
        start.elapsed().as_secs_f64(),
        file.entries.len()
    );
    if !args.quick {
        let start = Instant::now();
        let (file, report) = edc_composition(&settings, || {});
        println!(
            "EDC composition table: {:.1} s on {} threads, {} entries, {} undecided",
            start.elapsed().as_secs_f64(),
            rayon::current_num_threads(),
            file.entries.len(),
            report.undecided
        );
    }
}
