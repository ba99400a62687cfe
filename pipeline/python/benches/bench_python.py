"""Benchmarks of the Python package (figures in docs/PYTHON.md and docs/BENCHMARKS.md):

1. binding overhead of one ``qrm.measure`` call: the Python call against the same triple
   measured in Rust (``qrm-bench --triple-calls``);
2. a 000 Fig. 7 sweep: ``pipeline simulate montecarlo`` against ``qrm.batch.sweep`` in this
   process and on a ``LocalCluster`` of two single-threaded workers;
3. Dask's per-task cost (empty tasks on the same cluster) and, from the measured time per
   mapping run, an estimate of a 10^6-scenario sweep on 100 workers.

    python bench_python.py [--maps 100] [--json figures.json]

Run from anywhere after ``cargo build --release -p pipeline -p qrm-tools`` and installing the
wheel; it prints a Markdown table.
"""

import argparse
import json
import subprocess
import tempfile
import time
from pathlib import Path

import qrm
from qrm import _qrm, batch

ROOT = Path(__file__).resolve().parents[3]


def per_call(function, calls: int) -> float:
    """Seconds per call, best of three rounds."""
    best = float("inf")
    for _ in range(3):
        start = time.perf_counter()
        for _ in range(calls):
            function()
        best = min(best, (time.perf_counter() - start) / calls)
    return best


def rust_triple(bench: Path, calls: int, uncertainty: float) -> float:
    out = subprocess.run(
        [str(bench), "--triple-calls", str(calls), "--uncertainty", str(uncertainty)],
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    return float(out.split(" µs each")[0].rsplit(", ", 1)[1]) * 1e-6


def noop(x):
    return x


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--maps", type=int, default=100, help="maps of the Fig. 7 sweep")
    parser.add_argument("--chunk", type=int, default=10, help="runs per Dask task")
    parser.add_argument("--pipeline", type=Path, default=ROOT / "target/release/pipeline")
    parser.add_argument("--qrm-bench", type=Path, default=ROOT / "target/release/qrm-bench")
    parser.add_argument("--json", type=Path, help="also write the figures here")
    args = parser.parse_args()
    figures = {}

    # 1. Binding overhead of measure.
    for uncertainty, calls in ((0.0, 20000), (0.5, 1000)):

        def wrapper_call(u=uncertainty):
            return qrm.measure([0.0, 40.0, 100.0], "A<B<C", u)

        def native_call(u=uncertainty):
            return _qrm.measure("edc", [0.0, 40.0, 100.0], "A<B<C", u)

        wrapper = per_call(wrapper_call, calls)
        native = per_call(native_call, calls)
        rust = rust_triple(args.qrm_bench, calls, uncertainty)
        figures[f"measure ±{uncertainty}°"] = {
            "rust_us": rust * 1e6,
            "native_us": native * 1e6,
            "python_us": wrapper * 1e6,
            "overhead_us": (wrapper - rust) * 1e6,
        }

    # 2. The Fig. 7 sweep three ways.
    study = dict(maps=args.maps)
    runs = len(qrm.montecarlo_study(**study)["nearest"]) * args.maps
    with tempfile.TemporaryDirectory() as out:
        start = time.perf_counter()
        subprocess.run(
            [str(args.pipeline), "simulate", "montecarlo", "--maps", str(args.maps), "--out", out],
            capture_output=True,
            check=True,
        )
        cli_seconds = time.perf_counter() - start
    start = time.perf_counter()
    local = batch.sweep(chunk=args.chunk, **study)
    local_seconds = time.perf_counter() - start

    from distributed import Client, LocalCluster

    start = time.perf_counter()
    cluster = LocalCluster(n_workers=2, threads_per_worker=1, dashboard_address=None)
    client = Client(cluster)
    startup = time.perf_counter() - start
    client.submit(noop, 0).result()  # workers import qrm before the clock starts
    start = time.perf_counter()
    remote = batch.sweep(client=client, chunk=args.chunk, **study)
    cluster_seconds = time.perf_counter() - start
    equal = local.drop(columns="seconds").equals(remote.drop(columns="seconds"))

    # 3. Dask's cost per task: empty tasks, submitted and gathered.
    tasks = 2000
    start = time.perf_counter()
    client.gather(client.map(noop, range(tasks), pure=False))
    per_task = (time.perf_counter() - start) / tasks
    client.close()
    cluster.close()

    per_run_core = cluster_seconds * 2 / runs  # two single-threaded workers
    scenarios, workers = 10**6, 100
    estimate = scenarios * per_run_core / workers + scenarios / args.chunk * per_task
    figures["fig7"] = {
        "maps": args.maps,
        "runs": runs,
        "chunk": args.chunk,
        "cli_seconds": cli_seconds,
        "in_process_seconds": local_seconds,
        "cluster_seconds": cluster_seconds,
        "cluster_startup_seconds": startup,
        "speedup_vs_in_process": local_seconds / cluster_seconds,
        "speedup_vs_cli": cli_seconds / cluster_seconds,
        "cluster_equals_in_process": equal,
        "dask_seconds_per_empty_task": per_task,
        "core_seconds_per_run": per_run_core,
        "estimate_1e6_runs_100_workers_hours": estimate / 3600,
    }

    print("| figure | value |\n|---|---|")
    for name, values in figures.items():
        for key, value in values.items():
            shown = f"{value:.4g}" if isinstance(value, float) else str(value)
            print(f"| {name}: {key} | {shown} |")
    if args.json:
        args.json.write_text(json.dumps(figures, indent=2) + "\n")


if __name__ == "__main__":
    main()
