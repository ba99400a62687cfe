//! Calculus tools, `measure`, `simulate` and `synth`: answers on good input, exit code 2 and a
//! message naming the problem on bad input.

use super::pipeline;
use std::process::Output;

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).trim().to_string()
}

#[test]
fn answers() {
    let o = pipeline(&["classify", "0,0", "0,1", "-2,3"]);
    assert!(o.status.success());
    assert_eq!(stdout(&o), "1");
    assert_eq!(
        stdout(&pipeline(&[
            "classify",
            "--calculus",
            "fdc",
            "0,0",
            "0,1",
            "0,2"
        ])),
        "2"
    );
    assert_eq!(
        stdout(&pipeline(&["classify", "0,0", "0,1", "0,3"])),
        "boundary"
    );
    assert_eq!(
        stdout(&pipeline(&["compose", "1,5,11", "5"])),
        "{1,5,11,12,17,18,19,20}"
    );
    assert_eq!(stdout(&pipeline(&["unary", "left", "{6,7}"])), "{1,5,11}");
    let demo = pipeline(&["demo"]);
    assert!(demo.status.success());
    assert!(stdout(&demo).contains("{1,5,11,12,17,18,19,20}"));
    assert!(stdout(&pipeline(&["tables"])).contains("0 undecided"));
}

/// A reader that stops early (`pipeline tables | head -0`) ends the process quietly: no panic
/// on the broken pipe.
#[cfg(unix)]
#[test]
fn a_closed_output_pipe_ends_quietly() {
    use std::os::unix::process::ExitStatusExt;
    use std::process::{Command, Stdio};
    let mut child = Command::new(env!("CARGO_BIN_EXE_pipeline"))
        .arg("tables")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("binary runs");
    // Closing the read end before the binary has started writing breaks the pipe.
    drop(child.stdout.take());
    let o = child.wait_with_output().expect("binary ends");
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(
        o.status.success() || o.status.signal() == Some(libc::SIGPIPE),
        "{:?}: {stderr}",
        o.status
    );
}

#[test]
fn bad_input_is_a_clear_error() {
    for (args, needle) in [
        (
            vec!["classify", "0,0", "0,1", "x,3"],
            "bad x in point \"x,3\"",
        ),
        (vec!["classify", "0,0", "0,1", "1"], "must be written x,y"),
        (vec!["classify", "1,1", "1,1", "0,0"], "A and B coincide"),
        (
            vec!["classify", "0,0", "0,1", "1e200,1e200"],
            "coordinates too large",
        ),
        (
            vec!["classify", "0,0", "0,1", "nan,1"],
            "finite coordinates",
        ),
        (vec!["compose", "1,21", "5"], "outside 1..=20"),
        (
            vec!["compose", "--calculus", "fdc", "16", "5"],
            "outside 1..=15",
        ),
        (vec!["unary", "left", "{1,"], "missing '}'"),
    ] {
        let o = pipeline(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains(needle), "{args:?}: {err}");
    }
}

#[test]
fn measures_a_triple() {
    let o = pipeline(&["measure", "0", "40", "100", "--order", "A<B<C"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = stdout(&o);
    assert!(text.starts_with("AB:C = {1,2,5}"), "{text}");
    assert_eq!(text.lines().count(), 6);
    let wide = stdout(&pipeline(&[
        "measure",
        "0",
        "40",
        "100",
        "--order",
        "A<B<C",
        "--uncertainty",
        "1",
    ]));
    // ±1° admits arrangements the exact bearings do not: AB:C gains regions.
    let regions = |t: &str| t.lines().next().unwrap().matches(',').count() + 1;
    assert!(regions(&wide) > regions(&text), "{wide}");
    for bad in [
        vec!["measure", "0", "40", "100", "--order", "A<D"],
        vec!["measure", "0", "40", "100", "--order", "A<B,B<A"],
        vec!["measure", "0", "40", "100", "--uncertainty", "60"],
        vec!["measure", "1e20", "0", "90", "--uncertainty", "1"],
        vec!["measure", "0", "40", "x"],
    ] {
        let o = pipeline(&bad);
        assert_eq!(o.status.code(), Some(2), "{bad:?}");
        assert!(!o.stderr.is_empty(), "{bad:?}");
    }
}

#[test]
fn simulates_and_writes_outputs() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    let o = pipeline(&[
        "simulate",
        "single",
        "--landmarks",
        "8",
        "--stations",
        "6",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for file in ["steps.csv", "map.json", "rng.json"] {
        assert!(dir.join(file).is_file(), "{file}");
    }
    let map = std::fs::read_to_string(dir.join("map.json")).unwrap();
    assert!(qrm_core::map::Hypergraph::<qrm_core::edc::Edc>::from_json(&map).is_ok());
    let o = pipeline(&[
        "simulate",
        "montecarlo",
        "--maps",
        "2",
        "--stations",
        "4",
        "--nearest",
        "5,8",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(dir.join("montecarlo.csv").is_file());
    for bad in [
        vec!["simulate", "montecarlo", "--nearest", "2"],
        vec!["simulate", "single", "--nearest", "2"],
        vec!["simulate", "single", "--landmarks", "100000"],
        vec!["map", "info", "/nonexistent/map.json"],
    ] {
        let o = pipeline(&bad);
        assert_eq!(o.status.code(), Some(2), "{bad:?}");
        assert!(
            String::from_utf8_lossy(&o.stderr).starts_with("error: "),
            "{bad:?}"
        );
    }
}

#[test]
fn synthesises_a_dataset_and_rejects_bad_calibrations() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    let o = pipeline(&[
        "synth",
        "--preset",
        "random",
        "--stations",
        "2",
        "--mono",
        "--scale",
        "0.1",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for file in [
        "calib.toml",
        "truth.json",
        "station_000.png",
        "station_001.png",
    ] {
        assert!(dir.join(file).is_file(), "{file}");
    }
    let bad = dir.join("bad.toml");
    let text = std::fs::read_to_string(dir.join("calib.toml")).unwrap();
    std::fs::write(&bad, text.replace("height_m", "height")).unwrap();
    for args in [
        vec![
            "synth",
            "--calib",
            bad.to_str().unwrap(),
            "--out",
            "/tmp/never",
        ],
        vec![
            "synth",
            "--calib",
            "/nonexistent/calib.toml",
            "--out",
            "/tmp/never",
        ],
        vec!["synth", "--scale", "0", "--out", "/tmp/never"],
        vec!["synth", "--stations", "0", "--out", "/tmp/never"],
        vec!["synth", "--sun-elevation", "1", "--out", "/tmp/never"],
        vec![
            "synth",
            "--rock-albedo-contrast",
            "1.5",
            "--out",
            "/tmp/never",
        ],
        vec!["synth", "--cluster", "-0.1", "--out", "/tmp/never"],
        vec![
            "synth",
            "--preset",
            "stress",
            "--gamma",
            "9",
            "--out",
            "/tmp/never",
        ],
    ] {
        let o = pipeline(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.starts_with("error: "), "{args:?}: {err}");
    }
    let o = pipeline(&[
        "synth",
        "--calib",
        bad.to_str().unwrap(),
        "--out",
        "/tmp/never",
    ]);
    assert!(String::from_utf8_lossy(&o.stderr).contains("height_m"));
    assert!(!std::path::Path::new("/tmp/never").exists());
}

/// `--preset stress` prints its draws and records them in `truth.json`, writes the drawn column
/// axis into `calib.toml`, and lets an option given replace its draw.
#[test]
fn synthesises_a_stress_member() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    let args = |seed: &'static str, extra: &[&'static str]| {
        let mut a = vec![
            "synth",
            "--preset",
            "stress",
            "--seed",
            seed,
            "--stations",
            "2",
            "--mono",
            "--scale",
            "0.1",
            "--out",
        ];
        a.push(dir.to_str().unwrap());
        a.extend(extra);
        pipeline(&a)
    };
    let o = args("4", &[]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let printed = stdout(&o);
    assert!(printed.contains("stress (seed 4)"), "{printed}");
    assert!(printed.contains("variant: layout "), "{printed}");
    let truth: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("truth.json")).unwrap()).unwrap();
    assert_eq!(truth["preset"], "stress");
    let variant = &truth["variant"];
    assert!(["marsyard", "random"].contains(&variant["layout"].as_str().unwrap()));
    assert_eq!(variant["width"], 410);
    let calib = std::fs::read_to_string(dir.join("calib.toml")).unwrap();
    let direction = variant["column_direction"].as_str().unwrap();
    assert!(
        calib.contains(&format!("direction = \"{direction}\"")),
        "{calib}"
    );
    let o = args("4", &["--sun-elevation", "8", "--jpeg", "85"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let truth: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("truth.json")).unwrap()).unwrap();
    assert_eq!(truth["variant"]["sun_elevation_deg"], 8.0);
    assert_eq!(truth["variant"]["jpeg_quality"], 85);
    assert!(dir.join("station_000.jpg").is_file());
}

#[test]
fn closes_and_checks_constraint_networks() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    let path = |name: &str| dir.join(name).to_str().unwrap().to_string();
    std::fs::write(
        dir.join("net.txt"),
        "# four landmarks\n0 1 2 {1}\n0 1 3 {5,6}\n1 2 3 3,4,9\n",
    )
    .unwrap();
    std::fs::write(dir.join("bad.txt"), "0 1 2 {1}\n0 1 3 {5,6}\n1 2 0 {2}\n").unwrap();
    let o = pipeline(&["map", "check", &path("net.txt")]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(stdout(&o).contains("consistent") && stdout(&o).contains("closing tightens 2"));
    let o = pipeline(&["map", "close", &path("net.txt"), "--out", &path("net.json")]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // The closed map is a map: `map info` reads it.
    assert!(pipeline(&["map", "info", &path("net.json")])
        .status
        .success());
    let o = pipeline(&["map", "check", &path("bad.txt")]);
    assert_eq!(o.status.code(), Some(1));
    let text = stdout(&o);
    assert!(
        text.contains("minimal set of 2 conflicting constraints"),
        "{text}"
    );
    assert!(text.contains("0 1 2 {1}") && text.contains("1 2 0 {2}") && !text.contains("0 1 3"));
    let o = pipeline(&["map", "close", &path("bad.txt"), "--out", &path("bad.json")]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("nothing was written"));
    assert!(!dir.join("bad.json").exists());
    std::fs::write(dir.join("typo.txt"), "0 1 2 {1}\n0 1 x {2}\n").unwrap();
    let o = pipeline(&["map", "check", &path("typo.txt"), "--calculus", "fdc"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("line 2"));
}

/// `map realize` places a simulated map's landmarks so that every relation holds, writes the
/// positions and a picture together, and refuses a map it cannot read with nothing written.
#[test]
fn realizes_a_map() {
    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    let path = |name: &str| dir.join(name).to_str().unwrap().to_string();
    let o = pipeline(&[
        "simulate",
        "single",
        "--landmarks",
        "12",
        "--stations",
        "20",
        "--out",
        &path("sim"),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = pipeline(&[
        "map",
        "realize",
        &path("sim/map.json"),
        "--out",
        &path("layout/real.json"),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(
        stdout(&o).contains("constrained relations holds"),
        "{}",
        stdout(&o)
    );
    let layout: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("layout/real.json")).unwrap())
            .unwrap();
    assert_eq!(layout["format"], "qrm-realization");
    assert_eq!(layout["exact"], true);
    assert_eq!(layout["violated"], 0);
    assert_eq!(layout["landmarks"].as_array().unwrap().len(), 12);
    assert!(dir.join("layout/real.png").is_file());
    std::fs::write(dir.join("not-a-map.json"), "{\"calculus\": \"EDC\"}").unwrap();
    let o = pipeline(&[
        "map",
        "realize",
        &path("not-a-map.json"),
        "--out",
        &path("bad.json"),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("not-a-map.json"));
    assert!(!dir.join("bad.json").exists() && !dir.join("bad.png").exists());
}

/// `simulate probabilistic` writes 002's Table I for the three algorithms, and with almost no
/// noise the full and fast estimates put everything on the true state.
#[test]
fn probabilistic_table_one() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("p");
    let o = pipeline(&[
        "simulate",
        "probabilistic",
        "--scenarios",
        "6",
        "--bearing-noise",
        "0.01",
        "--motion-noise",
        "0.01",
        "--full-particles",
        "300",
        "--fast-particles",
        "100",
        "--baseline-samples",
        "200",
        "--noise-levels",
        "0.5,2",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // 002 Fig. 4 at two noise levels.
    let fig4: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("fig4.json")).unwrap()).unwrap();
    assert_eq!(fig4["levels"].as_array().unwrap().len(), 2);
    assert_eq!(fig4["levels"][1]["motion_noise_deg"], 4.0);
    assert!(out.join("fig4.png").is_file() && out.join("fig4.svg").is_file());
    let table: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("table1.json")).unwrap()).unwrap();
    let rows = table["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 3);
    for row in &rows[1..] {
        assert_eq!(row["dmse"][1].as_f64().unwrap(), 0.0, "{row}");
    }
    let outcomes: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("outcomes.json")).unwrap()).unwrap();
    assert_eq!(outcomes.as_array().unwrap().len(), 6);
    // Eq. (10): each of the 3 cameras is scored.
    assert_eq!(outcomes[0]["full"]["cameras"].as_array().unwrap().len(), 3);
    assert!(
        rows[1]["camera"]["dmse"][1].as_f64().unwrap() < 0.05,
        "{}",
        rows[1]
    );
}

/// `simulate single --mode probabilistic` writes 002's beliefs beside the map, keyed by the
/// map's landmark ids and normalized; the FDC is refused before any work.
#[test]
fn probabilistic_simulated_map() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("s");
    let o = pipeline(&[
        "simulate",
        "single",
        "--mode",
        "probabilistic",
        "--landmarks",
        "8",
        "--stations",
        "6",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(stdout(&o).contains("truth most likely"), "{}", stdout(&o));
    let beliefs: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("beliefs.json")).unwrap()).unwrap();
    assert_eq!(beliefs["format"], "qrm-beliefs");
    let triples = beliefs["triples"].as_array().unwrap();
    assert!(!triples.is_empty() && triples.len() <= 56);
    for t in triples {
        let p: Vec<f64> = serde_json::from_value(t["ab_c"].clone()).unwrap();
        assert_eq!(p.len(), 20);
        assert!((p.iter().sum::<f64>() - 1.0).abs() < 1e-9);
        assert!(t["a"].as_u64() < t["b"].as_u64() && t["b"].as_u64() < t["c"].as_u64());
    }
    let o = pipeline(&[
        "simulate",
        "single",
        "--mode",
        "probabilistic",
        "--calculus",
        "fdc",
        "--out",
        dir.path().join("f").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--calculus edc"));
    assert!(!dir.path().join("f").exists());
}
