//! `run.mcap`: per station, one JSON message on each channel, each channel with a JSON schema
//! (`schemas/`), so generic MCAP tools can list and plot the fields.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::Path;

use ::mcap::records::MessageHeader;
use serde::Serialize;

use super::{Problem, Recorder, RecordingError, RngDrawing};
use qrm_atomic_file::Temporary;
use qrm_vision::run::{
    Association, LateSighting, MetricsRecord, RegistrationRecord, StageSeconds, StationRecord,
};

/// The channels, in the order their ids are kept.
#[derive(Clone, Copy)]
enum Topic {
    Detections,
    Bearings,
    RangeOrder,
    Association,
    Measurements,
    MapMetrics,
    Rng,
}

impl Topic {
    const ALL: [Topic; 7] = [
        Topic::Detections,
        Topic::Bearings,
        Topic::RangeOrder,
        Topic::Association,
        Topic::Measurements,
        Topic::MapMetrics,
        Topic::Rng,
    ];

    /// Topic, schema name, JSON schema.
    fn describe(self) -> (&'static str, &'static str, &'static str) {
        match self {
            Topic::Detections => (
                "/detections",
                "qrm.Detections",
                include_str!("schemas/detections.json"),
            ),
            Topic::Bearings => (
                "/bearings",
                "qrm.Bearings",
                include_str!("schemas/bearings.json"),
            ),
            Topic::RangeOrder => (
                "/range_order",
                "qrm.RangeOrder",
                include_str!("schemas/range_order.json"),
            ),
            Topic::Association => (
                "/association",
                "qrm.Association",
                include_str!("schemas/association.json"),
            ),
            Topic::Measurements => (
                "/measurements",
                "qrm.Measurements",
                include_str!("schemas/measurements.json"),
            ),
            Topic::MapMetrics => (
                "/map_metrics",
                "qrm.MapMetrics",
                include_str!("schemas/map_metrics.json"),
            ),
            Topic::Rng => ("/rng", "qrm.Rng", include_str!("schemas/rng.json")),
        }
    }
}

/// Writes `run.mcap` (see `docs/RUN_OUTPUTS.md`). The run has no clock of its own, so station
/// `i`'s messages are logged and published at `i` seconds: players step one station a second.
pub struct McapRecorder {
    // Before `temporary`, so that it is dropped first: an unfinished writer completes the
    // temporary file on drop, and only then does `temporary` remove it.
    writer: ::mcap::Writer<BufWriter<File>>,
    /// Channel ids in [`Topic::ALL`] order.
    channels: [u16; 7],
    temporary: Temporary,
}

impl McapRecorder {
    /// Starts a recording that [`Recorder::finish`] moves to `path`.
    pub fn create(path: impl AsRef<Path>) -> Result<Self, RecordingError> {
        let path = path.as_ref();
        let temporary = Temporary::beside(path);
        let start = || -> Result<_, Problem> {
            let file = qrm_atomic_file::create_file(temporary.path())?;
            let mut writer = ::mcap::Writer::new(BufWriter::new(file))?;
            let mut channels = [0; 7];
            for (id, topic) in channels.iter_mut().zip(Topic::ALL) {
                let (topic, schema_name, schema) = topic.describe();
                let schema = writer.add_schema(schema_name, "jsonschema", schema.as_bytes())?;
                *id = writer.add_channel(schema, topic, "json", &BTreeMap::new())?;
            }
            Ok((writer, channels))
        };
        let (writer, channels) = start().map_err(|problem| RecordingError {
            path: path.to_path_buf(),
            problem,
        })?;
        Ok(Self {
            writer,
            channels,
            temporary,
        })
    }

    fn write(
        &mut self,
        topic: Topic,
        index: usize,
        message: &impl Serialize,
    ) -> Result<(), Problem> {
        let data = serde_json::to_vec(message)?;
        let nanoseconds = index as u64 * 1_000_000_000;
        let header = MessageHeader {
            channel_id: self.channels[topic as usize],
            sequence: index as u32,
            log_time: nanoseconds,
            publish_time: nanoseconds,
        };
        self.writer.write_to_known_channel(&header, &data)?;
        Ok(())
    }

    fn error(&self, problem: Problem) -> RecordingError {
        RecordingError {
            path: self.temporary.target().to_path_buf(),
            problem,
        }
    }

    fn write_station(&mut self, r: &StationRecord) -> Result<(), Problem> {
        self.write_front_end(r)?;
        self.write_mapping(r)
    }

    /// The detections, bearings and range evidence of one station.
    fn write_front_end(&mut self, r: &StationRecord) -> Result<(), Problem> {
        let (index, station) = (r.index, r.station.as_str());
        let detections = r.detections.iter().enumerate();
        self.write(
            Topic::Detections,
            index,
            &DetectionsMessage {
                index,
                station,
                detections: detections
                    .clone()
                    .map(|(detection, d)| Detection {
                        detection,
                        bbox: d.bbox,
                        centroid: d.centroid,
                        contact_row: d.contact_row,
                        pixels: d.pixels,
                        stereo_column: d.stereo_column,
                    })
                    .collect(),
            },
        )?;
        self.write(
            Topic::Bearings,
            index,
            &BearingsMessage {
                index,
                station,
                bearings: detections
                    .clone()
                    .map(|(detection, d)| Bearing {
                        detection,
                        bearing: d.bearing,
                        uncertainty: d.bearing_uncertainty,
                    })
                    .collect(),
            },
        )?;
        self.write(
            Topic::RangeOrder,
            index,
            &RangeOrderMessage {
                index,
                station,
                ranges: detections
                    .clone()
                    .map(|(detection, d)| Range {
                        detection,
                        ground: d.range.ground,
                        stereo: d.range.stereo,
                        size: d.range.size,
                        fused: d.range.fused,
                        conflict: d.range.conflict,
                    })
                    .collect(),
                nearer: &r.order,
            },
        )
    }

    /// Association, fusion and the map's state after one station.
    fn write_mapping(&mut self, r: &StationRecord) -> Result<(), Problem> {
        let (index, station) = (r.index, r.station.as_str());
        self.write(
            Topic::Association,
            index,
            &AssociationMessage {
                index,
                station,
                associations: r
                    .detections
                    .iter()
                    .enumerate()
                    .map(|(detection, d)| Decision {
                        detection,
                        association: &d.association,
                    })
                    .collect(),
                registrations: &r.registrations,
            },
        )?;
        let f = &r.fusion;
        self.write(
            Topic::Measurements,
            index,
            &MeasurementsMessage {
                index,
                station,
                files: &r.files,
                landmarks: f.landmarks,
                triples: f.triples,
                relations_tightened: f.relations_tightened,
                resolved_held_back: f.resolved_held_back,
                recognised: &f.recognised,
                revisited: &f.revisited,
                contradiction: f.contradiction.as_deref(),
                warnings: &r.warnings,
            },
        )?;
        self.write(
            Topic::MapMetrics,
            index,
            &MapMetricsMessage {
                index,
                station,
                metrics: &r.metrics,
                seconds: &r.seconds,
            },
        )
    }
}

impl Recorder for McapRecorder {
    fn wants_panorama(&self) -> bool {
        false
    }

    fn station(
        &mut self,
        record: &StationRecord,
        _panorama: &image::RgbImage,
    ) -> Result<(), RecordingError> {
        self.write_station(record).map_err(|p| self.error(p))
    }

    fn rng(&mut self, index: usize, drawing: &RngDrawing) -> Result<(), RecordingError> {
        let message = RngMessage {
            index,
            landmarks: drawing
                .landmarks
                .iter()
                .map(|&(landmark, position)| RngLandmark { landmark, position })
                .collect(),
            edges: drawing
                .edges
                .iter()
                .map(|&(from, to, cost)| RngEdge { from, to, cost })
                .collect(),
        };
        self.write(Topic::Rng, index, &message)
            .map_err(|p| self.error(p))
    }

    fn finish(self: Box<Self>) -> Result<Temporary, RecordingError> {
        let McapRecorder {
            mut writer,
            temporary,
            ..
        } = *self;
        let path = temporary.target().to_path_buf();
        let complete = || -> Result<(), Problem> {
            writer.finish()?;
            writer
                .into_inner()
                .into_inner()
                .map_err(|e| e.into_error())?;
            Ok(())
        };
        complete().map_err(|problem| RecordingError { path, problem })?;
        Ok(temporary)
    }
}

// The messages, shaped as `schemas/*.json` describe them.

#[derive(Serialize)]
struct DetectionsMessage<'a> {
    index: usize,
    station: &'a str,
    detections: Vec<Detection>,
}

#[derive(Serialize)]
struct Detection {
    detection: usize,
    bbox: [u32; 4],
    centroid: [f64; 2],
    contact_row: f64,
    pixels: u32,
    stereo_column: Option<f64>,
}

#[derive(Serialize)]
struct BearingsMessage<'a> {
    index: usize,
    station: &'a str,
    bearings: Vec<Bearing>,
}

#[derive(Serialize)]
struct Bearing {
    detection: usize,
    bearing: f64,
    uncertainty: f64,
}

#[derive(Serialize)]
struct RangeOrderMessage<'a> {
    index: usize,
    station: &'a str,
    ranges: Vec<Range>,
    nearer: &'a [(usize, usize)],
}

/// serde_json writes an infinite `high` as `null` (JSON has no infinity), as the schema says.
#[derive(Serialize)]
struct Range {
    detection: usize,
    ground: Option<[f64; 2]>,
    stereo: Option<[f64; 2]>,
    size: Option<[f64; 2]>,
    fused: [f64; 2],
    conflict: bool,
}

#[derive(Serialize)]
struct AssociationMessage<'a> {
    index: usize,
    station: &'a str,
    associations: Vec<Decision<'a>>,
    registrations: &'a [RegistrationRecord],
}

#[derive(Serialize)]
struct Decision<'a> {
    detection: usize,
    /// Adds `decision` and, by decision, `landmark`, `candidates` or the `reason` it is unused.
    #[serde(flatten)]
    association: &'a Association,
}

#[derive(Serialize)]
struct MeasurementsMessage<'a> {
    index: usize,
    station: &'a str,
    files: &'a [String],
    landmarks: usize,
    triples: usize,
    relations_tightened: usize,
    resolved_held_back: usize,
    recognised: &'a [LateSighting],
    revisited: &'a [LateSighting],
    contradiction: Option<&'a str>,
    warnings: &'a [String],
}

#[derive(Serialize)]
struct MapMetricsMessage<'a> {
    index: usize,
    station: &'a str,
    #[serde(flatten)]
    metrics: &'a MetricsRecord,
    seconds: &'a StageSeconds,
}

#[derive(Serialize)]
struct RngMessage {
    index: usize,
    landmarks: Vec<RngLandmark>,
    edges: Vec<RngEdge>,
}

#[derive(Serialize)]
struct RngLandmark {
    landmark: u32,
    position: [f64; 2],
}

#[derive(Serialize)]
struct RngEdge {
    from: u32,
    to: u32,
    cost: f64,
}
