"""Map from Python: JSON in and out, relations as arrays, fusion, merge, close and check, the
RNG — each against the command line on the same files."""

import json
import os
from pathlib import Path

import numpy as np
import pytest

import qrm


@pytest.fixture(scope="module")
def simulated(tmp_path_factory, cli):
    """Two simulated 12-landmark maps of the same world seen from different stations."""
    out = tmp_path_factory.mktemp("sim")
    cli("simulate", "single", "--landmarks", 12, "--stations", 6, "--seed", 5, "--out", out / "a")
    cli("simulate", "single", "--landmarks", 12, "--stations", 9, "--seed", 5, "--out", out / "b")
    return out


def test_json_round_trip_is_exact(simulated):
    text = (simulated / "a" / "map.json").read_text()
    m = qrm.Map.from_json(text)
    assert m.to_json() == text
    assert qrm.Map.load(simulated / "a" / "map.json").to_json() == text
    assert len(m) == 12 and m.calculus == "EDC"
    assert m.landmarks.dtype == np.uint32


def test_save_writes_the_same_text(simulated, tmp_path):
    m = qrm.Map.load(simulated / "a" / "map.json")
    m.save(tmp_path / "copy.json")
    assert (tmp_path / "copy.json").read_text() == m.to_json()
    assert [p.name for p in tmp_path.iterdir()] == ["copy.json"]


def test_relation_arrays_agree_with_relation(simulated):
    m = qrm.Map.load(simulated / "a" / "map.json")
    ids, masks = m.relations()
    assert ids.shape == masks.shape == (m.stats()["triples"], 3)
    for (a, b, c), (x, y, z) in zip(ids[:50], masks[:50]):
        for (p, q, r), mask in (((a, b, c), x), ((b, c, a), y), ((c, a, b), z)):
            members = {k + 1 for k in range(32) if mask >> k & 1}
            assert m.relation(int(p), int(q), int(r)) == members
    assert m.relation(0, 1, 99) is None


def test_rng_matches_cli(simulated, cli, tmp_path):
    m = qrm.Map.load(simulated / "b" / "map.json")
    cli("map", "info", simulated / "b" / "map.json", "--rng", tmp_path / "rng.json")
    assert m.rng() == json.loads((tmp_path / "rng.json").read_text())


def test_merge_matches_cli(simulated, cli, tmp_path):
    a = qrm.Map.load(simulated / "a" / "map.json")
    b = qrm.Map.load(simulated / "b" / "map.json")
    merged = a.copy()
    merged.merge(b)
    cli(
        "map",
        "merge",
        simulated / "a" / "map.json",
        simulated / "b" / "map.json",
        "--out",
        tmp_path / "merged.json",
    )
    assert merged.to_json() == (tmp_path / "merged.json").read_text()
    assert a.to_json() == (simulated / "a" / "map.json").read_text(), "copy() is independent"


NETWORK = "0 1 2 {1}\n0 1 3 {5,6}\n1 2 3 3,4,9\n"


def test_close_and_check_match_cli(cli, tmp_path):
    (tmp_path / "net.txt").write_text(NETWORK)
    closed = qrm.Map.close(NETWORK)
    cli("map", "close", tmp_path / "net.txt", "--out", tmp_path / "closed.json")
    assert closed.to_json() == (tmp_path / "closed.json").read_text()
    assert qrm.Map.close(Path(tmp_path / "net.txt")).to_json() == closed.to_json()
    verdict = qrm.Map.check(NETWORK)
    assert verdict["consistent"] and verdict["conflict"] == ""
    out = cli("map", "check", tmp_path / "net.txt").stdout
    assert f"closing tightens {verdict['tightened']} of them" in out


def test_inconsistent_network_names_its_conflict(cli, tmp_path):
    bad = NETWORK + "0 1 2 {2}\n"
    with pytest.raises(qrm.ContradictionError) as raised:
        qrm.Map.close(bad)
    verdict = qrm.Map.check(bad)
    assert not verdict["consistent"]
    (tmp_path / "bad.txt").write_text(bad)
    checked = cli("map", "check", tmp_path / "bad.txt", check=False)
    assert checked.returncode == 1
    conflict = checked.stdout.split("conflicting constraints:\n")[1].splitlines()
    assert "0 1 2 {2}" in " ".join(conflict)
    for line in conflict:
        assert line in str(raised.value) and line in verdict["conflict"]


def test_fuse_view_then_contradiction_leaves_map_unchanged():
    m = qrm.Map()
    report = m.fuse_view([10, 11, 12, 13], [0, 40, 100, 200], [(0, 1), (1, 2), (2, 3)], 0.5)
    assert report["new_landmarks"] == 4
    before = m.to_json()
    truth = m.relation(10, 11, 12)
    impossible = sorted(set(range(1, 21)) - set(truth))
    with pytest.raises(qrm.ContradictionError):
        m.fuse([(10, 11, 12, impossible)])
    assert m.to_json() == before


def test_fuse_agrees_with_measure():
    view = qrm.measure([0, 40, 100], "A<B<C", 0.5)
    m = qrm.Map()
    m.fuse([(1, 2, 3, view["AB:C"]), (2, 3, 1, view["BC:A"]), (3, 1, 2, view["CA:B"])])
    n = qrm.Map()
    n.fuse_view([1, 2, 3], [0, 40, 100], [(0, 1), (1, 2)], 0.5)
    assert m.to_json() == n.to_json()


@pytest.mark.parametrize(
    "call,error",
    [
        (lambda m: m.fuse([(1, 2, 3, [0])]), ValueError),
        (lambda m: m.fuse([(1, 2, 3, [21])]), ValueError),
        (lambda m: m.fuse([(1, 2, 3, ["x"])]), TypeError),
        (lambda m: m.fuse([(1, 1, 3, [1])]), qrm.ContradictionError),
        (lambda m: m.fuse_view([1, 2, 3], [0, 1], []), ValueError),
        (lambda m: m.fuse_view([1, 2, 3], [0, 1, float("nan")], []), ValueError),
        (lambda m: m.fuse_view([1, 2, 3], [0, 1, 2], [(0, 5)]), ValueError),
        (lambda m: m.fuse_view([1, 2, 3], [0, 1, 2], [], uncertainty=-1), ValueError),
        (lambda m: m.merge(qrm.Map("fdc")), ValueError),
        (lambda m: m.merge("map"), TypeError),
        (lambda m: qrm.Map.from_json("{}"), qrm.QrmError),
        (lambda m: qrm.Map.from_json("not json"), qrm.QrmError),
        (lambda m: qrm.Map.load("/no/such/map.json"), qrm.QrmError),
        (lambda m: qrm.Map("fdc").rng(), qrm.QrmError),
    ],
)
def test_bad_input_raises(call, error):
    with pytest.raises(error) as raised:
        call(qrm.Map())
    assert str(raised.value)


def test_realize_matches_cli(simulated, cli, tmp_path):
    m = qrm.Map.load(simulated / "a" / "map.json")
    mine = m.realize(seed=2)
    cli(
        "map",
        "realize",
        simulated / "a" / "map.json",
        "--seed",
        2,
        "--out",
        tmp_path / "r.json",
        check=False,
    )
    theirs = json.loads((tmp_path / "r.json").read_text())
    assert mine["exact"] == theirs["exact"] and mine["violated"] == theirs["violated"]
    assert list(mine["landmarks"]) == [p["landmark"] for p in theirs["landmarks"]]
    assert np.allclose(mine["x"], [p["x"] for p in theirs["landmarks"]])
    assert np.allclose(mine["y"], [p["y"] for p in theirs["landmarks"]])


def test_close_and_check_take_a_maps_own_calculus():
    m = qrm.Map("fdc")
    m.fuse([(1, 2, 3, [1, 2, 3]), (1, 2, 4, [4, 5])])
    assert qrm.Map.close(m).calculus == "FDC"
    assert qrm.Map.check(m)["consistent"]


def test_merging_a_map_with_itself_changes_nothing(simulated):
    m = qrm.Map.load(simulated / "a" / "map.json")
    before = m.to_json()
    assert m.merge(m)["relations_tightened"] == 0
    assert m.to_json() == before


def test_saved_maps_get_the_usual_file_mode(tmp_path):
    qrm.Map().save(tmp_path / "m.json")
    umask = os.umask(0)
    os.umask(umask)
    assert (tmp_path / "m.json").stat().st_mode & 0o777 == 0o666 & ~umask


@pytest.mark.parametrize(
    "call,error",
    [
        (lambda m: m.fuse([(-1, 2, 3, [1])]), ValueError),
        (lambda m: m.fuse([(2**32, 2, 3, [1])]), ValueError),
        (lambda m: m.fuse([(1.7, 2, 3, [1])]), TypeError),
        (lambda m: m.fuse([(1, 2, 3, [300])]), ValueError),
        (lambda m: m.fuse([(1, 2, 3)]), ValueError),
        (lambda m: m.relation(-1, 2, 3), ValueError),
        (lambda m: m.fuse_view([1, 1, 2], [0, 1, 2]), ValueError),
        (lambda m: m.fuse_view([1, 2, 3], [0, 1, 2], [(0, -1)]), ValueError),
        (lambda m: m.fuse_view([1, 2, 3], [0, 1, 2], uncertainty=float("nan")), ValueError),
        (lambda m: m.realize(seed=-1), ValueError),
    ],
)
def test_ids_and_numbers_are_checked_before_rust(call, error):
    with pytest.raises(error) as raised:
        call(qrm.Map())
    assert "OverflowError" not in type(raised.value).__name__ and str(raised.value)
