"""qrm.batch on a 2-worker LocalCluster: a sweep equals the in-process sweep exactly and the
command line's montecarlo.csv; a batch of traverses reports failures per traverse and
resumes."""

import shutil

import numpy as np
import pandas as pd
import pytest

import qrm
from qrm import batch

distributed = pytest.importorskip("distributed")

STUDY = dict(maps=5, stations=6, nearest=[6, 9], seed=3)


@pytest.fixture(scope="module")
def client():
    cluster = distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    )
    with distributed.Client(cluster) as c:
        yield c
    cluster.close()


def deterministic(frame: pd.DataFrame) -> pd.DataFrame:
    return frame.drop(columns=["seconds"])


def test_sweep_on_the_cluster_equals_the_sweep_in_process(client):
    local = batch.sweep(chunk=3, **STUDY)
    chunks = []
    remote = batch.sweep(
        client=client, chunk=3, on_chunk=lambda d, t: chunks.append((d, t)), **STUDY
    )
    assert len(local) == 2 * 5 * 6
    pd.testing.assert_frame_equal(deterministic(local), deterministic(remote), check_exact=True)
    assert chunks[-1] == (4, 4)
    assert local.attrs["study"]["nearest"] == [6, 9]


def test_sweep_rows_are_the_runs_of_simulate():
    frame = batch.sweep(chunk=100, **STUDY)
    one = qrm.simulate(2, 9, maps=5, stations=6, seed=3)
    rows = frame[(frame["nearest"] == 9) & (frame["map"] == 2)]
    for name in qrm.STEP_METRICS:
        if name != "seconds":
            assert np.array_equal(rows[name].to_numpy(), one[name], equal_nan=True), name


def test_aggregate_reproduces_the_cli_csv(cli, tmp_path):
    cli(
        "simulate",
        "montecarlo",
        "--maps",
        5,
        "--stations",
        6,
        "--nearest",
        "6,9",
        "--seed",
        3,
        "--out",
        tmp_path,
    )
    theirs = pd.read_csv(tmp_path / "montecarlo.csv", dtype={"n": str})
    mine = batch.aggregate(batch.sweep(**STUDY))
    assert list(mine.columns) == list(theirs.columns)
    assert list(mine["n"]) == list(theirs["n"]) and list(mine["image"]) == list(theirs["image"])
    for column in theirs.columns[2:]:
        if not column.startswith("seconds"):
            assert np.allclose(mine[column], theirs[column], atol=2e-6), column


def test_sweep_rejects_bad_studies():
    with pytest.raises(ValueError):
        batch.sweep(chunk=0, **STUDY)
    with pytest.raises(qrm.QrmError, match="--maps"):
        batch.sweep(maps=0)
    with pytest.raises(ValueError, match="--bogus"):
        batch.sweep(bogus=1)


def test_traverses_fail_alone_and_resume(client, demo, tmp_path):
    broken = tmp_path / "broken"
    shutil.copytree(demo, broken)
    (broken / "calib.toml").write_text("not a calibration")
    traverses = [demo, tmp_path / "missing", broken]
    seen = []
    first = batch.run_traverses(
        traverses, tmp_path / "out", client=client, no_eval=True, on_result=seen.append
    )
    assert list(first["status"]) == ["ok", "failed", "failed"]
    assert "does not exist" in first.loc[1, "error"]
    assert "calib" in first.loc[2, "error"]
    assert first.loc[0, "landmarks"] > 0 and len(seen) == 3
    assert (tmp_path / "out" / "demo" / "map.json").is_file()

    again = batch.run_traverses(traverses, tmp_path / "out", client=client, no_eval=True)
    assert list(again["status"]) == ["skipped", "failed", "failed"]
    assert again.loc[0, "landmarks"] == first.loc[0, "landmarks"]


def test_traverses_in_process_match_the_cluster(client, demo, tmp_path):
    local = batch.run_traverses([demo], tmp_path / "local", no_eval=True)
    remote = batch.run_traverses([demo], tmp_path / "remote", client=client, no_eval=True)
    assert (tmp_path / "local" / "demo" / "map.json").read_text() == (
        tmp_path / "remote" / "demo" / "map.json"
    ).read_text()
    keep = [c for c in local.columns if c not in ("out", "seconds")]
    pd.testing.assert_frame_equal(local[keep], remote[keep])


def test_traverse_globs_and_names(tmp_path, demo):
    with pytest.raises(FileNotFoundError):
        batch.run_traverses(str(tmp_path / "nothing-*"), tmp_path / "out")
    with pytest.raises(ValueError):
        batch.run_traverses([], tmp_path / "out")
    names = batch._output_names(
        [tmp_path / "a" / "sol", tmp_path / "b" / "sol", tmp_path / "sol-1"]
    )
    assert len(set(names)) == 3 and names[2] == "sol-1"
    assert all(n.startswith("sol-") for n in names)
    swapped = batch._output_names([tmp_path / "b" / "sol", tmp_path / "a" / "sol"])
    assert swapped == [names[1], names[0]], "names do not depend on the order"
