"""A notebook-style tour of qrm from Python (docs/PYTHON.md): map the demo panoramas, draw
their RNG with matplotlib, and run a small Monte Carlo sweep (000 Fig. 7) on a local Dask
cluster with two workers.

    python demo_map_and_sweep.py [--images datasets/demo] [--out qrm-python-demo]

Needs: pip install qrm[batch] matplotlib (or the wheel built from pipeline/python).
"""

# %% Set-up
import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from distributed import Client, LocalCluster  # noqa: E402

import qrm  # noqa: E402
from qrm import batch  # noqa: E402

ROOT = Path(__file__).resolve().parents[3]


# %% 1. Map the demo panoramas (the same files as `pipeline run`)
def map_panoramas(images: Path, out: Path) -> qrm.Map:
    summary = qrm.run(images, out, progress=True)
    print(
        f"{summary['landmarks']} landmarks from {summary['stations']} stations; "
        f"{summary['rng_certain']} certain and {summary['rng_uncertain']} possible RNG edges"
    )
    return qrm.Map.load(out / "map.json")


# %% 2. The map's RNG, drawn over one realization: positions under which every relation
# holds (the qualitative map fixes no metric positions, so any such layout will do)
MAX_COST = 0.15  # the edges rng.png draws by default: cost w <= 0.15 (docs/RUN.md)


def draw_rng(ax, m: qrm.Map) -> None:
    rng = m.rng()
    layout = m.realize()
    where = {int(i): (x, y) for i, x, y in zip(layout["landmarks"], layout["x"], layout["y"])}
    edges = [e for e in rng["edges"] if e["cost"] <= MAX_COST]
    for edge in sorted(edges, key=lambda e: -e["cost"]):
        (x0, y0), (x1, y1) = where[edge["a"]], where[edge["b"]]
        certain = edge["cost"] == 0
        ax.plot(
            [x0, x1],
            [y0, y1],
            color="black" if certain else "tab:orange",
            lw=2 if certain else 0.8,
            alpha=1 if certain else 0.5,
            zorder=1,
        )
    ax.scatter(layout["x"], layout["y"], s=60, color="tab:blue", zorder=2)
    for i, (x, y) in where.items():
        ax.annotate(str(i), (x, y), textcoords="offset points", xytext=(4, 4), fontsize=8)
    ax.plot([], [], color="black", lw=2, label="certain edge (w = 0)")
    ax.plot([], [], color="tab:orange", lw=0.8, label=f"possible edge (0 < w ≤ {MAX_COST})")
    ax.set_title(
        f"(a) RNG of the demo map: {len(m)} landmarks, {len(edges)} of "
        f"{len(rng['edges'])} edges,\n"
        f"drawn on an {'exact' if layout['exact'] else 'approximate'} realization"
    )
    ax.set_xlabel("x (realization units)")
    ax.set_ylabel("y (realization units)")
    ax.set_aspect("equal")
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=2, fontsize=8)


# %% 3. A small Fig. 7 sweep on a local cluster of two workers
def small_sweep(ax, out: Path) -> None:
    with (
        LocalCluster(n_workers=2, threads_per_worker=1, dashboard_address=None) as cluster,
        Client(cluster) as client,
    ):
        rows = batch.sweep(client=client, maps=8, stations=30, nearest=[6, 12, 30], chunk=4)
    table = batch.aggregate(rows)
    table.to_csv(out / "sweep.csv", index=False)
    for n, series in table.groupby("n", sort=False):
        ax.plot(series["image"], series["removed_incorrect_pct"], label=f"n = {n}")
    ax.set_title("(b) incorrect states removed (000 Fig. 7a), 8 random maps")
    ax.set_xlabel("image number")
    ax.set_ylabel("incorrect states removed (%)")
    ax.set_ylim(0, 100)
    ax.grid(alpha=0.3)
    ax.legend(title="nearest landmarks seen")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--images", type=Path, default=ROOT / "datasets" / "demo")
    parser.add_argument("--out", type=Path, default=Path("qrm-python-demo"))
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    fig, (ax_rng, ax_sweep) = plt.subplots(1, 2, figsize=(13, 5.5))
    draw_rng(ax_rng, map_panoramas(args.images, args.out / "run"))
    small_sweep(ax_sweep, args.out)
    fig.tight_layout()
    fig.savefig(args.out / "demo.png", dpi=110)
    print(f"wrote {args.out / 'demo.png'} and {args.out / 'sweep.csv'}")


# Dask's worker processes import this file: the work runs only when it is the program.
if __name__ == "__main__":
    main()
