//! `directions`: a route with its instructions, custom map and pictures from a run, from a
//! converged simulated map (where the map proves the legs), and `simulate directions`.

use super::navigate::{demo_run, DEMO};
use super::pipeline;
use std::path::Path;

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// From the demo run with its panoramas: every output is written, the route chains its legs
/// from `--from` to `--to`, every leg has an instruction and a picture, the custom map is in
/// the grammar, and a route of legs the map does not prove says so (support < 1).
#[test]
fn directions_from_a_run_with_pictures() {
    let scratch = tempfile::tempdir().unwrap();
    let run = demo_run(scratch.path());
    let map = json(&run.join("map.json"));
    let ids: Vec<u64> = map["landmarks"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| l.as_u64().unwrap())
        .collect();
    let out = scratch.path().join("dir");
    let (from, to) = (ids[0].to_string(), ids[ids.len() - 1].to_string());
    let o = pipeline(&[
        "directions",
        "--run",
        run.to_str().unwrap(),
        "--images",
        DEMO,
        "--from",
        &from,
        "--to",
        &to,
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains("Instructions:") && text.contains("Custom map"),
        "{text}"
    );
    let d = json(&out.join("directions.json"));
    assert_eq!(d["format"], "qrm-directions");
    let legs = d["legs"].as_array().unwrap();
    assert!(!legs.is_empty());
    assert_eq!(legs[0]["from"].to_string(), from);
    assert_eq!(legs[legs.len() - 1]["to"].to_string(), to);
    for pair in legs.windows(2) {
        assert_eq!(pair[0]["to"], pair[1]["from"]);
    }
    for (k, leg) in legs.iter().enumerate() {
        assert!(leg["instruction"].as_str().unwrap().starts_with("At L"));
        assert!(out.join(format!("leg_{}.png", k + 1)).is_file());
        let support = leg["support"].as_f64().unwrap();
        assert!(support > 0.0 && support <= 1.0);
        assert_eq!(
            leg["proven"].as_bool().unwrap(),
            support == 1.0 && leg["proven"] == true
        );
    }
    assert!(out.join("legs.png").is_file());
    let custom = d["custom_map"].as_str().unwrap();
    assert_eq!(custom.matches("cell").count(), legs.len() - 1, "{custom}");
    let u: f64 = legs
        .iter()
        .map(|l| l["unreliability"].as_f64().unwrap())
        .sum();
    assert!((u - d["route"]["unreliability"].as_f64().unwrap()).abs() < 1e-9);
}

/// On a converged map every leg of the route is proven, and the compromise is never worse in
/// D/R than the other two criteria.
#[test]
fn directions_on_a_converged_map_use_proven_legs() {
    let scratch = tempfile::tempdir().unwrap();
    let sim = scratch.path().join("sim");
    let o = pipeline(&[
        "simulate",
        "single",
        "--landmarks",
        "12",
        "--stations",
        "60",
        "--out",
        sim.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let map = sim.join("map.json");
    let mut routes = 0;
    for to in 1..12 {
        let o = pipeline(&[
            "directions",
            "--map",
            map.to_str().unwrap(),
            "--from",
            "0",
            "--to",
            &to.to_string(),
            "--samples",
            "0",
            "--json",
        ]);
        if !o.status.success() {
            assert!(String::from_utf8_lossy(&o.stderr).contains("no route"));
            continue;
        }
        routes += 1;
        let d: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        assert!(d["legs"]
            .as_array()
            .unwrap()
            .iter()
            .all(|l| l["proven"] == true));
        let cost = |name: &str| d["routes"][name]["d_over_r"].as_f64().unwrap();
        assert!(cost("compromise") <= cost("shortest") + 1e-9);
        assert!(cost("compromise") <= cost("reliable") + 1e-9);
    }
    assert!(routes >= 3, "only {routes} goals reachable on proven legs");
}

/// The study writes its fit and calibration, and the fit's constants are printed.
#[test]
fn the_reliability_study_writes_its_figure() {
    let scratch = tempfile::tempdir().unwrap();
    let out = scratch.path().join("study");
    let o = pipeline(&[
        "simulate",
        "directions",
        "--trials",
        "300",
        "--routes",
        "60",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let r = json(&out.join("reliability.json"));
    assert_eq!(r["rates"].as_array().unwrap().len(), 28);
    assert_eq!(r["calibration"]["routes"], 60);
    assert!(out.join("reliability.png").is_file());
}

/// `navigate directions`: routes planned on the demo run's map, followed through panoramas
/// rendered in its world; the same seed gives the same trials, every leg is judged, and a run
/// without eval.json (which rock each landmark is) is refused.
#[test]
fn directions_followed_through_rendered_panoramas() {
    let scratch = tempfile::tempdir().unwrap();
    let run = demo_run(scratch.path());
    let trial = |out: &str| {
        let out = scratch.path().join(out);
        let o = pipeline(&[
            "navigate",
            "directions",
            "--images",
            DEMO,
            "--run",
            run.to_str().unwrap(),
            "--routes",
            "3",
            "--samples",
            "4",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        assert!(out.join("summary.json").is_file());
        json(&out.join("trials.json"))
    };
    let first = trial("a");
    let routes = first.as_array().unwrap();
    assert_eq!(routes.len(), 3);
    for route in routes {
        let legs = route["legs"].as_array().unwrap();
        assert_eq!(legs.len() + 1, route["landmarks"].as_array().unwrap().len());
        let all = legs.iter().all(|l| l["correct_identified"] == true);
        assert_eq!(route["succeeded_identified"], all);
        for leg in legs {
            let p = leg["predicted"].as_f64().unwrap();
            assert!(p > 0.0 && p <= 1.0);
        }
    }
    assert_eq!(trial("b"), first, "the same seed gave other trials");
    std::fs::remove_file(run.join("eval.json")).unwrap();
    let o = pipeline(&[
        "navigate",
        "directions",
        "--images",
        DEMO,
        "--run",
        run.to_str().unwrap(),
        "--out",
        scratch.path().join("c").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("eval.json"));
}
