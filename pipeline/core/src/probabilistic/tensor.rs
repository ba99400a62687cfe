//! The offline tables of the probabilistic map (002 §III-E, §IV; seed digest C.5–C.6), generated
//! by `tools/gen-tables` (format: `tables/README.md`).
//!
//! - The composition tensor `K[i][j][k] = P(AB:D = k | AB:C = i, BC:D = j)`, with `C` uniform
//!   in region `i` and `D` uniform in region `j` of its own frame, both truncated to the disc
//!   `|L| ≤ r_max` (`|AB| = 1`): most EDC regions are unbounded. Stored as counts of sampled
//!   configurations, so that the committed file is exactly what the generator produces.
//! - The region centroids `c_i = E[L^{AB:C} | L ∈ s_i]` under 002's scenario generator (three
//!   landmarks uniform in `[−3, 3] × [−3, 4]`), for gmd.

use super::belief::{Belief, STATES};
use crate::geometry::Point;
use thiserror::Error;

/// Why a table file does not parse.
#[derive(Debug, Error, PartialEq, Eq)]
pub enum TableError {
    #[error("line {line}: {reason}")]
    Line { line: usize, reason: String },
    #[error("{0}")]
    Missing(String),
}

fn line_error(line: usize, reason: impl Into<String>) -> TableError {
    TableError::Line {
        line,
        reason: reason.into(),
    }
}

/// `K` as sampled counts: `counts[(i−1)·20 + (j−1)][k−1]` configurations with `AB:D = k` out of
/// `totals[…]`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CompositionTensor {
    /// The truncation radius, in `|AB|` units, written as in the file.
    pub r_max: String,
    counts: Vec<[u32; STATES]>,
    totals: Vec<u32>,
}

impl CompositionTensor {
    /// An empty tensor to count into.
    pub fn new(r_max: &str) -> CompositionTensor {
        CompositionTensor {
            r_max: r_max.to_string(),
            counts: vec![[0; STATES]; STATES * STATES],
            totals: vec![0; STATES * STATES],
        }
    }

    fn cell(i: u8, j: u8) -> usize {
        (i as usize - 1) * STATES + (j as usize - 1)
    }

    /// Counts one sampled configuration of cell `(i, j)` with `AB:D = k`.
    pub fn record(&mut self, i: u8, j: u8, k: u8) {
        let cell = Self::cell(i, j);
        self.counts[cell][k as usize - 1] += 1;
        self.totals[cell] += 1;
    }

    /// Adds another tensor's counts (of the same `r_max`).
    pub fn absorb(&mut self, other: &CompositionTensor) {
        for (cell, counts) in other.counts.iter().enumerate() {
            for (k, &n) in counts.iter().enumerate() {
                self.counts[cell][k] += n;
            }
            self.totals[cell] += other.totals[cell];
        }
    }

    /// `K[i][j][·]`, or `None` for a cell without samples.
    pub fn row(&self, i: u8, j: u8) -> Option<Belief> {
        let cell = Self::cell(i, j);
        Belief::from_weights(self.counts[cell].map(f64::from))
    }

    /// Samples behind cell `(i, j)`.
    pub fn total(&self, i: u8, j: u8) -> u32 {
        self.totals[Self::cell(i, j)]
    }

    /// 002 Eq. (11)–(13): `P(AB:D = k) = Σ_i Σ_j P(AB:C = i)·P(BC:D = j)·K[i][j][k]`. `None`
    /// when no sampled cell carries the operands' mass.
    pub fn compose(&self, ab_c: &Belief, bc_d: &Belief) -> Option<Belief> {
        let mut out = [0.0; STATES];
        for i in 1..=STATES as u8 {
            let pi = ab_c.probability(i);
            if pi == 0.0 {
                continue;
            }
            for j in 1..=STATES as u8 {
                let w = pi * bc_d.probability(j);
                if w == 0.0 {
                    continue;
                }
                if let Some(row) = self.row(i, j) {
                    for (o, p) in out.iter_mut().zip(row.probabilities()) {
                        *o += w * p;
                    }
                }
            }
        }
        Belief::from_weights(out)
    }

    /// The file text (format: `tables/README.md`), with `comments` after the header.
    pub fn to_text(&self, comments: &[&str]) -> String {
        let mut s = format!(
            "# calculus EDC\n# relations {STATES}\n# r_max {}\n",
            self.r_max
        );
        for c in comments {
            s.push_str(&format!("# {c}\n"));
        }
        for i in 1..=STATES as u8 {
            for j in 1..=STATES as u8 {
                let cell = Self::cell(i, j);
                s.push_str(&format!("{i} {j} {}", self.totals[cell]));
                for (k, &n) in self.counts[cell].iter().enumerate() {
                    if n > 0 {
                        s.push_str(&format!(" {}:{n}", k + 1));
                    }
                }
                s.push('\n');
            }
        }
        s
    }

    pub fn parse(text: &str) -> Result<CompositionTensor, TableError> {
        let mut r_max = None;
        let mut tensor = CompositionTensor::new("");
        let mut seen = vec![false; STATES * STATES];
        for (n, line) in text.lines().enumerate() {
            let line_no = n + 1;
            if let Some(comment) = line.strip_prefix('#') {
                if let Some(value) = comment.trim().strip_prefix("r_max ") {
                    r_max = Some(value.trim().to_string());
                }
                continue;
            }
            if line.trim().is_empty() {
                continue;
            }
            let fields: Vec<&str> = line.split_whitespace().collect();
            if fields.len() < 3 {
                return Err(line_error(line_no, "expected `i j total k:count …`"));
            }
            let state = |s: &str| {
                s.parse::<u8>()
                    .ok()
                    .filter(|r| (1..=STATES as u8).contains(r))
                    .ok_or_else(|| line_error(line_no, format!("{s:?} is no EDC state")))
            };
            let (i, j) = (state(fields[0])?, state(fields[1])?);
            let total: u32 = fields[2]
                .parse()
                .map_err(|_| line_error(line_no, format!("{:?} is no count", fields[2])))?;
            let cell = Self::cell(i, j);
            if seen[cell] {
                return Err(line_error(line_no, format!("cell ({i}, {j}) given twice")));
            }
            seen[cell] = true;
            for entry in &fields[3..] {
                let (k, count) = entry
                    .split_once(':')
                    .ok_or_else(|| line_error(line_no, format!("{entry:?} is not k:count")))?;
                let count: u32 = count
                    .parse()
                    .map_err(|_| line_error(line_no, format!("{entry:?} has no count")))?;
                tensor.counts[cell][state(k)? as usize - 1] += count;
            }
            if tensor.counts[cell].iter().sum::<u32>() != total {
                return Err(line_error(line_no, "the counts do not add up to the total"));
            }
            tensor.totals[cell] = total;
        }
        if seen.iter().any(|s| !s) {
            return Err(TableError::Missing(
                "not every one of the 400 cells is given".into(),
            ));
        }
        tensor.r_max = r_max.ok_or_else(|| TableError::Missing("no `# r_max` header".into()))?;
        Ok(tensor)
    }

    /// The committed tensor for `r_max = 3` (the default; `tables/`).
    pub fn committed() -> &'static CompositionTensor {
        static TENSOR: std::sync::OnceLock<CompositionTensor> = std::sync::OnceLock::new();
        TENSOR.get_or_init(|| {
            CompositionTensor::parse(qrm_tables::EDC_PROBABILISTIC_COMPOSITION)
                .expect("committed tables/edc_probabilistic_composition.txt")
        })
    }
}

/// The centroid of each EDC region in the `AB` frame (`A = (0,0)`, `B = (0,1)`).
#[derive(Clone, Debug, PartialEq)]
pub struct RegionCentroids {
    /// `(centroid, samples)` per region `1..=20`.
    pub rows: Vec<(Point, u64)>,
}

impl RegionCentroids {
    pub fn centroid(&self, region: u8) -> Point {
        self.rows[region as usize - 1].0
    }

    /// The file text: `region x y samples`, coordinates to 6 decimals.
    pub fn to_text(&self, comments: &[&str]) -> String {
        let mut s = format!("# calculus EDC\n# relations {STATES}\n");
        for c in comments {
            s.push_str(&format!("# {c}\n"));
        }
        for (r, (c, n)) in self.rows.iter().enumerate() {
            s.push_str(&format!("{} {:.6} {:.6} {n}\n", r + 1, c.x, c.y));
        }
        s
    }

    pub fn parse(text: &str) -> Result<RegionCentroids, TableError> {
        let mut rows = Vec::new();
        for (n, line) in text.lines().enumerate() {
            if line.starts_with('#') || line.trim().is_empty() {
                continue;
            }
            let fields: Vec<&str> = line.split_whitespace().collect();
            let parsed = match fields[..] {
                [r, x, y, count] => (
                    r.parse::<usize>().ok(),
                    x.parse::<f64>().ok(),
                    y.parse::<f64>().ok(),
                    count.parse::<u64>().ok(),
                ),
                _ => (None, None, None, None),
            };
            match parsed {
                (Some(r), Some(x), Some(y), Some(count))
                    if r == rows.len() + 1 && x.is_finite() && y.is_finite() =>
                {
                    rows.push((Point::new(x, y), count))
                }
                _ => {
                    return Err(line_error(
                        n + 1,
                        format!("expected `{} x y samples`", rows.len() + 1),
                    ))
                }
            }
        }
        if rows.len() != STATES {
            return Err(TableError::Missing(format!(
                "{} regions given, not {STATES}",
                rows.len()
            )));
        }
        Ok(RegionCentroids { rows })
    }

    /// The committed centroids (`tables/edc_region_centroids.txt`).
    pub fn committed() -> RegionCentroids {
        RegionCentroids::parse(qrm_tables::EDC_REGION_CENTROIDS)
            .expect("committed tables/edc_region_centroids.txt")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_tensor_round_trips_and_composes() {
        let mut k = CompositionTensor::new("3");
        for i in 1..=20 {
            for j in 1..=20 {
                k.record(i, j, 1 + (i + j) % 20);
                k.record(i, j, 5);
            }
        }
        let text = k.to_text(&["test"]);
        assert_eq!(CompositionTensor::parse(&text).unwrap(), k);
        let out = k.compose(&Belief::certain(2), &Belief::certain(3)).unwrap();
        assert_eq!(out.probability(6), 0.5);
        assert_eq!(out.probability(5), 0.5);
        let bad = text.replacen("1 1 2 3:1 5:1", "1 1 3 3:1 5:1", 1);
        assert!(CompositionTensor::parse(&bad)
            .unwrap_err()
            .to_string()
            .contains("add up"));
    }

    #[test]
    fn the_committed_tables_parse() {
        let k = CompositionTensor::committed();
        assert_eq!(k.r_max, "3");
        for i in 1..=20 {
            for j in 1..=20 {
                let row = k.row(i, j).expect("every cell sampled");
                assert!((row.probabilities().iter().sum::<f64>() - 1.0).abs() < 1e-9);
            }
        }
        assert_eq!(RegionCentroids::committed().rows.len(), 20);
    }
}
