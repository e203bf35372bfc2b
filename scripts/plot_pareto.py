#!/usr/bin/python3
"""Speed/accuracy Pareto plots from `spaceskip accuracy ... --csv FILE` (issue 13).

usage: plot_pareto.py OUT.png CSV [CSV...]
One panel per (data set, backend): each setting (sample distance x filter x early ray termination
x jitter) is a point, kernel fps (log) against PSNR to the 1/8-voxel reference; the Pareto front
(no other setting both faster and more accurate) is drawn as a line and its points labelled.
Needs matplotlib (Debian: python3-matplotlib).
"""
import csv
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def load(paths):
    rows = []
    for p in paths:
        with open(p, newline="") as f:
            rows += list(csv.DictReader(f))
    for r in rows:
        for k in ("dt_voxel", "psnr_db", "ssim", "fps", "kernel_fps", "max_diff"):
            r[k] = float(r[k])
        if math.isinf(r["psnr_db"]):
            r["psnr_db"] = 99.0
    return rows


def front(points):
    """Indices of the points no other point beats in both speed and PSNR."""
    out = []
    for i, a in enumerate(points):
        if not any(b["kernel_fps"] >= a["kernel_fps"] and b["psnr_db"] >= a["psnr_db"] and
                   (b["kernel_fps"] > a["kernel_fps"] or b["psnr_db"] > a["psnr_db"]) for b in points):
            out.append(i)
    return sorted(out, key=lambda i: points[i]["kernel_fps"])


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    rows = load(sys.argv[2:])
    panels = sorted({(os.path.basename(r["dataset"]), r["backend"]) for r in rows})
    cols = min(3, len(panels))
    nrows = (len(panels) + cols - 1) // cols
    fig, axes = plt.subplots(nrows, cols, figsize=(max(9.0, 5.2 * cols), 4.2 * nrows + 0.6), squeeze=False)
    colours = {"exact": "tab:blue", "hardware": "tab:orange"}
    for ax, (ds, be) in zip(axes.flat, panels):
        pts = [r for r in rows if os.path.basename(r["dataset"]) == ds and r["backend"] == be]
        for r in pts:
            marker = {("off", "off"): "o", ("0.99", "off"): "s", ("off", "on"): "^", ("0.99", "on"): "D"}[(r["ert"], r["jitter"])]
            ax.scatter(r["kernel_fps"], r["psnr_db"], c=colours.get(r["filter"], "k"), marker=marker, s=28, alpha=0.8)
        f = front(pts)
        ax.plot([pts[i]["kernel_fps"] for i in f], [pts[i]["psnr_db"] for i in f], "k--", lw=1)
        for i in f:
            r = pts[i]
            ax.annotate("%g%s%s" % (r["dt_voxel"], " ert" if r["ert"] != "off" else "", " j" if r["jitter"] == "on" else ""),
                        (r["kernel_fps"], r["psnr_db"]), fontsize=7, xytext=(3, 3), textcoords="offset points")
        ax.set_xscale("log")
        ax.set_title("%s (%s, %s)" % (ds, be, pts[0]["builder"]), fontsize=9)
        ax.set_xlabel("kernel fps")
        ax.set_ylabel("PSNR vs 1/8-voxel reference [dB]")
        ax.grid(True, which="both", alpha=0.3)
    for ax in list(axes.flat)[len(panels):]:
        ax.axis("off")
    from matplotlib.lines import Line2D
    handles = [Line2D([], [], color=c, marker="o", ls="", label=k) for k, c in colours.items()]
    handles += [Line2D([], [], color="k", marker=m, ls="", label=l) for m, l in
                (("o", "ERT off, no jitter"), ("s", "ERT 0.99"), ("^", "jitter"), ("D", "ERT + jitter"))]
    handles.append(Line2D([], [], color="k", ls="--", label="Pareto front (labels: step in voxels)"))
    fig.legend(handles=handles, loc="lower center", ncol=4, fontsize=8)
    fig.tight_layout(rect=(0, 0.06, 1, 1))
    fig.savefig(sys.argv[1], dpi=110)
    print("wrote", sys.argv[1], "panels:", len(panels))


if __name__ == "__main__":
    main()
