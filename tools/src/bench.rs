//! Benchmarks of the calculus core (figures for docs/BENCHMARKS.md): feasibility decisions in
//! 2 and 4 unknowns and one composition cell.

use clap::Parser;
use qrm::feasibility::Settings;
use qrm::generation::edc_composition_cell;
use std::time::Instant;

#[derive(Parser, Debug)]
struct Args {
    /// Time single composition cells `r1,r2`.
    #[arg(long, value_delimiter = ',', num_args = 2)]
    cell: Vec<u8>,
}

fn main() {
    let args = Args::parse();
    if args.cell.len() == 2 {
        let start = Instant::now();
        let (entries, report) =
            edc_composition_cell(args.cell[0], args.cell[1], &Settings::default());
        println!(
            "cell {:?}: {} entries {:?} in {:.3} s",
            args.cell,
            entries.len(),
            report,
            start.elapsed().as_secs_f64()
        );
        return;
    }
    for r1 in [1u8, 5, 7, 13, 17] {
        for r2 in [1u8, 6, 8, 14, 20] {
            let start = Instant::now();
            let (entries, report) = edc_composition_cell(r1, r2, &Settings::default());
            println!(
                "cell ({r1},{r2}): {} entries, sampled {} searched {} infeasible {} undecided {} boxes {} in {:.3} s",
                entries.len(),
                report.sampled,
                report.searched_feasible,
                report.proved_infeasible,
                report.undecided,
                report.boxes,
                start.elapsed().as_secs_f64()
            );
        }
    }
}
