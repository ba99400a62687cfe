//! The qrm command line as a library (`qrm_cli`): the argument grammar ([`Cli`]), the
//! subcommands and their output files (docs/ARCHITECTURE.md): the calculus (classification,
//! the operators, table statistics, a demo of 000 §III-C), measurement of single triples,
//! simulated mapping, map files, synthetic datasets, and `pipeline run` / `eval` over
//! directories of panoramas. Argument parsing, progress bars, recordings and output files live
//! here; the work is done by the libraries. The `pipeline` binary and the Python package
//! (`pipeline/python`) are both thin glue over it, so that they write the same files and fail
//! with the same messages.

use anyhow::{bail, Context, Result};
use clap::{Parser, Subcommand, ValueEnum};
use qrm_core::calculus::{Calculus, CompositionFile, OperatorTables, RelationSet, UnaryOperator};
use qrm_core::edc::Edc;
use qrm_core::fdc::Fdc;
use qrm_core::geometry::{boundary_values, Point};
use std::process::ExitCode;

pub mod commands;
mod recording;
use commands::CalculusName;

#[derive(Parser, Debug)]
#[command(
    name = "pipeline",
    version,
    about = "qrm: qualitative relational mapping (McClelland, Campbell, Estlin) from rover panoramas",
    long_about = "qrm: qualitative relational mapping (McClelland, Campbell, Estlin) from rover panoramas.\n\n\
        Relations are numbered as in the papers: EDC regions 1..20 (000 Fig. 3b), FDC relations \
        1..15 (003 §1.2). Sets are written {1,5,11} or 1,5,11."
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum Operator {
    Left,
    Right,
    Inverse,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Walk through the operator example of 000 §III-C with the committed tables.
    Demo,
    /// Relation of point C to the directed pair A→B, e.g. `classify 0,0 0,1 -2,3`.
    Classify {
        #[arg(long, value_enum, default_value = "edc")]
        calculus: CalculusName,
        #[arg(allow_hyphen_values = true)]
        a: String,
        #[arg(allow_hyphen_values = true)]
        b: String,
        #[arg(allow_hyphen_values = true)]
        c: String,
    },
    /// COMPOSE(AB:C, BC:D) → AB:D for relation sets, e.g. `compose 1,5,11 5`.
    Compose {
        #[arg(long, value_enum, default_value = "edc")]
        calculus: CalculusName,
        ab_c: String,
        bc_d: String,
    },
    /// LEFT (AB:C→BC:A), RIGHT (AB:C→CA:B) or INVERSE (AB:C→BA:C) of a relation set.
    Unary {
        #[arg(long, value_enum, default_value = "edc")]
        calculus: CalculusName,
        #[arg(value_enum)]
        operator: Operator,
        set: String,
    },
    /// Statistics of the committed operator tables.
    Tables,
    /// Measure one triple from bearings (degrees) and a range order (000 §IV), e.g.
    /// `measure 0 40 100 --order "A<B<C" --uncertainty 0.5`.
    Measure(commands::measure::MeasureArgs),
    /// Simulated mapping with ground truth: Monte Carlo studies (000 Fig. 7), single maps.
    #[command(subcommand)]
    Simulate(commands::simulate::SimulateCommand),
    /// Inspect or merge saved maps (JSON, docs/MAP_FORMAT.md).
    #[command(subcommand)]
    Map(commands::map::MapCommand),
    /// Navigate over a map's RNG (000 §VII-B): landmark routes and the convex hull, which cell a
    /// panorama was taken in, closed-loop trips through rendered panoramas and their flow field,
    /// and simulated navigation with an ideal sensor (docs/NAVIGATION.md).
    #[command(subcommand)]
    Navigate(commands::navigate::NavigateCommand),
    /// Route directions a person or rover can follow (004 Park & Kender) from a run's map:
    /// legs "of the n − 1 landmarks nearest to you, head for the most isolated", routes by
    /// distance, reliability or their compromise, checks to verify each arrival and recover
    /// from a wrong one, and a picture of every target rock (docs/DIRECTIONS.md), e.g.
    /// `directions --run demo-run --images datasets/demo --from 3 --to 12 --out dir`.
    Directions(commands::directions::DirectionsArgs),
    /// Render a synthetic dataset: stereo panoramas of a rock field with ground truth
    /// (datasets/README.md), e.g. `synth --preset marsyard --seed 1 --out data/marsyard`.
    Synth(commands::synth::SynthArgs),
    /// Map a directory of panoramas: detect rocks, bearings, range order, associate, fuse,
    /// RNG (docs/RUN.md), e.g. `run --images datasets/demo --out demo-run`.
    Run(commands::run::RunArgs),
    /// Score a run against the dataset's truth.json (docs/RUN.md).
    Eval(commands::eval::EvalArgs),
}

/// `x,y` with finite coordinates.
pub fn parse_point(text: &str) -> Result<Point> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    if parts.len() != 2 {
        bail!("point {text:?} must be written x,y");
    }
    let x: f64 = parts[0]
        .parse()
        .with_context(|| format!("bad x in point {text:?}"))?;
    let y: f64 = parts[1]
        .parse()
        .with_context(|| format!("bad y in point {text:?}"))?;
    if !x.is_finite() || !y.is_finite() {
        bail!("point {text:?} must have finite coordinates");
    }
    Ok(Point::new(x, y))
}

/// A relation set of a calculus with `relations` relations.
pub fn parse_set(text: &str, relations: u8) -> Result<RelationSet> {
    let set: RelationSet = text.parse()?;
    if !set.is_subset(RelationSet::all(relations as usize)) {
        bail!("relation set {text} names a relation outside 1..={relations}");
    }
    Ok(set)
}

/// The relation of C to the directed pair A→B; `None` on a boundary.
pub fn classify(calculus: CalculusName, a: Point, b: Point, c: Point) -> Result<Option<u8>> {
    if a == b {
        bail!("A and B coincide: the frame A→B is undefined");
    }
    if boundary_values(&a, &b, &c).iter().any(|v| !v.is_finite()) {
        bail!("coordinates too large: squared distances overflow a 64-bit float");
    }
    Ok(match calculus {
        CalculusName::Edc => Edc::classify(a, b, c),
        CalculusName::Fdc => Fdc::classify(a, b, c),
    })
}

/// COMPOSE(AB:C, BC:D) of two relation sets written `{1,5,11}` or `1,5,11`.
pub fn compose(calculus: CalculusName, ab_c: &str, bc_d: &str) -> Result<RelationSet> {
    let t = tables(calculus);
    Ok(t.compose(
        parse_set(ab_c, t.relations())?,
        parse_set(bc_d, t.relations())?,
    ))
}

/// LEFT, RIGHT or INVERSE of a relation set.
pub fn unary(calculus: CalculusName, operator: Operator, set: &str) -> Result<RelationSet> {
    let t = tables(calculus);
    let s = parse_set(set, t.relations())?;
    let op = match operator {
        Operator::Left => UnaryOperator::Left,
        Operator::Right => UnaryOperator::Right,
        Operator::Inverse => UnaryOperator::Inverse,
    };
    Ok(t.unary(op, s))
}

fn tables(c: CalculusName) -> &'static OperatorTables {
    match c {
        CalculusName::Edc => Edc::tables(),
        CalculusName::Fdc => Fdc::tables(),
    }
}

fn demo() {
    let t = Edc::tables();
    let x: RelationSet = "{6,7}".parse().expect("literal");
    let y: RelationSet = "{16}".parse().expect("literal");
    println!("000 §III-C: four landmarks A, B, C, D with AB:C = X = {x} and AC:D = Y = {y}.");
    println!("  LEFT(X)    = BC:A = {}", t.left(x));
    println!("  INVERSE(Y) = CA:D = {}", t.inverse(y));
    for (p, q) in [(1, 5), (5, 5), (11, 5)] {
        println!("  COMPOSE({p},{q}) = {}", t.compose_base(p, q));
    }
    println!(
        "  BC:D = COMPOSE(LEFT(X), INVERSE(Y)) = {}  (paper: {{1,5,11,12,17,18,19,20}})",
        t.compose(t.left(x), t.inverse(y))
    );
    let a = Point::new(0.0, 0.0);
    let b = Point::new(0.0, 1.0);
    let c = Point::new(-1.5, 0.75);
    println!(
        "\nClassification: with A=(0,0), B=(0,1), C=(-1.5,0.75): EDC AB:C = {:?}, FDC AB:C = {:?}",
        Edc::classify(a, b, c),
        Fdc::classify(a, b, c)
    );
    println!(
        "\nTry: pipeline compose 7,13 14   pipeline unary left 7   pipeline tables   pipeline --help"
    );
}

fn table_stats() {
    for (name, text) in [
        ("EDC", qrm_core::edc::COMPOSITION_TABLE),
        ("FDC", qrm_core::fdc::COMPOSITION_TABLE),
    ] {
        let file = CompositionFile::parse(text).expect("committed table");
        let n = file.relations as usize;
        println!(
            "{name}: {} relations, {} of {} composition triples possible ({} undecided), mean |COMPOSE(r1,r2)| = {:.2}",
            n,
            file.entries.len(),
            n * n * n,
            file.undecided(),
            file.entries.len() as f64 / (n * n) as f64
        );
    }
}

/// Runs one parsed command line; its exit status when it succeeds (1 for `map check` of an
/// inconsistent network and a `map realize` that found no realization).
pub fn dispatch(cli: Cli) -> Result<ExitCode> {
    match cli.command {
        Command::Demo => demo(),
        Command::Classify { calculus, a, b, c } => {
            match classify(
                calculus,
                parse_point(&a)?,
                parse_point(&b)?,
                parse_point(&c)?,
            )? {
                Some(r) => println!("{r}"),
                None => println!("boundary"),
            }
        }
        Command::Compose {
            calculus,
            ab_c,
            bc_d,
        } => println!("{}", compose(calculus, &ab_c, &bc_d)?),
        Command::Unary {
            calculus,
            operator,
            set,
        } => println!("{}", unary(calculus, operator, &set)?),
        Command::Tables => table_stats(),
        Command::Measure(args) => commands::measure::run(args)?,
        Command::Simulate(command) => commands::simulate::run_command(command)?,
        Command::Map(command) => return commands::map::run_command(command),
        Command::Navigate(command) => commands::navigate::run_command(command)?,
        Command::Synth(args) => commands::synth::run(args)?,
        Command::Run(args) => commands::run::run(args)?,
        Command::Directions(args) => commands::directions::run(&args)?,
        Command::Eval(args) => commands::eval::run(args)?,
    }
    Ok(ExitCode::SUCCESS)
}
