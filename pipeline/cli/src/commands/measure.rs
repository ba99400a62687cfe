//! `pipeline measure`: the relations of one triple from bearings and a range order (000 §IV).

use super::CalculusName;
use anyhow::{bail, Context, Result};
use clap::Args;
use qrm_core::calculus::{Calculus, RelationSet};
use qrm_core::edc::Edc;
use qrm_core::fdc::Fdc;
use qrm_core::measurement::{
    Bearing, RangeBounds, RangeOrder, StationView, MAX_BEARING_UNCERTAINTY,
};

#[derive(Args, Debug)]
pub struct MeasureArgs {
    /// Bearing of landmark A in degrees, counter-clockwise, any zero.
    #[arg(allow_hyphen_values = true)]
    a: f64,
    /// Bearing of landmark B in degrees.
    #[arg(allow_hyphen_values = true)]
    b: f64,
    /// Bearing of landmark C in degrees.
    #[arg(allow_hyphen_values = true)]
    c: f64,
    /// Range order, nearest first: a chain `A<B<C` or comma-separated pairs `A<B,A<C`; pairs
    /// left out are unknown. Empty: no order known.
    #[arg(long, default_value = "")]
    order: String,
    /// Bearing uncertainty: each true bearing lies within ± this many degrees.
    #[arg(long, default_value_t = 0.0)]
    uncertainty: f64,
    /// Range intervals of A, B, C, comma-separated, each `LOW:HIGH` (any unit; HIGH may be
    /// `inf`) or `-` for unknown: the ratios of the ranges are then bounded too, beyond the
    /// order. Empty: no intervals.
    #[arg(long, default_value = "", allow_hyphen_values = true)]
    ranges: String,
    #[arg(long, value_enum, default_value = "edc")]
    calculus: CalculusName,
}

/// `4:5,8:10,-` → the range intervals of A, B, C (`-`: unbounded); empty: all unbounded.
pub fn parse_ranges(text: &str) -> Result<Vec<RangeBounds>> {
    if text.trim().is_empty() {
        return Ok(vec![RangeBounds::UNBOUNDED; 3]);
    }
    let items: Vec<&str> = text.split(',').map(str::trim).collect();
    if items.len() != 3 {
        bail!(
            "--ranges {text:?} must give three intervals (A, B, C) separated by commas, e.g. 4:5,8:10,-"
        );
    }
    items
        .into_iter()
        .map(|item| {
            if item == "-" {
                return Ok(RangeBounds::UNBOUNDED);
            }
            let (low, high) = item
                .split_once(':')
                .with_context(|| format!("range interval {item:?} must look like LOW:HIGH or -"))?;
            let number = |v: &str| {
                v.trim()
                    .parse::<f64>()
                    .with_context(|| format!("{v:?} in range interval {item:?} is not a number"))
            };
            Ok(RangeBounds {
                low: number(low)?,
                high: number(high)?,
            })
        })
        .collect()
}

/// `A<B<C`, `A<B,A<C` → pairs of indices (0 = A), nearer first.
pub fn parse_order(text: &str) -> Result<Vec<(usize, usize)>> {
    let mut pairs = Vec::new();
    for chain in text.split(',').map(str::trim).filter(|c| !c.is_empty()) {
        let names: Vec<&str> = chain.split('<').map(str::trim).collect();
        if names.len() < 2 {
            bail!("order {chain:?} must look like A<B or A<B<C");
        }
        let index = |name: &str| match name {
            "A" | "a" => Ok(0),
            "B" | "b" => Ok(1),
            "C" | "c" => Ok(2),
            _ => bail!("unknown landmark {name:?} in order {chain:?}: use A, B, C"),
        };
        for w in names.windows(2) {
            pairs.push((index(w[0])?, index(w[1])?));
        }
    }
    Ok(pairs)
}

pub fn run(args: MeasureArgs) -> Result<()> {
    let relations = relations(
        args.calculus,
        [args.a, args.b, args.c],
        &args.order,
        args.uncertainty,
        &args.ranges,
    )?;
    for (name, set) in RELATION_NAMES.iter().zip(relations) {
        println!("{name} = {set}");
    }
    Ok(())
}

/// The relations [`relations`] returns, in order.
pub const RELATION_NAMES: [&str; 6] = ["AB:C", "BC:A", "CA:B", "BA:C", "CB:A", "AC:B"];

/// The relations of landmarks A, B, C seen at bearings `degrees` (counter-clockwise, any
/// zero, each within ±`uncertainty` degrees) with the range `order` (`A<B<C`, `A<B,A<C`, or
/// empty) and range intervals `ranges` ([`parse_ranges`]), in the order of
/// [`RELATION_NAMES`] (000 §IV).
pub fn relations(
    calculus: CalculusName,
    degrees: [f64; 3],
    order: &str,
    uncertainty: f64,
    ranges: &str,
) -> Result<[RelationSet; 6]> {
    let ranges = parse_ranges(ranges)?;
    let pairs = parse_order(order)?;
    let order = RangeOrder::from_pairs(3, &pairs).context("range order")?;
    if !(0.0..MAX_BEARING_UNCERTAINTY.to_degrees()).contains(&uncertainty) {
        bail!(
            "--uncertainty {} must lie in [0, {}) degrees",
            uncertainty,
            MAX_BEARING_UNCERTAINTY.to_degrees()
        );
    }
    let bearings = degrees
        .iter()
        .map(|deg| Bearing {
            angle: deg.to_radians(),
            uncertainty: uncertainty.to_radians(),
        })
        .collect();
    let panorama = StationView::new(bearings, order)?.with_ranges(ranges)?;
    Ok(match calculus {
        CalculusName::Edc => measured::<Edc>(&panorama),
        CalculusName::Fdc => measured::<Fdc>(&panorama),
    })
}

fn measured<C: Calculus>(panorama: &StationView) -> [RelationSet; 6] {
    let [ab_c, bc_a, ca_b] = panorama.measure_triple::<C>([0, 1, 2], [C::universe(); 3]);
    let inverse = |s: RelationSet| C::tables().inverse(s);
    [
        ab_c,
        bc_a,
        ca_b,
        inverse(ab_c),
        inverse(bc_a),
        inverse(ca_b),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orders_parse_as_chains_and_pairs() {
        assert_eq!(parse_order("A<B<C").unwrap(), vec![(0, 1), (1, 2)]);
        assert_eq!(parse_order("A<B, c<a").unwrap(), vec![(0, 1), (2, 0)]);
        assert!(parse_order("").unwrap().is_empty());
        assert!(parse_order("A<D").is_err());
        assert!(parse_order("AB").is_err());
    }
}
