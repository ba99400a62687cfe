"""qrm.run and qrm.synth against `pipeline run` and `pipeline synth` on the same inputs: the
same files, the same summary, the same errors; progress reported, the GIL released."""

import json
import shutil
import threading
import time

import pytest

import qrm

SAME_FILES = ["map.json", "rng.json", "landmarks.json"]


@pytest.fixture(scope="module")
def both_runs(demo, cli, tmp_path_factory):
    out = tmp_path_factory.mktemp("runs")
    cli("run", "--images", demo, "--out", out / "cli", "--quiet")
    calls = []
    summary = qrm.run(demo, out / "py", progress=lambda *a: calls.append(a))
    return out / "cli", out / "py", summary, calls


def test_run_writes_what_the_cli_writes(both_runs):
    cli_out, py_out, _, _ = both_runs
    for name in SAME_FILES:
        assert (py_out / name).read_text() == (cli_out / name).read_text(), name
    assert sorted(p.name for p in py_out.iterdir()) == sorted(p.name for p in cli_out.iterdir())


def test_run_returns_the_summary(both_runs):
    cli_out, py_out, summary, _ = both_runs
    written = json.loads((py_out / "summary.json").read_text())
    warnings = summary.pop("warnings")
    assert summary == written
    assert isinstance(warnings, list)
    theirs = json.loads((cli_out / "summary.json").read_text())
    for key in ("stations", "detections", "landmarks", "triples", "rng_certain", "contradictions"):
        assert summary[key] == theirs[key]


def test_progress_reports_both_stages(both_runs):
    _, _, summary, calls = both_runs
    stages = [c[0] for c in calls]
    assert stages[0] == "detect" and "map" in stages
    for stage in ("detect", "map"):
        counts = [(done, total) for s, done, total in calls if s == stage]
        assert counts[0][0] == 0 and counts[-1][0] == counts[-1][1]
        assert [d for d, _ in counts] == sorted(d for d, _ in counts)


def test_run_releases_the_gil(demo, tmp_path):
    ticks = []
    stop = threading.Event()

    def tick():
        while not stop.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.001)

    thread = threading.Thread(target=tick)
    thread.start()
    start = time.perf_counter()
    qrm.run(demo, tmp_path / "out", no_eval=True)
    elapsed = time.perf_counter() - start
    stop.set()
    thread.join()
    during = [t for t in ticks if start <= t <= start + elapsed]
    # A thread that kept the GIL would starve the ticker for the whole run.
    assert len(during) > 0.2 * elapsed / 0.001


def test_a_failing_progress_function_is_raised_after_the_run(demo, tmp_path):
    def broken(stage, done, total):
        raise RuntimeError("callback broke")

    with pytest.raises(RuntimeError, match="callback broke"):
        qrm.run(demo, tmp_path / "out", progress=broken, no_eval=True)
    # The run itself finished: its outputs are whole.
    assert (tmp_path / "out" / "summary.json").is_file()


def test_run_errors_carry_the_cli_message(demo, cli, tmp_path):
    cases = [
        (tmp_path / "missing", tmp_path / "o1", {}),
        (demo, demo, {}),
        (demo, tmp_path / "o2", {"calib": tmp_path / "no-calib.toml"}),
        (demo, tmp_path / "o3", {"truth": tmp_path / "no-truth.json"}),
    ]
    for images, out, options in cases:
        with pytest.raises(qrm.QrmError) as raised:
            qrm.run(images, out, **options)
        argv = ["run", "--images", images, "--out", out]
        for k, v in options.items():
            argv += ["--" + k, v]
        assert cli(*argv, check=False).stderr.strip() == f"error: {raised.value}"
        assert not (tmp_path / "o1").exists()


def test_corrupt_panorama_and_bad_calibration(demo, tmp_path):
    broken = tmp_path / "broken"
    shutil.copytree(demo, broken)
    (broken / "calib.toml").write_text("this is not a calibration")
    with pytest.raises(qrm.QrmError, match="calib"):
        qrm.run(broken, tmp_path / "out")
    assert not (tmp_path / "out").exists()


def test_unknown_options_are_rejected_before_any_work(demo, tmp_path):
    with pytest.raises(ValueError, match="--bogus"):
        qrm.run(demo, tmp_path / "out", bogus=3)
    with pytest.raises(ValueError, match="possible values"):
        qrm.run(demo, tmp_path / "out", channels="infrared")
    with pytest.raises(TypeError):
        qrm.run(demo, tmp_path / "out", progress=42)
    assert not (tmp_path / "out").exists()


def test_synth_renders_what_the_cli_renders(cli, tmp_path):
    options = [
        "--preset",
        "random",
        "--seed",
        "4",
        "--stations",
        "2",
        "--rocks",
        "8",
        "--scale",
        "0.25",
    ]
    cli("synth", *options, "--out", tmp_path / "cli")
    calls = []
    rendered = qrm.synth(
        tmp_path / "py",
        preset="random",
        seed=4,
        stations=2,
        rocks=8,
        scale=0.25,
        progress=lambda *a: calls.append(a),
    )
    assert rendered["stations"] == 2 and rendered["rocks"] == 8
    assert calls[-1] == ("render", 2, 2)
    cli_files = sorted(p.name for p in (tmp_path / "cli").iterdir())
    assert cli_files == sorted(p.name for p in (tmp_path / "py").iterdir())
    for name in cli_files:
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes()


def test_synth_errors(tmp_path):
    with pytest.raises(ValueError, match="possible values"):
        qrm.synth(tmp_path / "o", preset="moon")
    with pytest.raises(qrm.QrmError, match="--rocks"):
        qrm.synth(tmp_path / "o", rocks=0)


def test_options_take_negative_numbers_and_arrays():
    import numpy as np

    with pytest.raises(qrm.QrmError, match="--bearing-noise -0.5"):
        qrm.montecarlo_study(bearing_noise=-0.5)
    study = qrm.montecarlo_study(nearest=np.array([6, 9]))
    assert study["nearest"] == [6, 9]
    for reserved in ({"quiet": True}, {"help": True}, {"out": "x"}):
        with pytest.raises(TypeError):
            qrm.montecarlo_study(**reserved)
    with pytest.raises(ValueError):
        qrm.simulate(0, -1, maps=2)
