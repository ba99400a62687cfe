//! The few numbers a user wants at the end of `pipeline run` (also `summary.json`).

use super::mapper::Mapper;
use super::record::{Association, LateSighting, MergeRecord, MetricsRecord, StationRecord};
use crate::detection::Channels;
use qrm_core::calculus::Calculus;
use serde::{Deserialize, Serialize};
use std::fmt;

#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RunSummary {
    pub stations: usize,
    /// Stations whose primary image could not be used.
    pub stations_skipped: usize,
    /// Stations detected by luminance and stereo height (grayscale, JPEG or noisy-colour
    /// panoramas); the others by colour.
    #[serde(default)]
    pub stations_luminance: usize,
    /// Stations read, but with fewer than three usable detections: they add nothing.
    #[serde(default)]
    pub stations_unusable: usize,
    pub detections: usize,
    /// Landmarks of the published map (map.json), and those left out of it as fused from one
    /// station only (`Mapper::finish`).
    pub landmarks: usize,
    #[serde(default)]
    pub landmarks_uncorroborated: usize,
    pub triples: usize,
    pub open_fraction: f64,
    pub fully_constrained_fraction: f64,
    /// Panoramas the map rejected as contradicting it.
    pub contradictions: usize,
    /// Landmarks found to mix rocks and split after the fact (`association::audit`).
    #[serde(default)]
    pub landmarks_split: usize,
    /// Landmarks found to be one rock once the drive was over, and merged (`Mapper::finish`,
    /// `association::duplicate`).
    #[serde(default)]
    pub landmarks_merged: Vec<MergeRecord>,
    /// Observations held back at their station, resolved later (re-tested on a tighter map,
    /// recognised at later stations: `association::recognition`, or named by the drive's
    /// frames once it was over: `Mapper::finish`), and still pending at the end.
    pub held_back: usize,
    pub resolved_held_back: usize,
    #[serde(default)]
    pub recognised_held_back: usize,
    #[serde(default)]
    pub recognised_at_end: usize,
    pub pending_held_back: usize,
    /// Detections recorded unused for founding no landmark (pieces, doubted) and named at the
    /// end of the drive as a landmark founded after them.
    #[serde(default)]
    pub recognised_unused: usize,
    /// Held back at a stalled station (one whose detections registered against nothing) and
    /// fused when a later station's frames let it be mapped again (`Mapper::revisit_stalled`).
    #[serde(default)]
    pub revisited_held_back: usize,
    /// Stalled stations mapped again, and the sightings they added (detections held back or
    /// left out at first).
    #[serde(default)]
    pub stations_revisited: usize,
    #[serde(default)]
    pub revisited_sightings: usize,
    /// Held back and given up (waited too long, or their station had too few fused partners).
    pub expired_held_back: usize,
    pub rng_certain: usize,
    pub rng_uncertain: usize,
    /// Seconds per stage, summed over stations (decode and detect run on all cores, alongside
    /// mapping).
    pub seconds_decode: f64,
    pub seconds_detect: f64,
    pub seconds_range: f64,
    pub seconds_associate: f64,
    pub seconds_map: f64,
    /// The map's metrics and RNG estimate after every station, and handing each station to
    /// the recorders.
    #[serde(default)]
    pub seconds_metrics: f64,
    #[serde(default)]
    pub seconds_recording: f64,
    /// Wall time of the parallel decode+detect stage (from the start) and of the sequential
    /// mapping stage (from the first station mapped). Mapping runs alongside detection, so the
    /// two overlap, and each stage's per-station seconds above are wall seconds of threads
    /// that share the cores: their sums exceed the CPU time either stage would take alone.
    pub wall_front_end: f64,
    pub wall_mapping: f64,
    /// Wall time of writing the outputs (files, recordings, pictures), set by the writer; with
    /// the checks before the work and the span of the two stages above (mapping ends last) it
    /// accounts for the run.
    #[serde(default)]
    pub wall_outputs: f64,
    /// Wall time of opening the survey and checking the inputs (the truth's fingerprints of
    /// every image) before any work.
    #[serde(default)]
    pub wall_checks: f64,
    /// `--mode probabilistic`: how 002's beliefs (beliefs.json) were made.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub beliefs: Option<BeliefsSummary>,
}

/// How the run's 002 beliefs were made (`super::beliefs`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct BeliefsSummary {
    /// `fast` or `full`.
    pub estimator: String,
    /// Triples fused together at two or more stations, and those of them that got a belief
    /// (a chain of two or more views linked by a motion from the stereo placements).
    pub triples_seen_twice: usize,
    pub triples: usize,
    /// The bearing s.d. assumed, degrees.
    pub bearing_sd_deg: f64,
    pub wall_seconds: f64,
}

impl RunSummary {
    pub fn of<C: Calculus>(
        records: &[StationRecord],
        mapper: &Mapper<C>,
        published: &MetricsRecord,
        skipped: usize,
        wall_front_end: f64,
        wall_mapping: f64,
    ) -> RunSummary {
        let sum = |f: fn(&StationRecord) -> f64| records.iter().map(f).sum::<f64>();
        let revisited = || records.iter().flat_map(|r| &r.fusion.revisited);
        let held_back_at = |l: &LateSighting| {
            matches!(
                records[l.station].detections[l.detection].association,
                Association::HeldBack { .. }
            )
        };
        RunSummary {
            stations: records.len(),
            stations_skipped: skipped,
            stations_luminance: records
                .iter()
                .filter(|r| r.channels == Channels::Luminance)
                .count(),
            stations_unusable: records.iter().filter(|r| r.fusion.usable < 3).count(),
            detections: records.iter().map(|r| r.detections.len()).sum(),
            landmarks: published.landmarks,
            landmarks_uncorroborated: mapper.uncorroborated.len(),
            triples: published.triples,
            open_fraction: published.open_fraction,
            fully_constrained_fraction: published.fully_constrained_fraction,
            contradictions: records
                .iter()
                .filter(|r| r.fusion.contradiction.is_some())
                .count(),
            landmarks_split: records.iter().map(|r| r.fusion.splits.len()).sum(),
            landmarks_merged: mapper.merged.clone(),
            held_back: records
                .iter()
                .flat_map(|r| &r.detections)
                .filter(|d| matches!(d.association, Association::HeldBack { .. }))
                .count(),
            resolved_held_back: records.iter().map(|r| r.fusion.resolved_held_back).sum(),
            recognised_held_back: records.iter().map(|r| r.fusion.recognised.len()).sum(),
            recognised_at_end: mapper
                .recognised_at_end
                .iter()
                .filter(|l| held_back_at(l))
                .count(),
            pending_held_back: mapper.held_back(),
            recognised_unused: mapper
                .recognised_at_end
                .iter()
                .filter(|l| !held_back_at(l))
                .count(),
            revisited_held_back: revisited().filter(|l| held_back_at(l)).count(),
            stations_revisited: {
                let mut stations: Vec<usize> = revisited().map(|l| l.station).collect();
                stations.sort_unstable();
                stations.dedup();
                stations.len()
            },
            revisited_sightings: revisited().count(),
            expired_held_back: mapper.expired,
            rng_certain: published.rng_certain,
            rng_uncertain: published.rng_uncertain,
            seconds_decode: sum(|r| r.seconds.decode),
            seconds_detect: sum(|r| r.seconds.detect),
            seconds_range: sum(|r| r.seconds.range),
            seconds_associate: sum(|r| r.seconds.associate),
            seconds_map: sum(|r| r.seconds.map),
            seconds_metrics: sum(|r| r.seconds.metrics),
            seconds_recording: sum(|r| r.seconds.recording),
            wall_front_end,
            wall_mapping,
            wall_outputs: 0.0,
            wall_checks: 0.0,
            beliefs: None,
        }
    }
}

impl fmt::Display for RunSummary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "{} stations ({} skipped), {} detections → {} landmarks, {} triples",
            self.stations, self.stations_skipped, self.detections, self.landmarks, self.triples
        )?;
        match self.landmarks_uncorroborated {
            0 => {}
            1 => writeln!(
                f,
                "1 more landmark was fused from one station only and left out of map.json and landmarks.json"
            )?,
            n => writeln!(
                f,
                "{n} more landmarks were fused from one station only and left out of map.json and landmarks.json"
            )?,
        }
        if self.stations_unusable > 0 {
            writeln!(
                f,
                "{} stations had fewer than 3 usable detections and added nothing (warnings in stations.json)",
                self.stations_unusable
            )?;
        }
        let luminance = self.stations_luminance;
        match luminance {
            0 => writeln!(f, "rocks told from the ground by colour")?,
            n if n == self.stations => writeln!(
                f,
                "rocks told from the ground by luminance and stereo height (grayscale, JPEG, or colour too noisy to trust)"
            )?,
            n => writeln!(
                f,
                "rocks told from the ground by luminance and stereo height at {n} stations (grayscale, JPEG, or colour too noisy to trust), by colour at the others"
            )?,
        }
        writeln!(
            f,
            "map: {:.1} % of states open, {:.1} % of triples fully constrained; RNG {} certain + {} uncertain edges",
            100.0 * self.open_fraction,
            100.0 * self.fully_constrained_fraction,
            self.rng_certain,
            self.rng_uncertain
        )?;
        writeln!(
            f,
            "contradictions: {}; landmarks split: {}; held back: {} ({} resolved by re-test, {} recognised at later stations, {} named by the drive's frames at its end, {} fused when their station was revisited, {} given up, {} pending)",
            self.contradictions,
            self.landmarks_split,
            self.held_back,
            self.resolved_held_back,
            self.recognised_held_back,
            self.recognised_at_end,
            self.revisited_held_back,
            self.expired_held_back,
            self.pending_held_back
        )?;
        if !self.landmarks_merged.is_empty() {
            let merges: Vec<String> = self
                .landmarks_merged
                .iter()
                .map(|m| {
                    format!(
                        "{} into {} ({} pairs of stations)",
                        m.duplicate, m.landmark, m.frame_pairs
                    )
                })
                .collect();
            writeln!(
                f,
                "landmarks found to be one rock once the drive was over, merged: {}",
                merges.join(", ")
            )?;
        }
        if self.recognised_unused > 0 {
            writeln!(
                f,
                "pieces and doubted detections (recorded unused) named at the end as landmarks founded after them: {}",
                self.recognised_unused
            )?;
        }
        if self.stations_revisited > 0 {
            writeln!(
                f,
                "{} stalled stations (registered against nothing at first) mapped again once later stations gave them frames: {} sightings",
                self.stations_revisited, self.revisited_sightings
            )?;
        }
        if let Some(b) = &self.beliefs {
            writeln!(
                f,
                "002 beliefs ({} estimator, bearing s.d. {:.2}°): {} of the {} triples fused together at two or more stations, in {:.2} s",
                b.estimator, b.bearing_sd_deg, b.triples, b.triples_seen_twice, b.wall_seconds
            )?;
        }
        write!(
            f,
            "time: checks {:.2} s | decode {:.2} s + detect {:.2} s (threads, {:.2} s wall) | alongside: range {:.2} s, associate {:.2} s, map {:.2} s, metrics and RNG {:.2} s, recording {:.2} s ({:.2} s wall) | outputs {:.2} s",
            self.wall_checks,
            self.seconds_decode,
            self.seconds_detect,
            self.wall_front_end,
            self.seconds_range,
            self.seconds_associate,
            self.seconds_map,
            self.seconds_metrics,
            self.seconds_recording,
            self.wall_mapping,
            self.wall_outputs
        )
    }
}
