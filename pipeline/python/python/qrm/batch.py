"""Batches on a Dask cluster: many traverses mapped with :func:`qrm.run`, or Monte Carlo
sweeps of :func:`qrm.simulate` over scenarios and parameters (docs/PYTHON.md).

Both take a ``dask.distributed.Client`` and use nothing else of the cluster, so the same call
runs on a ``LocalCluster``, an HPC cluster (``dask_jobqueue.SLURMCluster`` and friends) or
Kubernetes (``dask_kubernetes``). Without a client they run in this process, one task after
the other: the same tasks and the same results, which is how a sweep on a cluster is checked.

- :func:`run_traverses`: one task per traverse; each traverse's outputs go to its own
  directory; a failing traverse is a row with its error, not the end of the batch; traverses
  whose outputs are complete are skipped (resumable).
- :func:`sweep`: one task per chunk of (series, map) runs; one row per run and image.
- :func:`aggregate`: a sweep's rows as ``pipeline simulate montecarlo`` writes montecarlo.csv
  (mean and population standard deviation over the maps, per series and image).
"""

from __future__ import annotations

import glob as globbing
import hashlib
import json
import os
import time
from pathlib import Path
from typing import Any, Callable, Iterable, List, Optional, Sequence, Union

import qrm

__all__ = ["aggregate", "run_traverses", "sweep", "traverse_outputs_complete"]


def _pandas():
    try:
        import pandas
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise ImportError("qrm.batch needs pandas: pip install 'qrm[batch]'") from e
    return pandas


def _traverse_dirs(traverses: Union[str, "os.PathLike[str]", Iterable[Any]]) -> List[Path]:
    """A glob pattern, one directory, or a list of directories, as sorted-for-globs paths."""
    if isinstance(traverses, (str, os.PathLike)):
        text = os.fspath(traverses)
        if any(ch in text for ch in "*?["):
            found = sorted(Path(p) for p in globbing.glob(text) if os.path.isdir(p))
            if not found:
                raise FileNotFoundError(f"no traverse directory matches {text!r}")
            return found
        return [Path(text)]
    dirs = [Path(os.fspath(t)) for t in traverses]
    if not dirs:
        raise ValueError("no traverses given")
    return dirs


def _output_names(dirs: Sequence[Path]) -> List[str]:
    """One output directory name per traverse: its own name, or, where names collide, the name
    with a short hash of its full path — stable whatever the order of the list, so that a
    resumed batch finds its outputs again."""
    names = [d.name or "traverse" for d in dirs]
    count: dict = {}
    for n in names:
        count[n] = count.get(n, 0) + 1
    return [
        n
        if count[n] == 1
        else f"{n}-{hashlib.sha1(os.fspath(d.resolve()).encode()).hexdigest()[:8]}"
        for n, d in zip(names, dirs)
    ]


def traverse_outputs_complete(out: Union[str, "os.PathLike[str]"]) -> bool:
    """Whether ``out`` holds a finished run: ``pipeline run`` moves all its files into place in
    one pass, summary.json among them, so its presence means the outputs are whole."""
    return (Path(out) / "summary.json").is_file()


#: The summary.json fields each traverse's row carries.
SUMMARY_COLUMNS = (
    "stations",
    "stations_skipped",
    "detections",
    "landmarks",
    "triples",
    "open_fraction",
    "contradictions",
    "rng_certain",
    "rng_uncertain",
)


def _run_traverse(images: str, out: str, options: dict, resume: bool) -> dict:
    """One traverse, as a task: a row of the batch table, never an exception."""
    row = {"traverse": images, "out": out, "status": "ok", "error": "", "seconds": 0.0}
    if resume and traverse_outputs_complete(out):
        row["status"] = "skipped"
        summary = _read_summary(out)
    else:
        start = time.perf_counter()
        try:
            summary = qrm.run(images, out, **options)
        except Exception as e:  # a failing traverse is reported, not fatal to the batch
            row.update(status="failed", error=f"{type(e).__name__}: {e}")
            summary = {}
        row["seconds"] = time.perf_counter() - start
    for key in SUMMARY_COLUMNS:
        if key in summary:
            row[key] = summary[key]
    return row


def _read_summary(out: str) -> dict:

    try:
        return json.loads((Path(out) / "summary.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return {}


def run_traverses(
    traverses: Union[str, "os.PathLike[str]", Iterable[Any]],
    out_root: Union[str, "os.PathLike[str]"],
    *,
    client: Any = None,
    resume: bool = True,
    on_result: Optional[Callable[[dict], Any]] = None,
    **options: Any,
):
    """Maps every traverse (a directory of panoramas, as :func:`qrm.run` takes) into
    ``out_root/NAME``, one task per traverse on ``client`` (a ``dask.distributed.Client``; in
    this process when ``None``). ``options`` go to :func:`qrm.run` (``no_eval=True``,
    ``channels="luminance"``, …). With ``resume``, a traverse whose outputs are complete is
    skipped. ``on_result(row)`` is called as each traverse finishes.

    Returns a pandas DataFrame, one row per traverse in the order given: ``traverse``,
    ``out``, ``status`` (``ok``, ``failed``, ``skipped``), ``error``, ``seconds`` and the
    summary's fields of :data:`SUMMARY_COLUMNS`.
    """
    pandas = _pandas()
    dirs = _traverse_dirs(traverses)
    root = Path(out_root)
    root.mkdir(parents=True, exist_ok=True)
    jobs = [(os.fspath(d), os.fspath(root / name)) for d, name in zip(dirs, _output_names(dirs))]
    rows: List[Optional[dict]] = [None] * len(jobs)
    if client is None:
        for i, (images, out) in enumerate(jobs):
            rows[i] = _run_traverse(images, out, options, resume)
            if on_result:
                on_result(rows[i])
    else:
        from distributed import as_completed

        futures = [
            client.submit(_run_traverse, images, out, options, resume, pure=False)
            for images, out in jobs
        ]
        index = {f.key: i for i, f in enumerate(futures)}
        for future in as_completed(futures):
            i = index[future.key]
            try:
                rows[i] = future.result()
            except Exception as e:  # the worker itself died: still one row
                images, out = jobs[i]
                rows[i] = {
                    "traverse": images,
                    "out": out,
                    "status": "failed",
                    "error": f"{type(e).__name__}: {e}",
                    "seconds": 0.0,
                }
            if on_result:
                on_result(rows[i])
    return pandas.DataFrame(rows)


def _sweep_chunk(runs: Sequence[tuple], options: dict) -> List[dict]:
    """Runs of a sweep, as a task: one row per (run, image)."""
    rows = []
    for nearest, map_index in runs:
        steps = qrm.simulate(map_index, nearest, **options)
        for image in range(len(steps["seconds"])):
            row = {"nearest": nearest, "map": map_index, "image": image + 1}
            for name in qrm.STEP_METRICS:
                value = steps[name][image]
                row[name] = value.item() if hasattr(value, "item") else value
            rows.append(row)
    return rows


def sweep(
    *,
    client: Any = None,
    chunk: int = 10,
    on_chunk: Optional[Callable[[int, int], Any]] = None,
    **study: Any,
):
    """A Monte Carlo sweep: every map of the study ``pipeline simulate montecarlo`` runs with
    these ``study`` options (``study="fig7"``, ``maps``, ``stations``, ``nearest=[6, 9]``,
    ``calculus``, ``seed``, ``bearing_noise``, ``order_swaps``), for every series, in tasks of
    ``chunk`` runs on ``client`` (in this process when ``None``). ``on_chunk(done, total)``
    is called as chunks finish.

    Returns a pandas DataFrame, one row per series, map and image: ``nearest`` (None = all),
    ``map``, ``image`` (1-based) and the metrics of :data:`qrm.STEP_METRICS`. Every column but
    ``seconds`` (wall time) is the same on any cluster and in this process.
    """
    pandas = _pandas()
    if isinstance(chunk, bool) or not isinstance(chunk, int) or chunk < 1:
        raise ValueError(f"chunk must be a positive integer, got {chunk!r}")
    described = qrm.montecarlo_study(**study)
    options = {k: v for k, v in study.items() if k != "nearest"}
    runs = [(n, m) for n in described["nearest"] for m in range(described["maps"])]
    chunks = [runs[i : i + chunk] for i in range(0, len(runs), chunk)]
    results: List[Optional[List[dict]]] = [None] * len(chunks)
    if client is None:
        for i, c in enumerate(chunks):
            results[i] = _sweep_chunk(c, options)
            if on_chunk:
                on_chunk(i + 1, len(chunks))
    else:
        from distributed import as_completed

        futures = [client.submit(_sweep_chunk, c, options, pure=False) for c in chunks]
        index = {f.key: i for i, f in enumerate(futures)}
        for done, future in enumerate(as_completed(futures), start=1):
            results[index[future.key]] = future.result()
            if on_chunk:
                on_chunk(done, len(chunks))
    rows = [row for chunk_rows in results for row in chunk_rows]
    frame = pandas.DataFrame(rows)
    frame.attrs["study"] = described
    return frame


#: The metrics of montecarlo.csv, in its column order.
CSV_METRICS = (
    "removed_incorrect_pct",
    "non_adjacent_open_pct",
    "fully_constrained_pct",
    "open_pct",
    "rng_cost",
    "seconds",
)


def aggregate(frame):
    """A sweep's rows per series and image as montecarlo.csv has them: ``n`` (``all`` for
    every landmark), ``image``, then the mean and population standard deviation (``_std``) of
    each metric over the maps."""
    pandas = _pandas()
    frame = frame.copy()
    frame["n"] = frame["nearest"].map(lambda n: "all" if n is None or n != n else str(int(n)))
    grouped = frame.groupby(["n", "image"], sort=False)[list(CSV_METRICS)]
    mean = grouped.mean()
    std = grouped.std(ddof=0)
    columns = {}
    for name in CSV_METRICS:
        columns[name] = mean[name]
        columns[f"{name}_std"] = std[name]
    return pandas.DataFrame(columns).reset_index()
