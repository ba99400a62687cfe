"""The calculus from Python against the command line on the same inputs, and the 000 §III-C
worked example."""

import numpy as np
import pytest

import qrm


def cli_set(text: str) -> frozenset:
    text = text.strip().strip("{}")
    return frozenset(int(x) for x in text.split(",") if x)


def test_worked_example_of_000():
    # 000 §III-C: BC:D = COMPOSE(LEFT({6,7}), INVERSE({16})) = {1,5,11,12,17,18,19,20}
    left = qrm.unary("left", {6, 7})
    inverse = qrm.unary("inverse", 16)
    assert qrm.compose(left, inverse) == {1, 5, 11, 12, 17, 18, 19, 20}


@pytest.mark.parametrize("calculus", ["edc", "fdc"])
def test_classify_matches_cli_on_random_points(cli, calculus):
    rng = np.random.default_rng(7)
    points = rng.uniform(-5, 5, size=(25, 3, 2))
    for a, b, c in points:
        mine = qrm.classify(a, b, c, calculus=calculus)
        args = [",".join(f"{v:.17g}" for v in p) for p in (a, b, c)]
        out = cli("classify", "--calculus", calculus, *args).stdout.strip()
        assert str(mine) == out or (mine is None and out == "boundary")


@pytest.mark.parametrize(
    "ab_c,bc_d", [("1,5,11", "5"), ("7,13", "14"), ("1,2,3,4,5,6,7,8,9,10", "12,13")]
)
def test_compose_matches_cli(cli, ab_c, bc_d):
    assert qrm.compose(ab_c, bc_d) == cli_set(cli("compose", ab_c, bc_d).stdout)


def test_measure_matches_cli(cli):
    rng = np.random.default_rng(3)
    for _ in range(10):
        bearings = rng.uniform(0, 360, 3)
        order = "A<B<C" if rng.random() < 0.5 else "B<A,C<A"
        mine = qrm.measure(bearings, order, uncertainty=0.5)
        out = cli(
            "measure", *[f"{b:.17g}" for b in bearings], "--order", order, "--uncertainty", 0.5
        ).stdout
        theirs = dict(line.split(" = ") for line in out.strip().splitlines())
        assert {k: cli_set(v) for k, v in theirs.items()} == mine


def test_measure_with_ranges_matches_cli_and_narrows(cli):
    bearings, order = [0.0, 40.0, 100.0], "A<B<C"
    mine = qrm.measure(bearings, order, ranges=[(4, 5), (8, 10), None])
    out = cli("measure", *bearings, "--order", order, "--ranges", "4:5,8:10,-").stdout
    theirs = dict(line.split(" = ") for line in out.strip().splitlines())
    assert {k: cli_set(v) for k, v in theirs.items()} == mine
    loose = qrm.measure(bearings, order)
    assert all(mine[k] <= loose[k] for k in loose) and mine != loose


def test_measure_takes_pairs_and_arrays():
    a = qrm.measure(np.array([0.0, 40.0, 100.0]), "A<B<C")
    b = qrm.measure([0, 40, 100], [(0, 1), (1, 2)])
    assert a == b
    assert all(s for s in a.values())


@pytest.mark.parametrize(
    "call,error",
    [
        (lambda: qrm.measure(["a", "b", "c"]), TypeError),
        (lambda: qrm.measure([0.0, float("nan"), 1.0]), ValueError),
        (lambda: qrm.measure([0.0, 1.0]), ValueError),
        (lambda: qrm.measure([0, 1, 2], "A<D"), qrm.QrmError),
        (lambda: qrm.measure([0, 1, 2], "A<B,B<A"), qrm.QrmError),
        (lambda: qrm.measure([0, 1, 2], uncertainty=90), qrm.QrmError),
        (lambda: qrm.measure([0, 1, 2], ranges=[(1, 2)]), ValueError),
        (lambda: qrm.measure([0, 1, 2], ranges=[(2, 1), None, None]), qrm.QrmError),
        (lambda: qrm.classify((0, 0), (0, 0), (1, 1)), qrm.QrmError),
        (lambda: qrm.classify((0, 0), (0, float("inf")), (1, 1)), ValueError),
        (lambda: qrm.classify((0, 0, 0), (0, 1), (1, 1)), ValueError),
        (lambda: qrm.compose("1,21", "5"), qrm.QrmError),
        (lambda: qrm.compose([1, "x"], [5]), TypeError),
        (lambda: qrm.unary("sideways", [1]), ValueError),
        (lambda: qrm.compose([1], [2], calculus="rcc8"), ValueError),
    ],
)
def test_bad_input_raises_clear_errors(call, error):
    with pytest.raises(error) as raised:
        call()
    assert str(raised.value)


def test_errors_carry_the_cli_message(cli):
    with pytest.raises(qrm.QrmError) as raised:
        qrm.compose("1,21", "5")
    cli_error = cli("compose", "1,21", "5", check=False).stderr.strip()
    assert cli_error == f"error: {raised.value}"


def test_measure_checks_the_uncertainty_in_degrees():
    with pytest.raises(ValueError, match="degrees"):
        qrm.measure([0, 40, 100], uncertainty=float("nan"))
    with pytest.raises(ValueError, match="degrees"):
        qrm.measure([0, 40, 100], uncertainty=-1)
