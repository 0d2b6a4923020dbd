#!/usr/bin/env python3
"""Charts from an rvr_bench JSON file (Google Benchmark's --benchmark_out format).

usage: plot.py RESULTS.json OUT_DIR
Writes frame_vs_triangles.png, depth_complexity.png, effects.png, ours_vs_embree.png.
"""
import json
import sys
from collections import defaultdict
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def load(path):
    data = json.loads(Path(path).read_text())
    rows = [b for b in data["benchmarks"] if b.get("run_type", "iteration") == "iteration"]
    return data.get("context", {}), rows


def ms(b):
    scale = {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}[b.get("time_unit", "ns")]
    return b["real_time"] * scale


def parts(b):
    return b["name"].replace("/real_time", "").split("/")


def subtitle(context):
    return f'{context.get("date", "")}, {context.get("num_cpus", "?")} CPUs at {context.get("mhz_per_cpu", "?")} MHz'


def frame_vs_triangles(rows, context, out):
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.5), sharey=True)
    for ax, scene in zip(axes, ["tessphere", "soup"]):
        series = defaultdict(list)
        for b in rows:
            p = parts(b)
            if p[0] == "BM_Frame" and p[2] == scene and p[4] == "1024":
                series[p[1]].append((int(p[3]), ms(b)))
        for name, pts in sorted(series.items()):
            pts.sort()
            ax.plot([x for x, _ in pts], [y for _, y in pts], marker="o", label=name)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_title(f"{scene}, 1024x768")
        ax.set_xlabel("triangles")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("frame time (ms)")
    axes[0].legend()
    fig.suptitle("Frame time vs triangles: z-buffer vs ray tracing (" + subtitle(context) + ")")
    fig.tight_layout()
    fig.savefig(out / "frame_vs_triangles.png", dpi=100)


def depth_complexity(rows, context, out):
    series = defaultdict(list)
    for b in rows:
        p = parts(b)
        if p[0] == "BM_DepthComplexity":
            series[p[1]].append((int(p[2]), ms(b)))
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    for name, pts in sorted(series.items()):
        pts.sort()
        ax.plot([x for x, _ in pts], [y for _, y in pts], marker="o", label=name)
    ax.set_xscale("log", base=2)
    ax.set_xlabel("depth complexity N (occluders:N, 512x384)")
    ax.set_ylabel("frame time (ms)")
    ax.set_title("The z-buffer pays for hidden surfaces\n" + subtitle(context))
    ax.grid(True, alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(out / "depth_complexity.png", dpi=100)


def effects(rows, context, out):
    times = {parts(b)[1]: ms(b) for b in rows if parts(b)[0] == "BM_Effects"}
    if "primary" not in times:
        return
    names = list(times)
    fig, ax = plt.subplots(figsize=(8, 4.5))
    ax.bar(names, [times[n] / times["primary"] for n in names], color="tab:orange")
    ax.set_ylabel("cost relative to primary rays only")
    ax.set_title("What each tracer effect costs on cornell (640x480)\n" + subtitle(context))
    ax.tick_params(axis="x", rotation=40)
    ax.grid(True, axis="y", alpha=0.3)
    fig.tight_layout()
    fig.savefig(out / "effects.png", dpi=100)


def ours_vs_embree(rows, context, out):
    trace = {}
    build = {}
    for b in rows:
        p = parts(b)
        if p[0] == "BM_Trace":
            trace[(p[1], p[2], p[3])] = b.get("rays/s", 0) / 1e6
        if p[0] == "BM_Build":
            build[(p[1], int(p[2]))] = b.get("prims/s", 0) / 1e6
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(12, 4.5))
    cases = sorted({(r, s) for (_, r, s) in trace})
    xs = range(len(cases))
    for i, accel in enumerate(["bvh", "embree"]):
        ax1.bar([x + 0.4 * i for x in xs], [trace.get((accel, r, s), 0) for r, s in cases], 0.4, label=accel)
    ax1.set_xticks([x + 0.2 for x in xs], [f"{r}\n{s}" for r, s in cases])
    ax1.set_ylabel("Mrays/s, one thread")
    ax1.set_title("Closest hit: our BVH vs rtcIntersect1")
    ax1.legend()
    sizes = sorted({n for (_, n) in build})
    for accel in ["bvh", "embree"]:
        ax2.plot(sizes, [build.get((accel, n), 0) for n in sizes], marker="o", label=accel)
    ax2.set_xscale("log")
    ax2.set_xlabel("triangles (soup)")
    ax2.set_ylabel("Mprims/s, one thread")
    ax2.set_title("BVH build")
    ax2.legend()
    fig.suptitle("Ours vs Embree (" + subtitle(context) + ")")
    fig.tight_layout()
    fig.savefig(out / "ours_vs_embree.png", dpi=100)


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    context, rows = load(sys.argv[1])
    out = Path(sys.argv[2])
    out.mkdir(parents=True, exist_ok=True)
    for chart in (frame_vs_triangles, depth_complexity, effects, ours_vs_embree):
        chart(rows, context, out)
    print(f"wrote charts to {out}/")


if __name__ == "__main__":
    main()
