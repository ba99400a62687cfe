//! `drive.rrd` for the rerun viewer (`pipeline navigate drive --rrd`, the `rerun` feature): the
//! world's rocks and the map's landmarks at their rocks once, then on the sequence timeline
//! `step` (every step of every trip in turn) the rover's true position and path so far, the
//! bearing it drives, and the navigator's time and identified landmarks as curves.

use super::Problem;
use qrm_synth::closed_loop::Trip;
use std::path::Path;

/// The timeline: steps of all trips, one after the other.
const TIMELINE: &str = "step";

/// A rock (position, footprint radius) and the map's landmarks at their rocks.
pub struct DriveScene {
    pub rocks: Vec<([f64; 2], f64)>,
    pub landmarks: Vec<(u32, [f64; 2])>,
}

/// The 2-D view's y axis points down; negating y keeps north up.
fn view([x, y]: [f64; 2]) -> [f32; 2] {
    [x as f32, -y as f32]
}

/// Writes `trips` over `scene` to `path` (a temporary file the caller moves into place).
pub fn write_drive_rrd(path: &Path, scene: &DriveScene, trips: &[Trip]) -> Result<(), Problem> {
    let rerun = |e: rerun::RecordingStreamError| Problem::Rerun(e.to_string());
    // Enabled explicitly: the `RERUN` environment variable must not silently empty a file the
    // user asked for.
    let stream = rerun::RecordingStreamBuilder::new("qrm-drive")
        .enabled(true)
        .save(path)
        .map_err(|e| Problem::Rerun(e.to_string()))?;
    stream
        .log_static(
            "world/rocks",
            &rerun::Points2D::new(scene.rocks.iter().map(|(p, _)| view(*p)))
                .with_radii(scene.rocks.iter().map(|(_, r)| *r as f32))
                .with_colors([rerun::Color::from_rgb(150, 120, 100)]),
        )
        .map_err(rerun)?;
    stream
        .log_static(
            "world/landmarks",
            &rerun::Points2D::new(scene.landmarks.iter().map(|(_, p)| view(*p)))
                .with_labels(scene.landmarks.iter().map(|(id, _)| format!("L{id}")))
                .with_colors([rerun::Color::from_rgb(40, 140, 255)]),
        )
        .map_err(rerun)?;
    let mut sequence = 0i64;
    for trip in trips {
        let mut path: Vec<[f32; 2]> = Vec::new();
        for step in &trip.steps {
            stream.set_time_sequence(TIMELINE, sequence);
            sequence += 1;
            let at = view(step.position);
            path.push(at);
            stream
                .log(
                    "rover/position",
                    &rerun::Points2D::new([at])
                        .with_labels([format!("trip {} → L{}", trip.number, trip.goal)])
                        .with_radii([0.25]),
                )
                .map_err(rerun)?;
            stream
                .log("rover/path", &rerun::LineStrips2D::new([path.clone()]))
                .map_err(rerun)?;
            let heading = match step.bearing_deg {
                Some(bearing) => (step.heading_deg + bearing).to_radians(),
                None => f64::NAN,
            };
            if heading.is_finite() {
                // World azimuth of the bearing driven; y negated as for positions.
                let arrow = [heading.cos() as f32, -heading.sin() as f32];
                stream
                    .log(
                        "rover/driving",
                        &rerun::Arrows2D::from_vectors([arrow])
                            .with_origins([at])
                            .with_labels([match step.target {
                                Some(target) => format!("{} L{target}", step.command),
                                None => step.command.to_string(),
                            }]),
                    )
                    .map_err(rerun)?;
            } else {
                stream
                    .log("rover/driving", &rerun::Clear::flat())
                    .map_err(rerun)?;
            }
            for (name, value) in [
                ("navigator/seconds", step.navigator_seconds),
                ("navigator/identified", step.identified.len() as f64),
                ("navigator/detections", step.detections as f64),
            ] {
                stream
                    .log(name, &rerun::Scalars::single(value))
                    .map_err(rerun)?;
            }
        }
    }
    stream
        .flush_blocking()
        .map_err(|e| Problem::Rerun(e.to_string()))?;
    // Writes the footer and closes the file.
    stream.finalize_deferred_sinks();
    Ok(())
}
