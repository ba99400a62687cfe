//! `pipeline map`: inspect, merge, close, check and realize saved maps (format in
//! docs/MAP_FORMAT.md).

use super::output::write_atomic;
use super::rng_picture::{stage_rng_over, EdgeCut};
use super::CalculusName;
use anyhow::{bail, Context, Result};
use clap::Subcommand;
use qrm_atomic_file::OutputSet;
use qrm_core::calculus::Calculus;
use qrm_core::edc::Edc;
use qrm_core::fdc::Fdc;
use qrm_core::map::{Hypergraph, Network, Observation, RealizeSettings};
use qrm_core::neighborhood::estimate;
use qrm_plot::Axes;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

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
    /// Close a constraint network (the unary operators and full path consistency, as SparQ's
    /// `a-closure`) into a map at `--out`. Input: a map JSON file, closed or not, or a text
    /// file with one constraint `A B C {r,…}` per line (docs/MAP_FORMAT.md). An inconsistent
    /// network is an error naming a minimal set of conflicting constraints; nothing is written.
    Close {
        file: PathBuf,
        #[arg(long)]
        out: PathBuf,
        /// Calculus of a text network (a JSON file names its own).
        #[arg(long, value_enum, default_value = "edc")]
        calculus: CalculusName,
    },
    /// Find positions for the landmarks under which every relation of a map holds (one
    /// realization, a witness layout) and draw the map there: `--out` gets the positions as
    /// JSON, `--picture` (default: beside it, .png) the landmarks with the RNG estimate's edges
    /// of cost w ≤ 0.15 (EDC). Exit 1 if the search ends with relations still violated (the
    /// files then hold the best layout found, marked as such).
    Realize {
        file: PathBuf,
        #[arg(long)]
        out: PathBuf,
        /// The picture (.png or .svg).
        #[arg(long)]
        picture: Option<PathBuf>,
        /// Seed of the search: the same seed gives the same layout.
        #[arg(long, default_value_t = RealizeSettings::default().seed)]
        seed: u64,
        /// Rounds in which every landmark is offered one move, per start.
        #[arg(long, default_value_t = RealizeSettings::default().sweeps)]
        sweeps: usize,
        /// Fresh random starts tried until one satisfies every relation.
        #[arg(long, default_value_t = RealizeSettings::default().restarts)]
        restarts: usize,
        /// Draw every possible RNG edge, not only those of cost w ≤ 0.15.
        #[arg(long)]
        all_edges: bool,
    },
    /// Check a constraint network (map JSON or text, as for `close`): exit 0 and say how much
    /// closing would tighten it if it is consistent, exit 1 and list a minimal set of
    /// conflicting constraints if path consistency finds it inconsistent.
    Check {
        file: PathBuf,
        /// Calculus of a text network (a JSON file names its own).
        #[arg(long, value_enum, default_value = "edc")]
        calculus: CalculusName,
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

/// Runs a `map` command; `check` and `realize` end with status 1 when the network is
/// inconsistent or no realization was found.
pub fn run_command(command: MapCommand) -> Result<ExitCode> {
    match command {
        MapCommand::Info { file, rng } => {
            let text = read(&file)?;
            match calculus_of(&file, &text)?.as_str() {
                "EDC" => info(&load::<Edc>(&file, &text)?, rng.as_deref()),
                "FDC" => info(&load::<Fdc>(&file, &text)?, rng.as_deref()),
                other => bail!("{}: unknown calculus {other:?}", file.display()),
            }
            .map(|()| ExitCode::SUCCESS)
        }
        MapCommand::Close {
            file,
            out,
            calculus,
        } => match network_calculus(&file, calculus)?.as_str() {
            "EDC" => close::<Edc>(&file, &out),
            "FDC" => close::<Fdc>(&file, &out),
            other => bail!("{}: unknown calculus {other:?}", file.display()),
        }
        .map(|()| ExitCode::SUCCESS),
        MapCommand::Check { file, calculus } => {
            let consistent = match network_calculus(&file, calculus)?.as_str() {
                "EDC" => check::<Edc>(&file)?,
                "FDC" => check::<Fdc>(&file)?,
                other => bail!("{}: unknown calculus {other:?}", file.display()),
            };
            Ok(status(consistent))
        }
        MapCommand::Realize {
            file,
            out,
            picture,
            seed,
            sweeps,
            restarts,
            all_edges,
        } => {
            let text = read(&file)?;
            let settings = RealizeSettings {
                seed,
                sweeps,
                restarts,
            };
            let picture = picture.unwrap_or_else(|| out.with_extension("png"));
            // Checked before the search, which can take seconds.
            if picture == out {
                bail!(
                    "--picture {} is the --out file: give the layout a .json name",
                    picture.display()
                );
            }
            let extension = |p: &Path| {
                p.extension()
                    .map(|e| e.to_string_lossy().to_ascii_lowercase())
                    .unwrap_or_default()
            };
            if !["png", "svg"].contains(&extension(&picture).as_str()) {
                bail!(
                    "--picture {}: a picture is written as .png or .svg",
                    picture.display()
                );
            }
            let cut = EdgeCut::new(all_edges);
            let exact = match calculus_of(&file, &text)?.as_str() {
                "EDC" => realize(&load::<Edc>(&file, &text)?, &settings, &out, &picture, cut)?,
                "FDC" => realize(&load::<Fdc>(&file, &text)?, &settings, &out, &picture, cut)?,
                other => bail!("{}: unknown calculus {other:?}", file.display()),
            };
            Ok(status(exact))
        }
        MapCommand::Merge { files, out } => {
            let text = read(&files[0])?;
            match calculus_of(&files[0], &text)?.as_str() {
                "EDC" => merge::<Edc>(&files, &out),
                "FDC" => merge::<Fdc>(&files, &out),
                other => bail!("{}: unknown calculus {other:?}", files[0].display()),
            }
            .map(|()| ExitCode::SUCCESS)
        }
    }
}

fn status(success: bool) -> ExitCode {
    if success {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
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

/// Realizes `map`, writes the layout to `out` and its picture to `picture` (together);
/// whether every relation holds there.
fn realize<C: Calculus>(
    map: &Hypergraph<C>,
    settings: &RealizeSettings,
    out: &Path,
    picture: &Path,
    cut: EdgeCut,
) -> Result<bool> {
    if map.is_empty() {
        bail!("the map has no landmarks to place");
    }
    let found = map.realize(settings);
    let verdict = if found.is_exact() {
        format!(
            "every one of its {} constrained relations holds",
            found.constrained
        )
    } else {
        format!(
            "not a realization: {} of {} constrained relations still violated",
            found.violated, found.constrained
        )
    };
    let json = serde_json::json!({
        "format": "qrm-realization",
        "version": 1,
        "calculus": C::NAME,
        "exact": found.is_exact(),
        "violated": found.violated,
        "constrained": found.constrained,
        "landmarks": found
            .landmarks
            .iter()
            .zip(&found.positions)
            .map(|(id, p)| serde_json::json!({"landmark": id, "x": p.x, "y": p.y}))
            .collect::<Vec<_>>(),
    });
    let mut outputs = OutputSet::new();
    for path in [out, picture] {
        if let Some(dir) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir)
                .with_context(|| format!("cannot create directory {}", dir.display()))?;
        }
    }
    outputs
        .stage_bytes(
            out,
            (serde_json::to_string_pretty(&json)? + "\n").as_bytes(),
        )
        .with_context(|| format!("cannot write {}", out.display()))?;
    let rng = estimate(map);
    let positions: Vec<(f64, f64)> = found.positions.iter().map(|p| (p.x, p.y)).collect();
    let title = if found.is_exact() {
        format!("One realization of the {} map", C::NAME)
    } else {
        format!("Best layout found, {} relations violated", found.violated)
    };
    stage_rng_over(
        &mut outputs,
        picture,
        title,
        (&found.landmarks, &positions),
        rng.as_ref(),
        cut,
        Axes::Realization,
    )?;
    outputs
        .commit()
        .with_context(|| format!("cannot move {} into place", out.display()))?;
    println!(
        "{} map of {} landmarks placed: {verdict}; wrote {} and {}",
        C::NAME,
        map.len(),
        out.display(),
        picture.display()
    );
    Ok(found.is_exact())
}

/// Whether `path` holds JSON (by its extension).
fn is_json(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"))
}

/// The calculus of a network file: a JSON file's own, else `--calculus`.
fn network_calculus(path: &Path, calculus: CalculusName) -> Result<String> {
    if is_json(path) {
        calculus_of(path, &read(path)?)
    } else {
        Ok(match calculus {
            CalculusName::Edc => Edc::NAME,
            CalculusName::Fdc => Fdc::NAME,
        }
        .to_string())
    }
}

fn network<C: Calculus>(path: &Path) -> Result<Network<C>> {
    let text = read(path)?;
    if is_json(path) {
        Network::from_json(&text).with_context(|| format!("invalid map {}", path.display()))
    } else {
        Network::from_text(&text).with_context(|| format!("invalid network {}", path.display()))
    }
}

/// The constraints, one `A B C {r,…}` per line.
pub fn constraint_lines(constraints: &[Observation]) -> String {
    constraints
        .iter()
        .map(|o| format!("  {} {} {} {}\n", o.a, o.b, o.c, o.states))
        .collect()
}

fn close<C: Calculus>(file: &Path, out: &Path) -> Result<()> {
    let network = network::<C>(file)?;
    match network.close() {
        Ok(map) => {
            write_atomic(out, map.to_json().as_bytes())?;
            println!(
                "{} network of {} constraints closed: {} landmarks, {} triples; wrote {}",
                C::NAME,
                network.constraints.len(),
                map.len(),
                map.triple_count(),
                out.display()
            );
            Ok(())
        }
        Err(contradiction) => {
            let conflict = network.minimal_conflict().unwrap_or_default();
            bail!(
                "{} is inconsistent ({contradiction}); these {} constraints conflict (each is needed):\n{}nothing was written",
                file.display(),
                conflict.len(),
                constraint_lines(&conflict)
            )
        }
    }
}

/// Prints the verdict; whether the network is consistent.
fn check<C: Calculus>(file: &Path) -> Result<bool> {
    let network = network::<C>(file)?;
    match network.close() {
        Ok(map) => {
            let tightened = network.tightened(&map);
            println!(
                "{}: consistent as far as path consistency tells ({} network, {} landmarks, {} constraints; closing tightens {} of them)",
                file.display(),
                C::NAME,
                map.len(),
                network.constraints.len(),
                tightened
            );
            Ok(true)
        }
        Err(contradiction) => {
            let conflict = network.minimal_conflict().unwrap_or_default();
            println!(
                "{}: inconsistent ({contradiction}); a minimal set of {} conflicting constraints:\n{}",
                file.display(),
                conflict.len(),
                constraint_lines(&conflict).trim_end()
            );
            Ok(false)
        }
    }
}
