"""qrm: qualitative relational mapping from rover panoramas (McClelland, Campbell, Estlin).

The Extended Double Cross calculus, qualitative maps, whole pipeline runs over directories of
panoramas, synthetic datasets and Monte Carlo mapping studies, from Python. Everything is the
Rust implementation behind the ``pipeline`` command line: the same files, the same checks and
the same error messages. Long work releases the GIL. Batches of traverses and sweeps on a Dask
cluster are in :mod:`qrm.batch`. Documentation: docs/PYTHON.md.

Relations are numbered as in the papers: EDC regions 1..20 (000 Fig. 3b), FDC relations 1..15.
A relation set is given as any iterable of numbers, a single number, or text such as
``"1,5,11"``; it is returned as a ``frozenset``.
"""

from __future__ import annotations

import json
import os
import sys
import tempfile
from pathlib import Path
from typing import Any, Callable, Iterable, Optional, Sequence, Tuple, Union

import numpy as np

from . import _qrm
from ._qrm import RELATION_NAMES, ContradictionError, QrmError, __version__

__all__ = [
    "ContradictionError",
    "Map",
    "QrmError",
    "__version__",
    "classify",
    "compose",
    "measure",
    "montecarlo_study",
    "run",
    "simulate",
    "synth",
    "unary",
]

Relations = Union[int, str, Iterable[int]]
Progress = Union[None, bool, Callable[[str, int, int], Any]]
PathLike = Union[str, "os.PathLike[str]"]


def _members(relations: Relations) -> list:
    """The relation numbers of a set given as numbers or as text (``"{1,5,11}"``)."""
    if isinstance(relations, str):
        try:
            return [int(x) for x in relations.strip().strip("{}").split(",") if x.strip()]
        except ValueError:
            raise ValueError(f"relation set {relations!r} must list numbers, e.g. 1,5,11") from None
    if isinstance(relations, (int, np.integer)) and not isinstance(relations, bool):
        return [int(relations)]
    members = []
    for r in relations:
        if isinstance(r, bool) or not isinstance(r, (int, np.integer)):
            raise TypeError(f"relation {r!r} is not an integer relation number")
        if not 1 <= r <= 32:
            raise ValueError(f"relation {r} is outside 1..=20 (EDC) and 1..=15 (FDC)")
        members.append(int(r))
    return members


def _id(x: Any, what: str = "landmark id") -> int:
    """A landmark id: an integer in 0..2³²."""
    if isinstance(x, bool) or not isinstance(x, (int, np.integer)):
        raise TypeError(f"{what} {x!r} must be an integer")
    if not 0 <= x < 2**32:
        raise ValueError(f"{what} {x} must lie in 0..2^32")
    return int(x)


def _degrees(value: Any, name: str) -> float:
    """A non-negative finite angle in degrees."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise TypeError(f"{name} must be a number of degrees, got {value!r}")
    if not (np.isfinite(value) and value >= 0):
        raise ValueError(f"{name} must be a finite, non-negative number of degrees, got {value}")
    return float(value)


def _count(value: Any, name: str) -> Optional[int]:
    """A non-negative integer, or None."""
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 0:
        raise ValueError(f"{name} must be a non-negative integer, got {value!r}")
    return int(value)


def _relations_text(relations: Relations) -> str:
    """A relation set as the command line writes it (``{1,5,11}``); text is passed on as it is,
    for the command line's own parser and messages."""
    if isinstance(relations, str):
        return relations
    return "{" + ",".join(str(r) for r in sorted(set(_members(relations)))) + "}"


def _point(p: Any, name: str) -> Tuple[float, float]:
    a = _numbers(p, name)
    if a.shape != (2,):
        raise ValueError(f"point {name} must have two coordinates, got shape {a.shape}")
    return float(a[0]), float(a[1])


def _numbers(values: Any, name: str) -> np.ndarray:
    """`values` as a float64 array; a clear error for anything that is not numbers."""
    a = np.asarray(values)
    if a.dtype.kind not in "iuf":
        raise TypeError(f"{name} must be numbers, got an array of dtype {a.dtype}")
    a = a.astype(np.float64)
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must be finite numbers, got {a.tolist()}")
    return a


def classify(a: Any, b: Any, c: Any, calculus: str = "edc") -> Optional[int]:
    """The relation of point ``c`` to the directed pair ``a``→``b`` (000 §III); ``None`` when
    ``c`` lies on a boundary.

    >>> classify((0, 0), (0, 1), (-2, 3))
    """
    return _qrm.classify(calculus, _point(a, "a"), _point(b, "b"), _point(c, "c"))


def compose(ab_c: Relations, bc_d: Relations, calculus: str = "edc") -> frozenset:
    """COMPOSE(AB:C, BC:D) → AB:D from the committed composition table (000 §III-C)."""
    return frozenset(_qrm.compose(calculus, _relations_text(ab_c), _relations_text(bc_d)))


def unary(operator: str, relations: Relations, calculus: str = "edc") -> frozenset:
    """LEFT (AB:C → BC:A), RIGHT (AB:C → CA:B) or INVERSE (AB:C → BA:C) of a set."""
    return frozenset(_qrm.unary(calculus, operator, _relations_text(relations)))


def _order_text(order: Union[str, Sequence[Tuple[Any, Any]]]) -> str:
    """A range order of A, B, C as the command line writes it (``A<B,B<C``)."""
    if isinstance(order, str):
        return order
    names = "ABC"
    pairs = []
    for pair in order:
        if len(pair) != 2:
            raise ValueError(f"range-order pair {pair!r} must be (nearer, farther)")
        named = []
        for x in pair:
            if isinstance(x, str):
                named.append(x)
            elif isinstance(x, (int, np.integer)) and 0 <= int(x) < 3:
                named.append(names[int(x)])
            else:
                raise ValueError(f"range-order entry {x!r} must be 0, 1, 2 or 'A', 'B', 'C'")
        pairs.append("<".join(named))
    return ",".join(pairs)


def measure(
    bearings: Any,
    order: Union[str, Sequence[Tuple[Any, Any]]] = "",
    uncertainty: float = 0.0,
    calculus: str = "edc",
    ranges: Optional[Sequence[Optional[Tuple[float, float]]]] = None,
) -> dict:
    """The relations of landmarks A, B, C seen at ``bearings`` (three angles in degrees,
    counter-clockwise, any zero, each true within ± ``uncertainty``) with the range ``order``
    (``"A<B<C"``, ``"A<B,A<C"``, pairs such as ``[(0, 1), (1, 2)]`` nearer first, or empty for
    no order) and, optionally, each landmark's range within ``ranges[i] = (low, high)`` (any
    unit, ``None`` for unknown; the ratios of ranges are then bounded too), as 000 §IV measures
    them: ``{"AB:C": frozenset, "BC:A": …, …}``."""
    b = _numbers(bearings, "bearings")
    if b.shape != (3,):
        raise ValueError(f"bearings must hold three angles, got shape {b.shape}")
    sets = _qrm.measure(
        calculus,
        b.tolist(),
        _order_text(order),
        _degrees(uncertainty, "uncertainty"),
        _ranges_text(ranges),
    )
    return {name: frozenset(s) for name, s in zip(RELATION_NAMES, sets)}


def _ranges_text(ranges: Optional[Sequence[Optional[Tuple[float, float]]]]) -> str:
    """Range intervals as ``pipeline measure --ranges`` takes them (``4:5,8:10,-``)."""
    if ranges is None:
        return ""
    if isinstance(ranges, str) or len(ranges) != 3:
        raise ValueError("ranges must hold three (low, high) intervals or None, one per landmark")
    items = []
    for r in ranges:
        if r is None:
            items.append("-")
            continue
        low, high = (float(v) for v in r)
        items.append(f"{low!r}:{high!r}")
    return ",".join(items)


def _write_atomic(path: PathLike, text: str) -> None:
    """Writes ``text`` to ``path`` whole or not at all (a temporary file renamed)."""
    path = Path(path)
    fd, temporary = tempfile.mkstemp(prefix=f".{path.name}.", dir=path.parent)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
        # mkstemp's file is private (0600); give it the mode a plain open() would.
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(temporary, 0o666 & ~umask)
        os.replace(temporary, path)
    except BaseException:
        if os.path.exists(temporary):
            os.unlink(temporary)
        raise


class Map:
    """A qualitative map (000 §VI): for every triple of landmarks, the relations still
    possible, kept path consistent. Maps read and write the JSON of docs/MAP_FORMAT.md, the
    same text as ``pipeline run``'s map.json."""

    def __init__(self, calculus: str = "edc") -> None:
        self._inner = _qrm.Map(calculus)

    @classmethod
    def _wrap(cls, inner: Any) -> "Map":
        m = cls.__new__(cls)
        m._inner = inner
        return m

    @classmethod
    def from_json(cls, text: str) -> "Map":
        """A map from its JSON text."""
        return cls._wrap(_qrm.Map.from_json(text))

    @classmethod
    def load(cls, path: PathLike) -> "Map":
        """A map from a JSON file (for example a run's map.json)."""
        try:
            text = Path(path).read_text(encoding="utf-8")
        except OSError as e:
            raise QrmError(f"cannot read {os.fspath(path)}: {e.strerror}") from e
        try:
            return cls.from_json(text)
        except QrmError as e:
            raise QrmError(f"invalid map {os.fspath(path)}: {e}") from None

    def to_json(self) -> str:
        return self._inner.to_json()

    def save(self, path: PathLike) -> None:
        """Writes the map as JSON, whole or not at all."""
        _write_atomic(path, self.to_json())

    @property
    def calculus(self) -> str:
        """``"EDC"`` or ``"FDC"``."""
        return self._inner.calculus

    @property
    def landmarks(self) -> np.ndarray:
        """Landmark ids in insertion order (uint32)."""
        return np.asarray(self._inner.landmarks(), dtype=np.uint32)

    def __len__(self) -> int:
        return len(self._inner)

    def __repr__(self) -> str:
        s = self.stats()
        return f"<qrm.Map {self.calculus}: {s['landmarks']} landmarks, {s['triples']} triples>"

    def stats(self) -> dict:
        """Landmarks, triples, open states, fully constrained triples, states per relation."""
        return self._inner.stats()

    def relation(self, a: int, b: int, c: int) -> Optional[frozenset]:
        """The possible relations AB:C; ``None`` if a landmark is not in the map."""
        r = self._inner.relation(_id(a), _id(b), _id(c))
        return None if r is None else frozenset(r)

    def relations(self) -> Tuple[np.ndarray, np.ndarray]:
        """Every triple as two ``(T, 3)`` uint32 arrays: landmark ids ``(a, b, c)`` and the
        bitsets of AB:C, BC:A, CA:B (bit ``r - 1`` set when relation ``r`` is possible)."""
        ids, masks = self._inner.relation_buffers()
        shape = (-1, 3)
        return (
            np.frombuffer(ids, dtype="<u4").reshape(shape).astype(np.uint32),
            np.frombuffer(masks, dtype="<u4").reshape(shape).astype(np.uint32),
        )

    def fuse(self, observations: Iterable[Tuple[int, int, int, Relations]]) -> dict:
        """Fuses measurements ``(a, b, c, relations)`` — "AB:C is one of relations" — as one
        update (000 §VI-B). New landmarks are added. A contradiction raises
        :class:`ContradictionError` and leaves the map exactly as it was."""
        batch = []
        for o in observations:
            if len(o) != 4:
                raise ValueError(f"observation {o!r} must be (a, b, c, relations)")
            a, b, c, relations = o
            batch.append((_id(a), _id(b), _id(c), _members(relations)))
        return self._inner.fuse(batch)

    def fuse_view(
        self,
        landmarks: Sequence[int],
        bearings: Any,
        order: Sequence[Tuple[int, int]] = (),
        uncertainty: float = 0.0,
    ) -> dict:
        """Fuses one panorama: ``landmarks[i]`` seen at ``bearings[i]`` degrees (each true
        within ± ``uncertainty``), with the range order as pairs ``(i, j)``, "i is nearer than
        j" (000 §IV, §VI-B)."""
        b = _numbers(bearings, "bearings")
        if b.ndim != 1:
            raise ValueError(f"bearings must be one angle per landmark, got shape {b.shape}")
        ids = [_id(x) for x in landmarks]
        if len(set(ids)) != len(ids):
            raise ValueError(f"landmarks {ids} name a landmark twice")
        pairs = []
        for pair in order:
            if len(pair) != 2:
                raise ValueError(f"range-order pair {pair!r} must be (nearer, farther)")
            pairs.append(tuple(_id(i, "range-order position") for i in pair))
        return self._inner.fuse_view(ids, b.tolist(), pairs, _degrees(uncertainty, "uncertainty"))

    def merge(self, other: "Map") -> dict:
        """Fuses another map of the same calculus (landmarks matched by id)."""
        if not isinstance(other, Map):
            raise TypeError(f"can only merge a qrm.Map, not {type(other).__name__}")
        # A map is borrowed mutably while it merges: merging it with itself takes a copy.
        source = other._inner.copy() if other is self else other._inner
        return self._inner.merge(source)

    def rng(self) -> dict:
        """The RNG estimate (000 §VII-A, Algorithm 2), as rng.json: edges with cost w (0 =
        certain), pruned pairs, total cost. EDC maps only."""
        return json.loads(self._inner.rng_json())

    def realize(
        self,
        seed: Optional[int] = None,
        sweeps: Optional[int] = None,
        restarts: Optional[int] = None,
    ) -> dict:
        """Positions under which every relation of the map holds, found by search as
        ``pipeline map realize`` does, with its defaults (a witness layout for drawing; the map
        fixes no metric positions): ``{"landmarks", "x", "y"}`` as numpy arrays, ``exact``
        (every constrained relation holds), ``violated`` and ``constrained`` counts."""
        ids, x, y, violated, constrained = self._inner.realize(
            _count(seed, "seed"), _count(sweeps, "sweeps"), _count(restarts, "restarts")
        )
        return {
            "landmarks": np.asarray(ids, dtype=np.uint32),
            "x": np.asarray(x),
            "y": np.asarray(y),
            "exact": violated == 0,
            "violated": violated,
            "constrained": constrained,
        }

    def copy(self) -> "Map":
        return Map._wrap(self._inner.copy())

    @classmethod
    def close(cls, network: Union["Map", str, "os.PathLike[str]"], calculus: str = "edc") -> "Map":
        """Closes a constraint network to full path consistency, as ``pipeline map close``:
        a :class:`Map`, a file (``pathlib.Path``; ``.json`` maps, otherwise one ``A B C {r,…}``
        per line), or network text; a Map's own calculus replaces ``calculus``. An inconsistent
        network raises
        :class:`ContradictionError` naming a minimal set of conflicting constraints."""
        text, is_json = _network(network)
        if isinstance(network, Map):
            calculus = network.calculus
        return cls._wrap(_qrm.Map.close(text, calculus, is_json))

    @staticmethod
    def check(network: Union["Map", str, "os.PathLike[str]"], calculus: str = "edc") -> dict:
        """Checks a constraint network, as ``pipeline map check``: ``{"consistent": bool,
        "tightened": int, "conflict": str}``."""
        text, is_json = _network(network)
        if isinstance(network, Map):
            calculus = network.calculus
        consistent, tightened, conflict = _qrm.Map.check(text, calculus, is_json)
        return {"consistent": consistent, "tightened": tightened, "conflict": conflict}


def _network(network: Any) -> Tuple[str, bool]:
    if isinstance(network, Map):
        return network.to_json(), True
    if isinstance(network, os.PathLike):
        path = Path(network)
        try:
            return path.read_text(encoding="utf-8"), path.suffix.lower() == ".json"
        except OSError as e:
            raise QrmError(f"cannot read {path}: {e.strerror}") from e
    if isinstance(network, str):
        return network, network.lstrip().startswith("{")
    raise TypeError("a network is a qrm.Map, a pathlib.Path or text")


def _flags(options: dict, reserved: Sequence[str] = ()) -> list:
    """Keyword options as command-line flags: ``no_eval=True`` → ``--no-eval``, ``seed=3`` →
    ``--seed=3``, lists and arrays joined by commas; ``False`` and ``None`` leave the flag out.
    Options the function sets itself (``reserved``) or that only make sense on a terminal are
    refused."""
    argv = []
    for key, value in options.items():
        if key in ("help", "version", "quiet", *reserved):
            raise TypeError(f"{key} is not an option here")
        flag = "--" + key.replace("_", "-")
        if value is None or value is False:
            continue
        if value is True:
            argv.append(flag)
        elif isinstance(value, (list, tuple, np.ndarray)):
            argv.append(f"{flag}=" + ",".join(str(v) for v in np.asarray(value).ravel().tolist()))
        elif isinstance(value, os.PathLike):
            argv.append(f"{flag}={os.fspath(value)}")
        else:
            argv.append(f"{flag}={value}")
    return argv


def _progress(progress: Progress) -> Optional[Callable[[str, int, int], Any]]:
    """A progress function: the caller's, a line on stderr per step for ``True``, or none."""
    if progress is None or progress is False:
        return None
    if progress is True:

        def show(stage: str, done: int, total: int) -> None:
            end = "\n" if done == total else ""
            print(f"\r{stage:<9} {done}/{total}", end=end, file=sys.stderr, flush=True)

        return show
    if not callable(progress):
        raise TypeError("progress must be a function (stage, done, total), True or None")
    return progress


def run(images: PathLike, out: PathLike, *, progress: Progress = None, **options: Any) -> dict:
    """Maps a directory of panoramas, as ``pipeline run --images IMAGES --out OUT``: every
    output file is written into ``out`` (docs/RUN.md) and the summary (summary.json) is
    returned, with ``warnings`` added: ``[[count, first message], …]`` by kind.

    Options are the command's flags: ``calib``, ``truth``, ``no_eval``, ``channels``
    (``"auto"``, ``"colour"``, ``"luminance"``), ``panoramas`` (``"reduced"``, ``"full"``,
    ``"none"``), ``all_edges``. ``progress`` is a function ``(stage, done, total)`` called
    as stations finish (stages ``detect`` and ``map``), or ``True`` for a line on stderr.
    Errors raise :class:`QrmError` with the command line's message; nothing half-written is
    left behind.
    """
    argv = ["run", "--images", os.fspath(images), "--out", os.fspath(out), "--quiet"]
    argv += _flags(options)
    return json.loads(_qrm.run(argv, _progress(progress)))


def synth(
    out: PathLike,
    *,
    preset: str = "marsyard",
    seed: int = 1,
    progress: Progress = None,
    **options: Any,
) -> dict:
    """Renders a synthetic dataset with ground truth into ``out``, as ``pipeline synth``
    (datasets/README.md): presets ``marsyard``, ``random``, ``sparse-large``, ``stress``;
    options are the command's flags (``scale=0.5``, ``rocks``, ``stations``, ``mono``,
    ``grayscale``, ``jpeg=90``, ``sun_elevation``, …). Returns what was rendered."""
    argv = ["synth", "--out", os.fspath(out), "--preset", str(preset), "--seed", str(seed)]
    argv += _flags(options)
    return _qrm.synth(argv, _progress(progress))


def montecarlo_study(**options: Any) -> dict:
    """The Monte Carlo study ``pipeline simulate montecarlo`` runs with these options
    (``study="fig7"`` or ``"dissertation"``, ``maps``, ``stations``, ``nearest=[6, 9]``,
    ``calculus``, ``seed``, ``bearing_noise``, ``order_swaps``): its calculus, maps,
    landmarks, stations, side, series (``nearest``; ``None`` = all) and seed."""
    return _qrm.montecarlo_study(_flags(options, reserved=("out",)))


#: The per-image metrics :func:`simulate` returns.
STEP_METRICS = (
    "removed_incorrect_pct",
    "non_adjacent_open_pct",
    "fully_constrained_pct",
    "open_pct",
    "rng_cost",
    "rng_precision",
    "rng_recall",
    "unsound_relations",
    "contradiction",
    "visible",
    "seconds",
)


def simulate(map_index: int, nearest: Optional[int] = None, **options: Any) -> dict:
    """One mapping run of a Monte Carlo study (000 §VIII-B), exactly as ``pipeline simulate
    montecarlo`` with the same ``options`` runs it: random map number ``map_index`` mapped with
    the ``nearest`` landmarks seen at each imaging point (``None``: all). Returns one numpy
    array per metric of :data:`STEP_METRICS`, one value per image; ``seconds`` is wall time
    (the only value that differs between two runs)."""
    columns = _qrm.montecarlo_run(
        _flags(options, reserved=("out",)),
        _count(map_index, "map_index"),
        _count(nearest, "nearest"),
    )
    return {name: np.asarray(columns[name]) for name in STEP_METRICS}
