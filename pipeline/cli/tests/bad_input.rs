//! The bad-input suite (issue 16): a table per kind of input — image directories, images of
//! every format and size, calibrations, truth files, maps and networks, command-line
//! arguments — each case a fixture in its own temporary directory, the arguments, the exit
//! code and what the error message must name (the file, the field, the line or the option).
//!
//! Every case of the bad-input tables guarantees:
//! - the binary does not panic (no "panicked" on stderr) and ends by itself, not by a signal;
//! - it does not exit 0: 2 for bad input (1 only for `map check`'s verdict "inconsistent");
//! - the message names what is wrong and where;
//! - nothing in the case's directory changed: no output file, no hidden temporary, no empty
//!   output directory, and an earlier run's outputs (where the case has one) byte for byte as
//!   they were.
//!
//! Odd input that is still usable (a bad right panorama, one unreadable station, a 16-bit PNG)
//! is not bad input: the `usable_input_*` table asserts exit 0, the warning naming the file,
//! and whole outputs. Interrupts are covered by `an_interrupted_run_leaves_the_earlier_outputs_whole`
//! in run.rs.

use super::pipeline;
use std::collections::BTreeMap;
use std::io::Cursor;
use std::path::{Path, PathBuf};
use std::process::Output;

const DEMO: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../datasets/demo");

/// Prepares a case's directory (`{dir}` in its arguments).
type Setup = Box<dyn Fn(&Path) + Send + Sync>;

/// Where a case's message is printed.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Stream {
    Stderr,
    /// `map check` prints its verdict on an inconsistent network, exit 1.
    Stdout,
}

/// One row of a table: `args` are split at whitespace, then `{dir}` becomes the case's
/// directory; `says` must all appear in the message.
struct Case {
    what: &'static str,
    setup: Setup,
    args: &'static str,
    code: i32,
    says: Vec<&'static str>,
    stream: Stream,
}

impl Case {
    /// A case failing with exit 2 and a message on stderr holding every one of `says`.
    fn new(what: &'static str, args: &'static str, says: &[&'static str]) -> Case {
        Case {
            what,
            setup: Box::new(|_| {}),
            args,
            code: 2,
            says: says.to_vec(),
            stream: Stream::Stderr,
        }
    }

    fn setup(mut self, setup: impl Fn(&Path) + Send + Sync + 'static) -> Case {
        self.setup = Box::new(setup);
        self
    }

    /// `map check`'s verdict: exit 1, printed on stdout.
    fn verdict(mut self) -> Case {
        self.code = 1;
        self.stream = Stream::Stdout;
        self
    }
}

/// `pipeline run` over the case's image directory into its output directory.
const RUN: &str = "run --images {dir}/img --out {dir}/out";

/// Every file and directory under `dir` (hidden ones too), with the files' bytes.
fn snapshot(dir: &Path) -> BTreeMap<PathBuf, Option<Vec<u8>>> {
    let mut all = BTreeMap::new();
    let mut pending = vec![dir.to_path_buf()];
    while let Some(current) = pending.pop() {
        for entry in std::fs::read_dir(&current).unwrap() {
            let path = entry.unwrap().path();
            let relative = path.strip_prefix(dir).unwrap().to_path_buf();
            if path.is_dir() {
                all.insert(relative, None);
                pending.push(path);
            } else {
                all.insert(relative, Some(std::fs::read(&path).unwrap()));
            }
        }
    }
    all
}

/// What differs between two snapshots, by path.
fn changes(
    before: &BTreeMap<PathBuf, Option<Vec<u8>>>,
    after: &BTreeMap<PathBuf, Option<Vec<u8>>>,
) -> Vec<String> {
    let mut changed = Vec::new();
    for (path, content) in after {
        match before.get(path) {
            None => changed.push(format!("new {}", path.display())),
            Some(old) if old != content => changed.push(format!("changed {}", path.display())),
            Some(_) => {}
        }
    }
    for path in before.keys().filter(|p| !after.contains_key(*p)) {
        changed.push(format!("removed {}", path.display()));
    }
    changed
}

fn scratch() -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix("qrm-bad-input-")
        .tempdir()
        .unwrap()
}

/// Runs the binary with `template`'s arguments for the directory `dir`.
fn run_in(dir: &Path, template: &str) -> Output {
    let args: Vec<String> = template
        .split_whitespace()
        .map(|a| a.replace("{dir}", dir.to_str().unwrap()))
        .collect();
    pipeline(&args.iter().map(String::as_str).collect::<Vec<_>>())
}

/// Runs every case of a table of bad input and reports all that fail.
fn check_bad_input(table: &str, cases: Vec<Case>) {
    let failures: Vec<String> = cases
        .iter()
        .filter_map(|case| {
            let scratch = scratch();
            let dir = scratch.path();
            (case.setup)(dir);
            let before = snapshot(dir);
            let o = run_in(dir, case.args);
            let after = snapshot(dir);
            let stderr = String::from_utf8_lossy(&o.stderr);
            let stdout = String::from_utf8_lossy(&o.stdout);
            let message = match case.stream {
                Stream::Stderr => &stderr,
                Stream::Stdout => &stdout,
            };
            let mut problems = Vec::new();
            if stderr.contains("panicked") {
                problems.push("panicked".to_string());
            }
            assert_ne!(
                case.code, 0,
                "{}: a bad-input case expects failure",
                case.what
            );
            match o.status.code() {
                Some(code) if code == case.code => {}
                Some(code) => problems.push(format!("exit {code}, expected {}", case.code)),
                None => problems.push(format!("ended by a signal: {:?}", o.status)),
            }
            // clap prints its usage alone when no subcommand is given.
            if case.code == 2 && !stderr.contains("error:") && !stderr.contains("Usage:") {
                problems.push("no error message".to_string());
            }
            for needle in &case.says {
                if !message.contains(needle) {
                    problems.push(format!("message lacks {needle:?}"));
                }
            }
            let changed = changes(&before, &after);
            if !changed.is_empty() {
                problems.push(format!("the directory changed: {changed:?}"));
            }
            (!problems.is_empty()).then(|| {
                format!(
                    "{} ({}): {}\n    stderr: {}\n    stdout: {}",
                    case.what,
                    case.args,
                    problems.join("; "),
                    stderr.trim(),
                    stdout.lines().next().unwrap_or("")
                )
            })
        })
        .collect();
    assert!(
        failures.is_empty(),
        "{} of {} {table} cases failed:\n{}",
        failures.len(),
        cases.len(),
        failures.join("\n")
    );
}

// ---------------------------------------------------------------------------------------------
// Fixtures

/// `dir/img`: the first two demo stations with calib.toml and truth.json.
fn demo(dir: &Path) {
    let img = dir.join("img");
    std::fs::create_dir(&img).unwrap();
    for entry in std::fs::read_dir(DEMO).unwrap() {
        let path = entry.unwrap().path();
        let file = path.file_name().unwrap().to_string_lossy().to_string();
        let keep = match file.strip_prefix("station_") {
            Some(rest) => rest[..3].parse::<usize>().unwrap() < 2,
            None => true,
        };
        if keep {
            std::fs::copy(&path, img.join(&file)).unwrap();
        }
    }
}

/// [`demo`] and a good run of it in `dir/out` (scored: eval.json too).
fn demo_run(dir: &Path) {
    demo(dir);
    let o = run_in(dir, "run --images {dir}/img --out {dir}/out --quiet");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(dir.join("out/eval.json").is_file());
}

/// Replaces `from` by `to` in `dir/file`, which must hold it.
fn edit(dir: &Path, file: &str, from: &str, to: &str) {
    let path = dir.join(file);
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.contains(from), "{} lacks {from:?}", path.display());
    std::fs::write(&path, text.replacen(from, to, 1)).unwrap();
}

/// [`demo`] with `from` replaced by `to` in its calib.toml.
fn calib(from: &'static str, to: &'static str) -> impl Fn(&Path) + Send + Sync {
    move |dir| {
        demo(dir);
        edit(dir, "img/calib.toml", from, to);
    }
}

/// [`demo`] with every left panorama replaced: `bytes(original)` written as
/// `station_NNN_left.EXT`.
fn lefts(ext: &'static str, bytes: fn(&[u8]) -> Vec<u8>) -> impl Fn(&Path) + Send + Sync {
    move |dir| {
        demo(dir);
        for station in 0..2 {
            let png = dir.join(format!("img/station_{station:03}_left.png"));
            let original = std::fs::read(&png).unwrap();
            std::fs::remove_file(&png).unwrap();
            std::fs::write(png.with_extension(ext), bytes(&original)).unwrap();
        }
    }
}

/// An image encoded in memory.
fn encoded(image: image::DynamicImage, format: image::ImageFormat) -> Vec<u8> {
    let mut bytes = Cursor::new(Vec::new());
    image.write_to(&mut bytes, format).unwrap();
    bytes.into_inner()
}

/// A soil-coloured RGB image.
fn plain(width: u32, height: u32) -> image::DynamicImage {
    image::DynamicImage::ImageRgb8(image::RgbImage::from_pixel(
        width,
        height,
        image::Rgb([150, 110, 80]),
    ))
}

/// CRC-32 (IEEE) of PNG chunks.
fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &b in bytes {
        crc ^= u32::from(b);
        for _ in 0..8 {
            crc = if crc & 1 == 1 {
                (crc >> 1) ^ 0xedb8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

/// A PNG file of only its header and end: `width` × `height`, `bits` per sample, colour type
/// `colour` (0 grey, 2 RGB).
fn png_header(width: u32, height: u32, bits: u8, colour: u8) -> Vec<u8> {
    let mut file = b"\x89PNG\r\n\x1a\n".to_vec();
    for (kind, data) in [
        (
            &b"IHDR"[..],
            [
                &width.to_be_bytes()[..],
                &height.to_be_bytes(),
                &[bits, colour, 0, 0, 0],
            ]
            .concat(),
        ),
        (b"IEND", Vec::new()),
    ] {
        file.extend((data.len() as u32).to_be_bytes());
        let chunk = [kind, &data].concat();
        file.extend(&chunk);
        file.extend(crc32(&chunk).to_be_bytes());
    }
    file
}

/// A 24-bit BMP file (a format the reader is not built for).
fn bmp(width: u32, height: u32) -> Vec<u8> {
    let row = (width * 3 + 3) & !3;
    let size = 54 + row * height;
    let mut file = b"BM".to_vec();
    file.extend(size.to_le_bytes());
    file.extend([0; 4]);
    file.extend(54u32.to_le_bytes());
    file.extend(40u32.to_le_bytes());
    file.extend(width.to_le_bytes());
    file.extend(height.to_le_bytes());
    file.extend(1u16.to_le_bytes());
    file.extend(24u16.to_le_bytes());
    file.extend([0; 24]);
    file.resize(size as usize, 128);
    file
}

/// A GIF file's header and trailer, no frame.
fn gif(width: u16, height: u16) -> Vec<u8> {
    let mut file = b"GIF89a".to_vec();
    file.extend(width.to_le_bytes());
    file.extend(height.to_le_bytes());
    file.extend([0, 0, 0, 0x3b]);
    file
}

/// A little-endian TIFF file with an empty directory.
fn tiff() -> Vec<u8> {
    let mut file = b"II*\0".to_vec();
    file.extend(8u32.to_le_bytes());
    file.extend([0; 6]);
    file
}

/// A simulated EDC map in `dir/sim` (8 landmarks, ids 0..8), FDC in `dir/fdc`, and the EDC
/// map of another world over the same ids in `dir/other`.
fn maps(dir: &Path) {
    for (sub, extra) in [
        ("sim", ""),
        ("fdc", " --calculus fdc"),
        ("other", " --seed 2"),
    ] {
        let args =
            format!("simulate single --landmarks 8 --stations 20 --out {{dir}}/{sub}{extra}");
        let o = run_in(dir, &args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
}

/// [`maps`] and `dir/bad.json`: the EDC map edited by `edit`.
fn bad_map(edit: fn(&mut serde_json::Value)) -> impl Fn(&Path) + Send + Sync {
    move |dir| {
        maps(dir);
        let mut map: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join("sim/map.json")).unwrap())
                .unwrap();
        edit(&mut map);
        std::fs::write(dir.join("bad.json"), map.to_string()).unwrap();
    }
}

/// `dir/name` holding `text`.
fn file(name: &'static str, text: &'static str) -> impl Fn(&Path) + Send + Sync {
    move |dir| std::fs::write(dir.join(name), text).unwrap()
}

/// `dir/img/truth.json` edited as JSON by `edit`, written as `dir/img/NAME`.
fn truth_edited(name: &'static str, edit: fn(&mut serde_json::Value)) -> impl Fn(&Path) {
    move |dir| {
        let mut truth: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join("img/truth.json")).unwrap())
                .unwrap();
        edit(&mut truth);
        std::fs::write(dir.join("img").join(name), truth.to_string()).unwrap();
    }
}

// ---------------------------------------------------------------------------------------------
// Tables

/// Image directories that hold no station.
fn directory_cases() -> Vec<Case> {
    vec![
        Case::new(
            "the directory does not exist",
            "run --images {dir}/nope --out {dir}/out",
            &["image directory", "nope", "does not exist"],
        ),
        Case::new(
            "a file instead of a directory",
            "run --images {dir}/a-file --out {dir}/out",
            &["a-file is not a directory"],
        )
        .setup(file("a-file", "x")),
        Case::new("an empty directory", RUN, &["img holds no panoramas"])
            .setup(|d| std::fs::create_dir(d.join("img")).unwrap()),
        Case::new(
            "only files that are not images",
            RUN,
            &["img holds no panoramas"],
        )
        .setup(|d| {
            demo(d);
            for entry in std::fs::read_dir(d.join("img")).unwrap() {
                let path = entry.unwrap().path();
                if path.extension().is_some_and(|e| e == "png") {
                    std::fs::rename(&path, path.with_extension("txt")).unwrap();
                }
            }
        }),
        Case::new(
            "only images in formats it does not read (.bmp, .gif, .tiff)",
            RUN,
            &["img holds no panoramas", ".png, .jpg or .jpeg"],
        )
        .setup(|d| {
            demo(d);
            for station in 0..2 {
                for side in ["left", "right"] {
                    std::fs::remove_file(d.join(format!("img/station_{station:03}_{side}.png")))
                        .unwrap();
                }
            }
            std::fs::write(d.join("img/station_000.bmp"), bmp(1024, 192)).unwrap();
            std::fs::write(d.join("img/station_001.gif"), gif(1024, 192)).unwrap();
            std::fs::write(d.join("img/station_002.tiff"), tiff()).unwrap();
        }),
        Case::new("only hidden images", RUN, &["img holds no panoramas"]).setup(|d| {
            demo(d);
            for entry in std::fs::read_dir(d.join("img")).unwrap() {
                let path = entry.unwrap().path();
                let name = path.file_name().unwrap().to_str().unwrap().to_string();
                if name.ends_with(".png") {
                    std::fs::rename(&path, d.join("img").join(format!(".{name}"))).unwrap();
                }
            }
        }),
        Case::new(
            "only right panoramas, no left partner",
            RUN,
            &["img holds no station", "station_000_right.png"],
        )
        .setup(|d| {
            demo(d);
            for station in 0..2 {
                std::fs::remove_file(d.join(format!("img/station_{station:03}_left.png"))).unwrap();
            }
        }),
        Case::new(
            "only images that leave no station name",
            RUN,
            &["img holds no station", "_left.png"],
        )
        .setup(|d| {
            demo(d);
            std::fs::rename(d.join("img/station_000_left.png"), d.join("img/_left.png")).unwrap();
            std::fs::rename(
                d.join("img/station_000_right.png"),
                d.join("img/_right.png"),
            )
            .unwrap();
            for side in ["left", "right"] {
                std::fs::remove_file(d.join(format!("img/station_001_{side}.png"))).unwrap();
            }
        }),
    ]
}

/// Every station's primary panorama unreadable: nothing to map. Each unreadable file is named
/// with its problem (with `--quiet` too: `earlier_run_cases`).
fn image_cases() -> Vec<Case> {
    let none = "none of the 2 stations";
    vec![
        Case::new(
            "zero-byte PNGs",
            RUN,
            &[
                none,
                "station_000_left.png: cannot decode",
                "station_001_left.png",
            ],
        )
        .setup(lefts("png", |_| Vec::new())),
        Case::new(
            "PNGs cut after their header",
            RUN,
            &[none, "station_000_left.png: cannot decode"],
        )
        .setup(lefts("png", |b| b[..40].to_vec())),
        Case::new(
            "PNGs cut in their pixel data",
            RUN,
            &[none, "station_000_left.png: cannot decode"],
        )
        .setup(lefts("png", |b| b[..b.len() / 3].to_vec())),
        Case::new(
            "text renamed .png",
            RUN,
            &[none, "station_000_left.png: cannot decode"],
        )
        .setup(lefts("png", |_| b"not a png".to_vec())),
        Case::new(
            "text renamed .jpg",
            RUN,
            &[none, "station_000_left.jpg: cannot decode"],
        )
        .setup(lefts("jpg", |_| b"not a jpeg".to_vec())),
        Case::new(
            "valid PNGs of another size",
            RUN,
            &[
                none,
                "station_000_left.png: 64×32 pixels, but the calibration is for 1024×192",
            ],
        )
        .setup(lefts("png", |_| {
            encoded(plain(64, 32), image::ImageFormat::Png)
        })),
        Case::new(
            "valid PNGs of the calibration's width, another height",
            RUN,
            &[none, "station_000_left.png: 1024×96 pixels"],
        )
        .setup(lefts("png", |_| {
            encoded(plain(1024, 96), image::ImageFormat::Png)
        })),
        Case::new(
            "valid JPEGs of another size",
            RUN,
            &[none, "station_000_left.jpg: 64×32 pixels"],
        )
        .setup(lefts("jpg", |_| {
            encoded(plain(64, 32), image::ImageFormat::Jpeg)
        })),
        Case::new(
            "BMPs renamed .png",
            RUN,
            &[none, "station_000_left.png: cannot decode", "Bmp"],
        )
        .setup(lefts("png", |_| bmp(1024, 192))),
        Case::new(
            "GIFs renamed .png",
            RUN,
            &[none, "station_000_left.png: cannot decode", "Gif"],
        )
        .setup(lefts("png", |_| gif(1024, 192))),
        Case::new(
            "TIFFs renamed .png",
            RUN,
            &[none, "station_000_left.png: cannot decode", "Tiff"],
        )
        .setup(lefts("png", |_| tiff())),
        Case::new(
            "1-bit PNGs",
            RUN,
            &[none, "station_000_left.png: a 1-bit PNG"],
        )
        .setup(lefts("png", |_| png_header(1024, 192, 1, 0))),
        Case::new(
            "2-bit PNGs",
            RUN,
            &[none, "station_000_left.png: a 2-bit PNG"],
        )
        .setup(lefts("png", |_| png_header(1024, 192, 2, 0))),
        Case::new(
            "PNG headers claiming 65535 × 65535 pixels",
            RUN,
            &[none, "station_000_left.png: cannot decode"],
        )
        .setup(lefts("png", |_| png_header(65535, 65535, 8, 2))),
    ]
}

/// Calibrations: missing, unreadable, not TOML, a field missing, unknown or out of range, or a
/// size the panoramas do not have. Each message names the file and the field.
fn calibration_cases() -> Vec<Case> {
    let toml = "calib.toml";
    vec![
        Case::new(
            "no calib.toml in the image directory",
            RUN,
            &["no calibration", "calib.toml does not exist", "--calib"],
        )
        .setup(|d| {
            demo(d);
            std::fs::remove_file(d.join("img/calib.toml")).unwrap();
        }),
        Case::new(
            "--calib names a missing file",
            "run --images {dir}/img --out {dir}/out --calib {dir}/nope.toml",
            &["no calibration", "nope.toml does not exist"],
        )
        .setup(demo),
        Case::new(
            "--calib names a directory",
            "run --images {dir}/img --out {dir}/out --calib {dir}/img",
            &["cannot read calibration", "img"],
        )
        .setup(demo),
        Case::new("an empty file", RUN, &[toml, "missing field `image`"]).setup(|d| {
            demo(d);
            std::fs::write(d.join("img/calib.toml"), "").unwrap();
        }),
        Case::new("not TOML", RUN, &[toml, "line 1"]).setup(|d| {
            demo(d);
            std::fs::write(d.join("img/calib.toml"), "width: 1024\n").unwrap();
        }),
        Case::new("a section missing", RUN, &[toml, "missing field `mast`"])
            .setup(calib("[mast]\nheight_m = 1.5\n", "")),
        Case::new("focal_px missing", RUN, &[toml, "missing field `focal_px`"])
            .setup(calib("focal_px = 163.0\n", "")),
        Case::new(
            "baseline_m missing",
            RUN,
            &[toml, "missing field `baseline_m`"],
        )
        .setup(calib("baseline_m = 0.3", "")),
        Case::new(
            "direction missing",
            RUN,
            &[toml, "missing field `direction`"],
        )
        .setup(calib("direction = \"clockwise\"", "")),
        Case::new("width missing", RUN, &[toml, "missing field `width`"])
            .setup(calib("width = 1024\n", "")),
        Case::new("an unknown field", RUN, &[toml, "unknown field `roll_deg`"])
            .setup(calib("height_m = 1.5", "height_m = 1.5\nroll_deg = 0.0")),
        Case::new("an unknown section", RUN, &[toml, "unknown field `lens`"])
            .setup(calib("[mast]", "[lens]\nmodel = \"fisheye\"\n\n[mast]")),
        Case::new(
            "an unknown column direction",
            RUN,
            &[
                toml,
                "field `azimuth.direction`",
                "unknown variant `sideways`",
            ],
        )
        .setup(calib("\"clockwise\"", "\"sideways\"")),
        Case::new(
            "a fractional width",
            RUN,
            &[toml, "field `image.width`", "1024.5"],
        )
        .setup(calib("width = 1024", "width = 1024.5")),
        Case::new(
            "a negative width",
            RUN,
            &[toml, "field `image.width`", "-1024"],
        )
        .setup(calib("width = 1024", "width = -1024")),
        Case::new("a width too small", RUN, &[toml, "`image.width` is 4"])
            .setup(calib("width = 1024", "width = 4")),
        Case::new("a height of one row", RUN, &[toml, "`image.height` is 1"])
            .setup(calib("height = 192", "height = 1")),
        Case::new(
            "a number written as text",
            RUN,
            &[toml, "field `elevation.focal_px`", "string"],
        )
        .setup(calib("focal_px = 163.0", "focal_px = \"163\"")),
        Case::new("focal_px NaN", RUN, &[toml, "`elevation.focal_px`", "NaN"])
            .setup(calib("focal_px = 163.0", "focal_px = nan")),
        Case::new(
            "focal_px infinite",
            RUN,
            &[toml, "`elevation.focal_px`", "inf"],
        )
        .setup(calib("focal_px = 163.0", "focal_px = inf")),
        Case::new(
            "focal_px zero",
            RUN,
            &[toml, "`elevation.focal_px` must be positive"],
        )
        .setup(calib("focal_px = 163.0", "focal_px = 0.0")),
        Case::new(
            "focal_px negative",
            RUN,
            &[toml, "`elevation.focal_px` must be positive"],
        )
        .setup(calib("focal_px = 163.0", "focal_px = -163.0")),
        Case::new(
            "focal_px implausible for the width",
            RUN,
            &[toml, "`elevation.focal_px` is 1e300", "near square"],
        )
        .setup(calib("focal_px = 163.0", "focal_px = 1e300")),
        Case::new(
            "the horizon below the image",
            RUN,
            &[toml, "`elevation.horizon_row` is 300"],
        )
        .setup(calib("horizon_row = 75.0", "horizon_row = 300.0")),
        Case::new(
            "column0_deg infinite",
            RUN,
            &[toml, "`azimuth.column0_deg`", "finite"],
        )
        .setup(calib("column0_deg = 180.0", "column0_deg = -inf")),
        Case::new(
            "mast height zero",
            RUN,
            &[toml, "`mast.height_m` must be positive"],
        )
        .setup(calib("height_m = 1.5", "height_m = 0.0")),
        Case::new("mast height NaN", RUN, &[toml, "`mast.height_m`", "NaN"])
            .setup(calib("height_m = 1.5", "height_m = nan")),
        Case::new("a mast too high", RUN, &[toml, "`mast.height_m` is 25.0"])
            .setup(calib("height_m = 1.5", "height_m = 25.0")),
        Case::new(
            "a negative baseline",
            RUN,
            &[toml, "`stereo.baseline_m` must not be negative"],
        )
        .setup(calib("baseline_m = 0.3", "baseline_m = -0.3")),
        Case::new(
            "a baseline too large for the mast",
            RUN,
            &[toml, "`stereo.baseline_m` is 5.0", "twice the mast"],
        )
        .setup(calib("baseline_m = 0.3", "baseline_m = 5.0")),
        Case::new(
            "a width the panoramas do not have",
            RUN,
            &[
                "none of the 2 stations",
                "station_000_left.png: 1024×192 pixels, but the calibration is for 512×192",
            ],
        )
        .setup(calib("width = 1024", "width = 512")),
        Case::new(
            "a height the panoramas do not have",
            RUN,
            &[
                "none of the 2 stations",
                "station_001_left.png: 1024×192 pixels, but the calibration is for 1024×96",
            ],
        )
        .setup(calib("height = 192", "height = 96")),
    ]
}

/// Truth files for `run --truth` (checked before any work) and `eval`, and run directories
/// `eval` cannot score. `eval` leaves the run's eval.json as it was.
fn truth_cases() -> Vec<Case> {
    const RUN_TRUTH: &str = "run --images {dir}/img --out {dir}/out --truth {dir}/img/bad.json";
    const EVAL: &str = "eval --run {dir}/out --truth {dir}/img/bad.json";
    const EVAL_GOOD: &str = "eval --run {dir}/out --truth {dir}/img/truth.json";
    let nothing = "--truth; nothing was written";
    vec![
        Case::new(
            "run: --truth names a missing file",
            "run --images {dir}/img --out {dir}/out --truth {dir}/img/nope.json",
            &[nothing, "nope.json"],
        )
        .setup(demo),
        Case::new(
            "run: an empty truth file",
            RUN_TRUTH,
            &[nothing, "bad.json", "EOF"],
        )
        .setup(|d| {
            demo(d);
            std::fs::write(d.join("img/bad.json"), "").unwrap();
        }),
        Case::new(
            "run: a truth file that is not JSON",
            RUN_TRUTH,
            &[nothing, "bad.json"],
        )
        .setup(|d| {
            demo(d);
            std::fs::write(d.join("img/bad.json"), "rocks: 3\n").unwrap();
        }),
        Case::new(
            "run: JSON of another shape",
            RUN_TRUTH,
            &[nothing, "bad.json", "missing field"],
        )
        .setup(|d| {
            demo(d);
            std::fs::write(d.join("img/bad.json"), r#"{"images": []}"#).unwrap();
        }),
        Case::new(
            "run: a file of another format (a map)",
            RUN_TRUTH,
            &[nothing, "bad.json", "qrm-truth"],
        )
        .setup(|d| {
            demo(d);
            truth_edited("bad.json", |t| t["format"] = "qrm-map".into())(d);
        }),
        Case::new(
            "run: a truth file of a later version",
            RUN_TRUTH,
            &[nothing, "bad.json", "version 7"],
        )
        .setup(|d| {
            demo(d);
            truth_edited("bad.json", |t| t["version"] = 7.into())(d);
        }),
        Case::new(
            "run: another dataset's truth (same names, other images)",
            "run --images {dir}/img --out {dir}/out --truth {dir}/img/truth.json",
            &[
                "station_000_left.png is not the image the truth file describes",
                "nothing was written",
            ],
        )
        .setup(|d| {
            demo(d);
            let (a, b) = (
                d.join("img/station_000_left.png"),
                d.join("img/station_001_left.png"),
            );
            let (bytes_a, bytes_b) = (std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
            std::fs::write(&a, bytes_b).unwrap();
            std::fs::write(&b, bytes_a).unwrap();
        }),
        Case::new(
            "run: a truth file of other file names",
            RUN_TRUTH,
            &[
                "the truth file does not describe station_000_left.png",
                "nothing was written",
            ],
        )
        .setup(|d| {
            demo(d);
            truth_edited("bad.json", |t| {
                for image in t["images"].as_array_mut().unwrap() {
                    let file = image["file"].as_str().unwrap().replace("station", "stop");
                    image["file"] = file.into();
                }
            })(d);
        }),
        Case::new(
            "eval: the truth file is missing (and so is the calibration beside it)",
            "eval --run {dir}/out --truth {dir}/nowhere/truth.json",
            &["nowhere/truth.json"],
        )
        .setup(demo_run),
        Case::new(
            "eval: the truth file is missing",
            "eval --run {dir}/out --truth {dir}/img/nope.json",
            &["cannot read", "nope.json"],
        )
        .setup(demo_run),
        Case::new("eval: an empty truth file", EVAL, &["bad.json", "EOF"]).setup(|d| {
            demo_run(d);
            std::fs::write(d.join("img/bad.json"), "").unwrap();
        }),
        Case::new("eval: a truth file that is not JSON", EVAL, &["bad.json"]).setup(|d| {
            demo_run(d);
            std::fs::write(d.join("img/bad.json"), "<truth/>").unwrap();
        }),
        Case::new(
            "eval: a file of another format (the run's map)",
            "eval --run {dir}/out --truth {dir}/img/map.json",
            &["map.json"],
        )
        .setup(|d| {
            demo_run(d);
            std::fs::copy(d.join("out/map.json"), d.join("img/map.json")).unwrap();
        }),
        Case::new(
            "eval: another dataset's truth",
            EVAL,
            &["does not fit the run", "crc32:00000000"],
        )
        .setup(|d| {
            demo_run(d);
            truth_edited("bad.json", |t| {
                t["images"][0]["digest"] = "crc32:00000000".into();
            })(d);
        }),
        Case::new(
            "eval: --run is an image directory, not a run",
            "eval --run {dir}/img --truth {dir}/img/truth.json",
            &["cannot read", "img/stations.json"],
        )
        .setup(demo_run),
        Case::new(
            "eval: --run does not exist",
            "eval --run {dir}/nope --truth {dir}/img/truth.json",
            &["cannot read", "nope/stations.json"],
        )
        .setup(demo_run),
        Case::new(
            "eval: the run's map.json is corrupt",
            EVAL_GOOD,
            &["out/map.json"],
        )
        .setup(|d| {
            demo_run(d);
            std::fs::write(d.join("out/map.json"), "{\"format\": \"qrm-map\"").unwrap();
        }),
        Case::new(
            "eval: the run's map.json is another calculus's",
            EVAL_GOOD,
            &["out/map.json", "expected EDC"],
        )
        .setup(|d| {
            demo_run(d);
            edit(d, "out/map.json", "\"EDC\"", "\"FDC\"");
        }),
        Case::new(
            "eval: the run's stations.json is corrupt",
            EVAL_GOOD,
            &["out/stations.json"],
        )
        .setup(|d| {
            demo_run(d);
            std::fs::write(d.join("out/stations.json"), "[{}]").unwrap();
        }),
        Case::new(
            "eval: the run's landmarks.json is missing",
            EVAL_GOOD,
            &["cannot read", "out/landmarks.json"],
        )
        .setup(|d| {
            demo_run(d);
            std::fs::remove_file(d.join("out/landmarks.json")).unwrap();
        }),
        Case::new(
            "eval: --calib names a missing file",
            "eval --run {dir}/out --truth {dir}/img/truth.json --calib {dir}/nope.toml",
            &["cannot read calibration", "nope.toml"],
        )
        .setup(demo_run),
    ]
}

/// Failed runs into the directory of an earlier good run: its outputs stay byte for byte.
fn earlier_run_cases() -> Vec<Case> {
    vec![
        Case::new(
            "a calibration field out of range",
            RUN,
            &["`elevation.focal_px` must be positive"],
        )
        .setup(|d| {
            demo_run(d);
            edit(d, "img/calib.toml", "focal_px = 163.0", "focal_px = -1.0");
        }),
        Case::new(
            "every panorama cut short",
            RUN,
            &[
                "none of the 2 stations",
                "station_001_left.png: cannot decode",
            ],
        )
        .setup(|d| {
            demo_run(d);
            for station in 0..2 {
                let path = d.join(format!("img/station_{station:03}_left.png"));
                let bytes = std::fs::read(&path).unwrap();
                std::fs::write(&path, &bytes[..bytes.len() / 2]).unwrap();
            }
        }),
        Case::new(
            "a truth file of other images",
            "run --images {dir}/img --out {dir}/out --truth {dir}/img/bad.json",
            &["--truth", "is not the image the truth file describes"],
        )
        .setup(|d| {
            demo_run(d);
            truth_edited("bad.json", |t| {
                t["images"][1]["digest"] = "crc32:00000000".into();
            })(d);
        }),
        Case::new("the images all gone", RUN, &["img holds no panoramas"]).setup(|d| {
            demo_run(d);
            for station in 0..2 {
                for side in ["left", "right"] {
                    std::fs::remove_file(d.join(format!("img/station_{station:03}_{side}.png")))
                        .unwrap();
                }
            }
        }),
        Case::new(
            "a corrupt truth.json in the image directory (no --truth)",
            RUN,
            &[
                "the image directory's truth.json",
                "--no-eval",
                "truth.json",
            ],
        )
        .setup(|d| {
            demo_run(d);
            std::fs::write(d.join("img/truth.json"), "{").unwrap();
        }),
        Case::new(
            "every panorama cut short, quietly",
            "run --images {dir}/img --out {dir}/out --quiet",
            &[
                "none of the 2 stations",
                "station_000_left.png: cannot decode",
            ],
        )
        .setup(|d| {
            demo_run(d);
            for station in 0..2 {
                let path = d.join(format!("img/station_{station:03}_left.png"));
                std::fs::write(&path, b"not a png").unwrap();
            }
        }),
    ]
}

/// Map files (`map info`, `merge`, `close`, `check`, `navigate`), text networks, and
/// landmarks a map lacks. `merge`, `close` and `info --rng` write nothing.
fn map_cases() -> Vec<Case> {
    vec![
        Case::new(
            "info: a missing file",
            "map info {dir}/nope.json",
            &["cannot read", "nope.json"],
        ),
        Case::new(
            "info: an empty file",
            "map info {dir}/m.json",
            &["m.json is not JSON"],
        )
        .setup(file("m.json", "")),
        Case::new(
            "info: not JSON",
            "map info {dir}/m.json",
            &["m.json is not JSON"],
        )
        .setup(file("m.json", "landmarks: 3")),
        Case::new(
            "info: JSON that is not a map",
            "map info {dir}/m.json",
            &["m.json has no \"calculus\" field"],
        )
        .setup(file("m.json", "[1, 2, 3]")),
        Case::new(
            "info: an RNG file, not a map",
            "map info {dir}/sim/rng.json",
            &["invalid map", "rng.json", "unknown field `edges`"],
        )
        .setup(maps),
        Case::new(
            "info: another format tag",
            "map info {dir}/bad.json",
            &["invalid map", "bad.json", "\"format\" is \"qrm-rng\""],
        )
        .setup(bad_map(|m| m["format"] = "qrm-rng".into())),
        Case::new(
            "info: a later version",
            "map info {dir}/bad.json",
            &["bad.json", "unsupported version 2"],
        )
        .setup(bad_map(|m| m["version"] = 2.into())),
        Case::new(
            "info: an unknown calculus",
            "map info {dir}/bad.json",
            &["bad.json", "unknown calculus \"RCC8\""],
        )
        .setup(bad_map(|m| m["calculus"] = "RCC8".into())),
        Case::new(
            "info: a relation out of range",
            "map info {dir}/bad.json",
            &["bad.json", "ab_c: relation 21 is not possible"],
        )
        .setup(bad_map(|m| {
            m["triples"][0]["ab_c"] = serde_json::json!([21])
        })),
        Case::new(
            "info: a negative relation",
            "map info {dir}/bad.json",
            &["bad.json", "bc_a: relation -3 is not possible"],
        )
        .setup(bad_map(|m| {
            m["triples"][0]["bc_a"] = serde_json::json!([-3])
        })),
        Case::new(
            "info: an empty relation",
            "map info {dir}/bad.json",
            &["bad.json", "ca_b is empty"],
        )
        .setup(bad_map(|m| m["triples"][0]["ca_b"] = serde_json::json!([]))),
        Case::new(
            "info: an inconsistent map",
            "map info {dir}/bad.json",
            &["bad.json", "not path consistent"],
        )
        .setup(bad_map(|m| {
            m["triples"][0]["ab_c"] = serde_json::json!([1])
        })),
        Case::new(
            "info: a landmark listed twice",
            "map info {dir}/bad.json",
            &["bad.json", "listed twice"],
        )
        .setup(bad_map(|m| {
            let first = m["landmarks"][0].clone();
            m["landmarks"].as_array_mut().unwrap().push(first);
        })),
        Case::new(
            "info: a triple of an unlisted landmark",
            "map info {dir}/bad.json",
            &["bad.json", "landmark 99 is not in \"landmarks\""],
        )
        .setup(bad_map(|m| m["triples"][0]["ids"][2] = 99.into())),
        Case::new(
            "info: more landmarks than the reader takes",
            "map info {dir}/bad.json",
            &["bad.json", "1001 landmarks"],
        )
        .setup(bad_map(|m| {
            m["landmarks"] = (0..1001).collect::<Vec<u32>>().into();
        })),
        Case::new(
            "info --rng of an FDC map",
            "map info {dir}/fdc/map.json --rng {dir}/rng.json",
            &["FDC maps have no RNG estimate"],
        )
        .setup(maps),
        Case::new(
            "merge: maps that contradict each other",
            "map merge {dir}/sim/map.json {dir}/other/map.json --out {dir}/merged.json",
            &["other/map.json contradicts the maps before it"],
        )
        .setup(maps),
        Case::new(
            "merge: maps of two calculi",
            "map merge {dir}/sim/map.json {dir}/fdc/map.json --out {dir}/merged.json",
            &["fdc/map.json", "expected EDC"],
        )
        .setup(maps),
        Case::new(
            "merge: a corrupt second map",
            "map merge {dir}/sim/map.json {dir}/bad.json --out {dir}/merged.json",
            &["bad.json", "not path consistent"],
        )
        .setup(bad_map(|m| {
            m["triples"][0]["ab_c"] = serde_json::json!([1])
        })),
        Case::new(
            "close: an inconsistent network",
            "map close {dir}/net.txt --out {dir}/closed.json",
            &[
                "net.txt is inconsistent",
                "0 1 2 {1}",
                "nothing was written",
            ],
        )
        .setup(file("net.txt", "0 1 2 {1}\n0 1 3 {5,6}\n1 2 0 {2}\n")),
        Case::new(
            "close: a missing network",
            "map close {dir}/net.txt --out {dir}/closed.json",
            &["cannot read", "net.txt"],
        ),
        Case::new(
            "close: a JSON network of another format",
            "map close {dir}/bad.json --out {dir}/closed.json",
            &["bad.json", "\"format\" is \"qrm-rng\""],
        )
        .setup(bad_map(|m| m["format"] = "qrm-rng".into())),
        Case::new(
            "check: a bad landmark id",
            "map check {dir}/net.txt",
            &["net.txt", "line 2", "\"x\" is not a landmark id"],
        )
        .setup(file("net.txt", "0 1 2 {1}\n0 1 x {2}\n")),
        Case::new(
            "check: a line cut short",
            "map check {dir}/net.txt",
            &["net.txt", "line 3", "not a landmark id"],
        )
        .setup(file("net.txt", "# two constraints\n0 1 2 {1}\n0 1\n")),
        Case::new(
            "check: a relation outside the calculus",
            "map check {dir}/net.txt --calculus fdc",
            &["net.txt", "line 1", "outside FDC"],
        )
        .setup(file("net.txt", "0 1 2 {16}\n")),
        Case::new(
            "check: a relation out of any range",
            "map check {dir}/net.txt",
            &["net.txt", "line 1", "relation 99"],
        )
        .setup(file("net.txt", "0 1 2 {1,99}\n")),
        Case::new(
            "check: a set left open",
            "map check {dir}/net.txt",
            &["net.txt", "line 1", "missing '}'"],
        )
        .setup(file("net.txt", "0 1 2 {1,2\n")),
        Case::new(
            "check: landmarks not distinct",
            "map check {dir}/net.txt",
            &["net.txt", "line 1", "not distinct"],
        )
        .setup(file("net.txt", "0 0 2 {1}\n")),
        Case::new(
            "check: an empty relation set",
            "map check {dir}/net.txt",
            &["net.txt", "line 1", "empty"],
        )
        .setup(file("net.txt", "0 1 2 {}\n")),
        Case::new(
            "check: an inconsistent network (the verdict)",
            "map check {dir}/net.txt",
            &["inconsistent", "0 1 2 {1}", "1 2 0 {2}"],
        )
        .setup(file("net.txt", "0 1 2 {1}\n0 1 3 {5,6}\n1 2 0 {2}\n"))
        .verdict(),
        Case::new(
            "navigate plan: an unknown start",
            "navigate plan --map {dir}/sim/map.json --from 42 --to 1",
            &["sim/map.json", "landmark 42 is not in the map"],
        )
        .setup(maps),
        Case::new(
            "navigate plan: an unknown goal",
            "navigate plan --map {dir}/sim/map.json --from 0 --to 99",
            &["sim/map.json", "landmark 99 is not in the map"],
        )
        .setup(maps),
        Case::new(
            "navigate plan: an FDC map",
            "navigate plan --map {dir}/fdc/map.json --from 0 --to 1",
            &["fdc/map.json", "no RNG estimate"],
        )
        .setup(maps),
        Case::new(
            "navigate plan: an inconsistent map",
            "navigate plan --map {dir}/bad.json --from 0 --to 1",
            &["bad.json", "not path consistent"],
        )
        .setup(bad_map(|m| {
            m["triples"][0]["ab_c"] = serde_json::json!([1])
        })),
        Case::new(
            "navigate plan: a missing map",
            "navigate plan --map {dir}/nope.json --from 0 --to 1",
            &["cannot read", "nope.json"],
        ),
        Case::new(
            "navigate hull: not JSON",
            "navigate hull --map {dir}/m.json",
            &["m.json is not JSON"],
        )
        .setup(file("m.json", "\u{0}\u{1}")),
    ]
}

/// Command lines: unknown commands and options, values out of their sets or ranges, numbers
/// that are not numbers, and outputs that would overwrite inputs.
fn argument_cases() -> Vec<Case> {
    let cases = vec![
        Case::new("no subcommand", "", &["Usage: pipeline <COMMAND>"]),
        Case::new(
            "an unknown subcommand",
            "frobnicate",
            &["unrecognized subcommand 'frobnicate'"],
        ),
        Case::new("run without --images", "run --out {dir}/out", &["--images"]),
        Case::new(
            "an unknown option",
            "run --images {dir}/img --out {dir}/out --fast",
            &["unexpected argument '--fast'"],
        )
        .setup(demo),
        Case::new(
            "--channels of no mode",
            "run --images {dir}/img --out {dir}/out --channels rgb",
            &["invalid value 'rgb' for '--channels"],
        )
        .setup(demo),
        Case::new(
            "--panoramas of no size",
            "run --images {dir}/img --out {dir}/out --panoramas huge",
            &["invalid value 'huge' for '--panoramas"],
        )
        .setup(demo),
        Case::new(
            "--out is the image directory",
            "run --images {dir}/img --out {dir}/img",
            &["is the image directory", "nothing was written"],
        )
        .setup(demo),
        Case::new(
            "--out is the image directory, spelt differently",
            "run --images {dir}/img --out {dir}/img/../img/.",
            &["is the image directory"],
        )
        .setup(demo),
        Case::new(
            "--out is a file",
            "run --images {dir}/img --out {dir}/a-file",
            &["cannot create output directory", "a-file"],
        )
        .setup(|d| {
            demo(d);
            std::fs::write(d.join("a-file"), "x").unwrap();
        }),
        Case::new(
            "classify: --calculus of no calculus",
            "classify --calculus rcc8 0,0 0,1 1,1",
            &["invalid value 'rcc8' for '--calculus"],
        ),
        Case::new(
            "classify: a point that is not x,y",
            "classify 0,0 0,1 1",
            &["point \"1\" must be written x,y"],
        ),
        Case::new(
            "classify: a coordinate that is not a number",
            "classify 0,0 0,1 x,3",
            &["bad x in point \"x,3\""],
        ),
        Case::new(
            "classify: an infinite coordinate",
            "classify inf,0 0,1 1,1",
            &["point \"inf,0\" must have finite coordinates"],
        ),
        Case::new(
            "classify: A and B coincide",
            "classify 1,1 1,1 0,0",
            &["A and B coincide"],
        ),
        Case::new("classify: a point missing", "classify 0,0 0,1", &["<C>"]),
        Case::new(
            "compose: a relation out of range",
            "compose 1,21 5",
            &["outside 1..=20"],
        ),
        Case::new(
            "compose: not a relation set",
            "compose one 5",
            &["invalid relation set \"one\""],
        ),
        Case::new(
            "unary: an unknown operator",
            "unary sideways 1",
            &["invalid value 'sideways'"],
        ),
        Case::new("unary: a set left open", "unary left {1,", &["missing '}'"]),
        Case::new(
            "unary: an FDC relation out of range",
            "unary --calculus fdc left 16",
            &["outside 1..=15"],
        ),
        Case::new(
            "measure: a bearing that is not a number",
            "measure 0 40 x",
            &["invalid value 'x'"],
        ),
        Case::new(
            "measure: a NaN bearing",
            "measure nan 40 100",
            &["not a finite angle"],
        ),
        Case::new(
            "measure: an unknown landmark in the order",
            "measure 0 40 100 --order A<D",
            &["unknown landmark \"D\""],
        ),
        Case::new(
            "measure: a cyclic order",
            "measure 0 40 100 --order A<B,B<A",
            &["range order", "cyclic"],
        ),
        Case::new(
            "measure: an uncertainty out of range",
            "measure 0 40 100 --uncertainty 60",
            &["--uncertainty 60"],
        ),
        Case::new(
            "measure: a NaN uncertainty",
            "measure 0 40 100 --uncertainty nan",
            &["--uncertainty NaN"],
        ),
        Case::new(
            "measure: two range intervals for three landmarks",
            "measure 0 40 100 --ranges 4:5,8:10",
            &["three intervals"],
        ),
        Case::new(
            "measure: a range interval that is not one",
            "measure 0 40 100 --ranges 4-5,-,-",
            &["\"4-5\"", "LOW:HIGH"],
        ),
        Case::new(
            "measure: a range interval upside down",
            "measure 0 40 100 --ranges 5:4,-,-",
            &["range interval of landmark 0 is [5, 4]"],
        ),
        Case::new(
            "measure: range intervals against the order",
            "measure 0 40 100 --order A<B --ranges 8:10,4:5,-",
            &["landmark 0 is ordered nearer than landmark 1"],
        ),
        Case::new(
            "map check: --calculus of no calculus",
            "map check {dir}/net.txt --calculus xdc",
            &["invalid value 'xdc' for '--calculus"],
        )
        .setup(file("net.txt", "0 1 2 {1}\n")),
        Case::new(
            "map merge: one map only",
            "map merge {dir}/sim/map.json --out {dir}/merged.json",
            &["2 values required"],
        )
        .setup(maps),
        Case::new(
            "navigate plan: --from not a number",
            "navigate plan --map {dir}/sim/map.json --from a --to 1",
            &["invalid value 'a' for '--from"],
        )
        .setup(maps),
        Case::new(
            "navigate plan: a negative landmark id",
            "navigate plan --map {dir}/sim/map.json --from -1 --to 1",
            &["unexpected argument '-1'"],
        )
        .setup(maps),
        Case::new(
            "navigate plan: --routes 0",
            "navigate plan --map {dir}/sim/map.json --from 0 --to 1 --routes 0",
            &["--routes must be at least 1"],
        )
        .setup(maps),
        Case::new(
            "navigate plan: --lambda NaN",
            "navigate plan --map {dir}/sim/map.json --from 0 --to 1 --lambda NaN",
            &["--lambda NaN"],
        )
        .setup(maps),
        Case::new(
            "simulate: --landmarks not a number",
            "simulate single --landmarks many --out {dir}/sim",
            &["invalid value 'many' for '--landmarks"],
        ),
    ];
    // Only a build without the rerun feature refuses --rrd.
    let without_rerun = cfg!(not(feature = "rerun")).then(|| {
        [
            Case::new(
                "--rrd in a build without rerun",
                "run --images {dir}/img --out {dir}/out --rrd",
                &["--rrd needs a build with the rerun feature"],
            )
            .setup(demo),
            Case::new(
                "navigate drive --rrd in a build without rerun",
                "navigate drive --images {dir}/img --run {dir}/img --out {dir}/out --rrd",
                &["--rrd needs a build with the rerun feature"],
            )
            .setup(demo),
        ]
    });
    cases
        .into_iter()
        .chain(without_rerun.into_iter().flatten())
        .collect()
}

#[test]
fn bad_directories() {
    check_bad_input("directory", directory_cases());
}

#[test]
fn bad_images() {
    check_bad_input("image", image_cases());
}

#[test]
fn bad_calibrations() {
    check_bad_input("calibration", calibration_cases());
}

#[test]
fn bad_truth_files_and_run_directories() {
    check_bad_input("truth", truth_cases());
}

#[test]
fn failed_runs_leave_an_earlier_run_whole() {
    check_bad_input("earlier-run", earlier_run_cases());
}

#[test]
fn bad_maps_and_networks() {
    check_bad_input("map", map_cases());
}

/// `directions` over a run or map it cannot use.
fn directions_cases() -> Vec<Case> {
    const DIRECTIONS: &str = "directions --run {dir}/out --from 0 --to 1";
    vec![
        Case::new(
            "directions: a landmark the map lacks",
            "directions --run {dir}/out --from 0 --to 999",
            &["landmark 999 is not in the map"],
        )
        .setup(demo_run),
        Case::new(
            "directions: no route on the legs the map proves",
            "directions --run {dir}/out --from 0 --to 3 --samples 0",
            &[
                "no route from landmark 0 to landmark 3",
                "proven by the map",
                "none chain there",
            ],
        )
        .setup(demo_run),
        Case::new(
            "directions: a run directory without stations.json",
            DIRECTIONS,
            &["cannot read", "stations.json"],
        )
        .setup(|d| {
            demo_run(d);
            std::fs::remove_file(d.join("out/stations.json")).unwrap();
        }),
        Case::new(
            "directions: a run whose stations.json lists none",
            DIRECTIONS,
            &["lists no stations"],
        )
        .setup(|d| {
            demo_run(d);
            std::fs::write(d.join("out/stations.json"), "[]").unwrap();
        }),
        Case::new(
            "directions: a run directory that does not exist",
            "directions --run {dir}/nowhere --from 0 --to 1",
            &["nowhere", "does not exist"],
        ),
        Case::new(
            "directions: an FDC map",
            "directions --map {dir}/fdc/map.json --from 0 --to 1",
            &["FDC map cannot rank neighbours"],
        )
        .setup(maps),
        Case::new(
            "directions: a scene beyond the reliability model",
            "directions --map {dir}/sim/map.json --from 0 --to 1 --scene 9",
            &["--scene 9"],
        )
        .setup(maps),
        Case::new(
            "directions: pictures without a run",
            "directions --map {dir}/sim/map.json --images {dir} --from 0 --to 1",
            &["--run"],
        )
        .setup(maps),
        Case::new(
            "directions: from a landmark to itself",
            "directions --map {dir}/sim/map.json --from 3 --to 3",
            &["you are there"],
        )
        .setup(maps),
        Case::new(
            "simulate probabilistic: no scenarios",
            "simulate probabilistic --scenarios 0 --out {dir}/p",
            &["--scenarios"],
        ),
        Case::new(
            "simulate probabilistic: no bearing noise (the sampler needs some)",
            "simulate probabilistic --bearing-noise 0 --out {dir}/p",
            &["--bearing-noise"],
        ),
        Case::new(
            "simulate probabilistic: noise levels not increasing",
            "simulate probabilistic --noise-levels 3,1 --out {dir}/p",
            &["--noise-levels"],
        ),
        Case::new(
            "simulate single --mode probabilistic: one view cannot resect",
            "simulate single --mode probabilistic --views 1 --out {dir}/s",
            &["--views"],
        ),
        Case::new(
            "simulate single --mode probabilistic: no particles",
            "simulate single --mode probabilistic --particles 0 --out {dir}/s",
            &["--particles"],
        ),
        Case::new(
            "simulate single --mode probabilistic: motion noise out of range",
            "simulate single --mode probabilistic --motion-noise 90 --out {dir}/s",
            &["--motion-noise"],
        ),
        Case::new(
            "simulate single: the beliefs' options without --mode probabilistic",
            "simulate single --motion-noise 3 --out {dir}/s",
            &["--motion-noise", "--mode probabilistic"],
        ),
        Case::new(
            "simulate single: an estimator without --mode probabilistic",
            "simulate single --estimator full --out {dir}/s",
            &["--estimator", "--mode probabilistic"],
        ),
        Case::new(
            "simulate single: wrong associations not a probability",
            "simulate single --wrong-associations 1.5 --out {dir}/s",
            &["--wrong-associations"],
        ),
        Case::new(
            "simulate directions: no trials",
            "simulate directions --trials 0 --out {dir}/study",
            &["--trials and --routes must be positive"],
        ),
    ]
}

#[test]
fn bad_directions() {
    check_bad_input("directions", directions_cases());
}

#[test]
fn bad_arguments() {
    check_bad_input("argument", argument_cases());
}

/// Issue 16 asks for at least 50 cases of bad input.
#[test]
fn the_suite_holds_enough_cases() {
    let tables = [
        directory_cases().len(),
        image_cases().len(),
        calibration_cases().len(),
        truth_cases().len(),
        earlier_run_cases().len(),
        map_cases().len(),
        argument_cases().len(),
        directions_cases().len(),
    ];
    assert!(tables.iter().sum::<usize>() >= 55, "{tables:?}");
}

// ---------------------------------------------------------------------------------------------
// Usable input

/// Odd input a run can still use: exit 0, a warning naming the file (where something is lost),
/// and whole outputs.
struct Usable {
    what: &'static str,
    setup: fn(&Path),
    warns: &'static [&'static str],
}

#[test]
fn usable_input_is_mapped_with_a_warning() {
    let cases = [
        Usable {
            what: "a right panorama of another size",
            setup: |d| {
                demo(d);
                std::fs::write(
                    d.join("img/station_000_right.png"),
                    encoded(plain(64, 32), image::ImageFormat::Png),
                )
                .unwrap();
            },
            warns: &[
                "station station_000: right panorama unusable, no stereo cue",
                "station_000_right.png: 64×32 pixels",
            ],
        },
        Usable {
            what: "a right panorama cut short",
            setup: |d| {
                demo(d);
                let path = d.join("img/station_001_right.png");
                let bytes = std::fs::read(&path).unwrap();
                std::fs::write(&path, &bytes[..bytes.len() / 2]).unwrap();
            },
            warns: &[
                "right panorama unusable",
                "station_001_right.png: cannot decode",
            ],
        },
        Usable {
            what: "one of the two stations unreadable",
            setup: |d| {
                demo(d);
                std::fs::write(d.join("img/station_001_left.png"), "").unwrap();
            },
            warns: &[
                "station station_001 skipped",
                "station_001_left.png: cannot decode",
            ],
        },
        Usable {
            what: "a left panorama without its right partner",
            setup: |d| {
                demo(d);
                std::fs::remove_file(d.join("img/station_001_right.png")).unwrap();
            },
            warns: &["station_001_left.png has no _right partner"],
        },
        Usable {
            what: "a right panorama without its left partner",
            setup: |d| {
                demo(d);
                std::fs::copy(
                    d.join("img/station_001_right.png"),
                    d.join("img/lonely_right.png"),
                )
                .unwrap();
            },
            warns: &["lonely_right.png has no _left partner"],
        },
        Usable {
            what: "16-bit PNG panoramas",
            setup: |d| {
                demo(d);
                for entry in std::fs::read_dir(d.join("img")).unwrap() {
                    let path = entry.unwrap().path();
                    if path.extension().is_some_and(|e| e == "png") {
                        let deep = image::open(&path).unwrap().to_rgb16();
                        image::DynamicImage::ImageRgb16(deep).save(&path).unwrap();
                    }
                }
            },
            warns: &[],
        },
    ];
    let mut failures = Vec::new();
    for case in &cases {
        let scratch = scratch();
        let dir = scratch.path();
        (case.setup)(dir);
        let o = run_in(dir, "run --images {dir}/img --out {dir}/out --no-eval");
        let stderr = String::from_utf8_lossy(&o.stderr);
        let mut problems = Vec::new();
        if !o.status.success() || stderr.contains("panicked") {
            problems.push(format!("{:?}", o.status));
        }
        problems.extend(
            case.warns
                .iter()
                .filter(|w| !stderr.contains(*w))
                .map(|w| format!("no warning {w:?}")),
        );
        if case.warns.is_empty() && stderr.contains("warning") {
            problems.push("a warning".to_string());
        }
        let written = snapshot(&dir.join("out"));
        for file in ["map.json", "stations.json", "summary.json", "run.mcap"] {
            if !written.contains_key(Path::new(file)) {
                problems.push(format!("no {file}"));
            }
        }
        let hidden: Vec<_> = written
            .keys()
            .filter(|p| p.file_name().unwrap().to_string_lossy().starts_with('.'))
            .collect();
        if !hidden.is_empty() {
            problems.push(format!("temporaries left: {hidden:?}"));
        }
        if !problems.is_empty() {
            failures.push(format!(
                "{}: {}\n    {}",
                case.what,
                problems.join("; "),
                stderr.trim()
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
