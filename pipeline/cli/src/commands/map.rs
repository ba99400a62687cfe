//! `pipeline map`: inspect and merge saved maps (format in docs/MAP_FORMAT.md).

use super::output::write_atomic;
use anyhow::{bail, Context, Result};
use clap::Subcommand;
use qrm_core::calculus::Calculus;
use qrm_core::edc::Edc;
use qrm_core::fdc::Fdc;
use qrm_core::map::Hypergraph;
use qrm_core::neighborhood::estimate;
use std::path::{Path, PathBuf};

#[derive(Subcommand, Debug)]
pub enum MapCommand {
    /// Landmarks, triples, open states and (EDC) the RNG estimate of a saved map.
    Info {
        file: PathBuf,
        /// Also write the RNG estimate as JSON here (EDC maps).
        #[arg(long)]
        rng: Option<PathBuf>,
    },
    /// Merge maps over the same landmark ids (equal to fusing all their measurements) into
    /// `--out`; a contradiction between them is an error and nothing is written.
    Merge {
        #[arg(required = true, num_args = 2..)]
        files: Vec<PathBuf>,
        #[arg(long)]
        out: PathBuf,
    },
}

/// The `calculus` field of a map file, to pick the type to load it as.
pub(super) fn calculus_of(path: &Path, text: &str) -> Result<String> {
    let value: serde_json::Value =
        serde_json::from_str(text).with_context(|| format!("{} is not JSON", path.display()))?;
    match value.get("calculus").and_then(|c| c.as_str()) {
        Some(name) => Ok(name.to_string()),
        None => bail!(
            "{} has no \"calculus\" field: not a qrm map",
            path.display()
        ),
    }
}

pub(super) fn read(path: &Path) -> Result<String> {
    std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))
}

pub(super) fn load<C: Calculus>(path: &Path, text: &str) -> Result<Hypergraph<C>> {
    Hypergraph::<C>::from_json(text).with_context(|| format!("invalid map {}", path.display()))
}

pub fn run_command(command: MapCommand) -> Result<()> {
    match command {
        MapCommand::Info { file, rng } => {
            let text = read(&file)?;
            match calculus_of(&file, &text)?.as_str() {
                "EDC" => info(&load::<Edc>(&file, &text)?, rng.as_deref()),
                "FDC" => info(&load::<Fdc>(&file, &text)?, rng.as_deref()),
                other => bail!("{}: unknown calculus {other:?}", file.display()),
            }
        }
        MapCommand::Merge { files, out } => {
            let text = read(&files[0])?;
            match calculus_of(&files[0], &text)?.as_str() {
                "EDC" => merge::<Edc>(&files, &out),
                "FDC" => merge::<Fdc>(&files, &out),
                other => bail!("{}: unknown calculus {other:?}", files[0].display()),
            }
        }
    }
}

fn info<C: Calculus>(map: &Hypergraph<C>, rng_out: Option<&Path>) -> Result<()> {
    let states = C::universe().len();
    let triples = map.triple_count();
    let open = map.open_states();
    let full = map.fully_constrained_triples();
    println!(
        "{} map: {} landmarks, {} triples",
        C::NAME,
        map.len(),
        triples
    );
    if triples > 0 {
        println!(
            "open states: {:.1}% ({} of {}); fully constrained triples: {:.1}%",
            100.0 * open as f64 / (3 * states * triples) as f64,
            open,
            3 * states * triples,
            100.0 * full as f64 / triples as f64
        );
    }
    match (estimate(map), rng_out) {
        (Some(rng), out) => {
            if let Some(path) = out {
                write_atomic(path, super::rng_json(map, &rng).as_bytes())?;
            }
            println!(
                "RNG estimate: {} edges ({} certain), {} pairs pruned, total cost {:.4}",
                rng.edges.len(),
                rng.certain().count(),
                rng.pruned,
                rng.total_cost()
            );
            if let Some(path) = out {
                println!("wrote {}", path.display());
            }
        }
        (None, Some(_)) => bail!("{} maps have no RNG estimate (no lune)", C::NAME),
        (None, None) => {}
    }
    Ok(())
}

fn merge<C: Calculus>(files: &[PathBuf], out: &Path) -> Result<()> {
    let mut map = load::<C>(&files[0], &read(&files[0])?)?;
    for file in &files[1..] {
        let other = load::<C>(file, &read(file)?)?;
        map.merge(&other)
            .with_context(|| format!("{} contradicts the maps before it", file.display()))?;
    }
    write_atomic(out, map.to_json().as_bytes())?;
    println!(
        "merged {} maps: {} landmarks → {}",
        files.len(),
        map.len(),
        out.display()
    );
    Ok(())
}
