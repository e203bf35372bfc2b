#!/usr/bin/python3
"""Draws the paper's figures from `spaceskip bench --paper --csv FILE`.

Zellmann, "Comparing Hierarchical Data Structures for Sparse Volume Rendering with Empty Space
Skipping": Fig. 3 (frame rates per data set and structure), Fig. 4 (build rates, log scale), and
our ratio to the paper per cell (data set x structure), both as frame rates and as speed-up over
naive (which cancels most of the hardware and scale difference).

usage: plot-paper-bench.py OURS.csv [MORE.csv...] [--paper paper_results.csv] [--out DIR] [--title TEXT]
Needs matplotlib (Debian: python3-matplotlib; SPACESKIP_PLOTS=1 bash scripts/setup-debian.sh; not used by
the tests or CI).
"""
import argparse
import csv
import math
import os
import sys

try:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:  # a clear message rather than a traceback
    sys.exit("plot-paper-bench.py needs matplotlib: apt-get install python3-matplotlib "
             "(or SPACESKIP_PLOTS=1 bash scripts/setup-debian.sh)")

PAPER_KEYS = ["naive", "lbvh", "cpu_shallow", "cpu_mls32", "cpu_mls128", "gpu_shallow", "gpu_mls32",
              "gpu_mls128", "hybrid"]
LABELS = {"naive": "Naive", "lbvh": "LBVH", "cpu_shallow": "CPU shallow", "cpu_mls32": "CPU MLS=32",
          "cpu_mls128": "CPU MLS=128", "gpu_shallow": "GPU shallow", "gpu_mls32": "GPU MLS=32",
          "gpu_mls128": "GPU MLS=128", "hybrid": "Hybrid", "grid": "Grid (ours)",
          "distance_grid": "DistanceGrid (ours)", "kdtree_gpu_fast": "KdTreeGPUFast (ours)",
          "kdtree_empty": "k-d Empty (ours)", "auto": "Auto (ours)"}


def num(s):
    try:
        v = float(s)
        return v if math.isfinite(v) else None
    except (TypeError, ValueError):
        return None


def voxels(dims):
    x, y, z = (int(t) for t in dims.split("x"))
    return x * y * z


def read_ours(paths):
    rows = [r for path in paths for r in csv.DictReader(open(path)) if r.get("status", "ok") == "ok"]
    sets, variants, cell = [], [], {}
    for r in rows:
        if r["dataset"] not in sets:
            sets.append(r["dataset"])
        if r["variant"] not in variants:
            variants.append(r["variant"])
        cell[(r["dataset"], r["variant"])] = r
    return sets, variants, cell


def read_paper(path):
    lines = [l for l in open(path) if not l.startswith("#") and l.strip()]
    out = {}
    for r in csv.DictReader(lines):
        d = {"dims": r["dims"], "naive_fps": num(r["naive_fps"])}
        for k in PAPER_KEYS[1:]:
            d[k + "_fps"] = num(r[k + "_fps"])
            d[k + "_build"] = num(r[k + "_build"])
        d["naive_fps"] = num(r["naive_fps"])
        out[r["dataset"]] = d
    return out


def paper_fps(paper, ds, k):
    p = paper.get(ds)
    if not p:
        return None
    return p["naive_fps"] if k == "naive" else p.get(k + "_fps")


def grid_axes(n, w=4.2, h=3.0):
    cols = min(4, n)
    rows = (n + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(w * cols, h * rows), squeeze=False)
    flat = [a for row in axes for a in row]
    for a in flat[n:]:
        a.axis("off")
    return fig, flat


def bars(ax, names, values, colors, log=False):
    xs = range(len(names))
    ax.bar(xs, [v if v is not None else 0 for v in values], color=colors)
    ax.set_xticks(list(xs))
    ax.set_xticklabels([LABELS.get(n, n) for n in names], rotation=70, ha="right", fontsize=6)
    if log:
        ax.set_yscale("log")
    ax.tick_params(axis="y", labelsize=7)


def color(k):
    cmap = plt.get_cmap("tab20")
    order = PAPER_KEYS + ["grid", "distance_grid", "kdtree_gpu_fast", "kdtree_empty", "auto"]
    return cmap(order.index(k) % 20) if k in order else "0.5"


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("ours", nargs="+", help="one or more CSVs of bench --paper (rows are merged)")
    ap.add_argument("--paper", default=os.path.join(here, "..", "docs", "results", "paper-bench", "paper",
                                                    "paper_results.csv"))
    ap.add_argument("--out", default=".")
    ap.add_argument("--title", default="")
    a = ap.parse_args()
    sets, variants, cell = read_ours(a.ours)
    if not sets:
        sys.exit("no measured rows in " + " ".join(a.ours))
    paper = read_paper(a.paper)
    os.makedirs(a.out, exist_ok=True)
    sub = (" - " + a.title) if a.title else ""

    def metric(ds, v, key):
        r = cell.get((ds, v))
        return num(r[key]) if r else None

    # Fig. 3: frame rates per data set, ours and the paper's.
    fig, ax = grid_axes(len(sets))
    for i, ds in enumerate(sets):
        vs = [v for v in variants if (ds, v) in cell]
        bars(ax[i], vs, [metric(ds, v, "kernel_fps") for v in vs], [color(v) for v in vs])
        ax[i].set_title("%s %s" % (ds, cell[(ds, vs[0])]["dims"]), fontsize=8)
        ax[i].set_ylabel("fps (render kernel)", fontsize=7)
    fig.suptitle("Frame rates, ours" + sub, fontsize=10)
    fig.tight_layout()
    fig.savefig(os.path.join(a.out, "fps_ours.png"), dpi=110)
    plt.close(fig)

    psets = [ds for ds in sets if ds in paper]
    if psets:
        fig, ax = grid_axes(len(psets))
        for i, ds in enumerate(psets):
            bars(ax[i], PAPER_KEYS, [paper_fps(paper, ds, k) for k in PAPER_KEYS], [color(k) for k in PAPER_KEYS])
            ax[i].set_title("%s %s" % (ds, paper[ds]["dims"]), fontsize=8)
            ax[i].set_ylabel("fps (Titan V)", fontsize=7)
        fig.suptitle("Frame rates, the paper (Fig. 3, Table 2)", fontsize=10)
        fig.tight_layout()
        fig.savefig(os.path.join(a.out, "fps_paper.png"), dpi=110)
        plt.close(fig)

    # Fig. 4: build rates (voxels per second of construction), log scale; ours solid, the
    # paper's (at its full dims) hatched beside them.
    fig, ax = grid_axes(len(sets), w=5.0)
    for i, ds in enumerate(sets):
        # Builders with nothing to build (naive, grid: classification only) are left out.
        vs = [v for v in variants if (ds, v) in cell and (metric(ds, v, "build_s") or 0) > 1e-6]
        xs = list(range(len(vs)))
        ours = [voxels(cell[(ds, v)]["dims"]) / metric(ds, v, "build_s") for v in vs]
        theirs = []
        for v in vs:
            b = paper.get(ds, {}).get(v + "_build")
            theirs.append(voxels(paper[ds]["dims"]) / b if b else 0)
        ax[i].bar([x - 0.2 for x in xs], ours, width=0.4, color=[color(v) for v in vs], label="ours")
        ax[i].bar([x + 0.2 for x in xs], theirs, width=0.4, color="white", edgecolor=[color(v) for v in vs],
                  hatch="///", label="paper")
        ax[i].set_yscale("log")
        ax[i].set_xticks(xs)
        ax[i].set_xticklabels([LABELS.get(v, v) for v in vs], rotation=70, ha="right", fontsize=6)
        ax[i].set_title(ds, fontsize=8)
        ax[i].set_ylabel("voxels / s of build", fontsize=7)
        ax[i].tick_params(axis="y", labelsize=7)
        if i == 0:
            ax[i].legend(fontsize=6)
    fig.suptitle("Build rates (log scale); hatched: the paper's" + sub, fontsize=10)
    fig.tight_layout()
    fig.savefig(os.path.join(a.out, "build_rates.png"), dpi=110)
    plt.close(fig)

    # Ratio to the paper per cell: fps ratio and speed-up-over-naive ratio.
    keys = [k for k in PAPER_KEYS if any((ds, k) in cell for ds in psets)]
    if psets and keys:
        for what, fname in (("fps", "ratio_fps.png"), ("speedup", "ratio_speedup.png")):
            m = []
            for ds in psets:
                row = []
                naive_ours = metric(ds, "naive", "kernel_fps")
                naive_paper = paper_fps(paper, ds, "naive")
                for k in keys:
                    o, p = metric(ds, k, "kernel_fps"), paper_fps(paper, ds, k)
                    if what == "speedup":
                        o = o / naive_ours if o and naive_ours else None
                        p = p / naive_paper if p and naive_paper else None
                    row.append(o / p if o and p else float("nan"))
                m.append(row)
            fig, axh = plt.subplots(figsize=(1.0 + 0.9 * len(keys), 1.0 + 0.45 * len(psets)))
            finite = [v for row in m for v in row if v == v and v > 0]
            lim = max(abs(math.log10(v)) for v in finite) if finite else 1
            logm = [[math.log10(v) if v == v and v > 0 else float("nan") for v in row] for row in m]
            im = axh.imshow(logm, cmap="RdBu", vmin=-lim, vmax=lim, aspect="auto")
            for r, row in enumerate(m):
                for c, v in enumerate(row):
                    if v == v:
                        axh.text(c, r, ("%.2f" if v < 10 else "%.0f") % v, ha="center", va="center", fontsize=6)
            axh.set_xticks(range(len(keys)))
            axh.set_xticklabels([LABELS.get(k, k) for k in keys], rotation=45, ha="right", fontsize=7)
            axh.set_yticks(range(len(psets)))
            axh.set_yticklabels(psets, fontsize=7)
            cb = fig.colorbar(im, ax=axh)
            cb.set_label("log10 ratio", fontsize=7)
            axh.set_title(("ours / paper, kernel fps" if what == "fps" else
                           "ours / paper, speed-up over naive") + sub, fontsize=8)
            fig.tight_layout()
            fig.savefig(os.path.join(a.out, fname), dpi=110)
            plt.close(fig)
    print("wrote", ", ".join(f for f in ("fps_ours.png", "fps_paper.png", "build_rates.png", "ratio_fps.png",
                                         "ratio_speedup.png") if os.path.exists(os.path.join(a.out, f))), "in", a.out)


if __name__ == "__main__":
    main()
