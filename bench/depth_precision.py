#!/usr/bin/env python3
"""The z-fighting chart: id mismatch rate against the tracer as far/near grows, per z-buffer format.

Two planes (one triangle each, larger than the view, so no edge lies in the picture) tilted
across the view from depth ~6 to ~16, the second 1e-3 behind the first along the view axis and
listed first (drawn first, so it keeps every pixel where a format stores the same depth for
both). Far is 1000; near sweeps so far/near runs over the ratios given. For every format and
rasterizer `rvr compare SCENE -r RASTERIZER,raytrace --mode visibility --depth-format F` gives
visibility.id_agreement; 1 - that is the mismatch rate. Writes depth_precision.json (every point)
and, with matplotlib, depth_precision.png.

  depth_precision.py --rvr build/bin/rvr --out bench/charts [--ratios 1e2,1e4,1e6] [--size 128]
  depth_precision.py ... --check   # exit 1 unless softraster's d24 fights at the largest ratio
                                   # (every fight classified depth_precision), nothing fights at
                                   # the smallest, d32f_reversed never does

softraster stores the exact window depth as the format would (its definition); GL's curve is
what llvmpipe does: it computes window z in float from clipped vertices and interpolates it in
float before storing, and those errors are correlated between the two parallel planes, so its
d24 can order separations below the 24-bit step here and mis-order some above it (a sweep of the
separation shows both).
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

FORMATS = ["d24", "d32f", "d32f_reversed"]
RASTERIZERS = ["raster", "softraster"]
FAR = 1000.0
SEPARATION = 1e-3


def scene(near, size):
    # Plane z = -(11 + 0.5 x): depth 11 at the centre, the view (30 deg) spans x = +-3 or so.
    def plane(shift):
        def z(x):
            return -(11.0 + 0.5 * x + shift)
        return [[-40.0, -40.0, z(-40.0)], [40.0, -40.0, z(40.0)], [0.0, 60.0, z(0.0)]]
    return {
        "format": "rvr-scene/1",
        "image": {"width": size, "height": size},
        "camera": {"eye": [0, 0, 0], "target": [0, 0, -1], "up": [0, 1, 0], "fov_y_deg": 30,
                   "near": near, "far": FAR},
        "lights": [{"type": "point", "position": [0, 0, 0], "intensity": [1, 1, 1]}],
        "objects": [
            {"name": "behind", "type": "triangle", "vertices": plane(SEPARATION)},
            {"name": "front", "type": "triangle", "vertices": plane(0.0)},
        ],
    }


def mismatch(rvr, work, near, size, rasterizer, fmt):
    path = os.path.join(work, "scene.json")
    with open(path, "w") as f:
        json.dump(scene(near, size), f)
    out = os.path.join(work, f"{rasterizer}-{fmt}-{near:g}")
    cmd = [rvr, "compare", path, "-r", f"{rasterizer},raytrace", "--mode", "visibility",
           "--depth-format", fmt, "--quiet", "-o", out]
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode not in (0, 1):
        sys.exit(f"error: {' '.join(cmd)}: exit {done.returncode}: {done.stderr.strip()}")
    with open(os.path.join(out, "metrics.json")) as f:
        metrics = json.load(f)
    visibility = metrics["visibility"]
    pixels = max(1, visibility["pixels"])
    classes = {k: v / pixels for k, v in visibility["mismatch_classes"].items()}
    return 1.0 - visibility["id_agreement"], classes


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rvr", required=True)
    ap.add_argument("--out", required=True, help="folder for depth_precision.json/.png")
    ap.add_argument("--ratios", default="1e2,1e3,1e4,1e5,1e6,1e7")
    ap.add_argument("--size", type=int, default=128)
    ap.add_argument("--check", action="store_true")
    args = ap.parse_args()
    ratios = [float(r) for r in args.ratios.split(",")]
    os.makedirs(args.out, exist_ok=True)
    points = []
    with tempfile.TemporaryDirectory() as work:
        for rasterizer in RASTERIZERS:
            for fmt in FORMATS:
                for ratio in ratios:
                    rate, classes = mismatch(args.rvr, work, FAR / ratio, args.size, rasterizer,
                                             fmt)
                    points.append({"rasterizer": rasterizer, "format": fmt, "far_over_near": ratio,
                                   "near": FAR / ratio, "mismatch": rate, "classes": classes})
                    shown = "  ".join(f"{k} {v:.3f}" for k, v in classes.items() if v > 0)
                    print(f"{rasterizer:10s} {fmt:14s} far/near {ratio:8.0e}  mismatch {rate:.5f}"
                          f"  {shown}")
    with open(os.path.join(args.out, "depth_precision.json"), "w") as f:
        json.dump({"far": FAR, "separation": SEPARATION, "size": args.size, "points": points}, f,
                  indent=1)
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, (ax, ax_classes) = plt.subplots(1, 2, figsize=(12, 4.5))
        for rasterizer, style in zip(RASTERIZERS, ["-", "--"]):
            for fmt, colour in zip(FORMATS, ["tab:red", "tab:orange", "tab:blue"]):
                mine = [p for p in points if p["rasterizer"] == rasterizer and p["format"] == fmt]
                xs = [p["far_over_near"] for p in mine]
                ax.plot(xs, [p["mismatch"] for p in mine], style, color=colour, marker="o",
                        label=f"{rasterizer} {fmt}")
                # The classes: a tie within the format's depth resolution, or beyond it.
                ax_classes.plot(xs, [p["classes"].get("depth_precision", 0.0) for p in mine],
                                style, color=colour, marker="o",
                                label=f"{rasterizer} {fmt} depth_precision")
                ax_classes.plot(xs, [p["classes"].get("occlusion", 0.0) for p in mine], style,
                                color=colour, marker="x", label=f"{rasterizer} {fmt} occlusion")
        for a in (ax, ax_classes):
            a.set_xscale("log")
            a.set_xlabel("far / near (far = 1000)")
            a.grid(True, alpha=0.3)
        ax.set_ylabel("id mismatch vs raytrace")
        ax.set_title(f"z-fighting: two planes {SEPARATION:g} apart at depth 6-16")
        ax.legend(fontsize=8)
        ax_classes.set_ylabel("fraction of pixels")
        ax_classes.set_title("mismatch classes: depth_precision (o), occlusion (x)")
        ax_classes.legend(fontsize=6)
        fig.tight_layout()
        fig.savefig(os.path.join(args.out, "depth_precision.png"), dpi=110)
    except ImportError:
        print("matplotlib missing: no chart")
    if args.check:
        def rate(r, f, ratio):
            return next(p["mismatch"] for p in points
                        if p["rasterizer"] == r and p["format"] == f and p["far_over_near"] == ratio)
        problems = []
        # softraster's d24 is the format's definition, so it must fight; GL's is measured only
        # (llvmpipe resolves more than 24 bits' worth here: see the chart).
        if rate("softraster", "d24", ratios[-1]) < 0.2:
            problems.append(f"softraster d24 does not fight at far/near {ratios[-1]:g}")
        # Its fights are ties within the format's resolution, so compare must call them
        # depth_precision, never occlusion.
        fights = next(p for p in points if p["rasterizer"] == "softraster" and
                      p["format"] == "d24" and p["far_over_near"] == ratios[-1])
        if abs(fights["classes"].get("depth_precision", 0.0) - fights["mismatch"]) > 1e-9:
            problems.append(f"softraster d24's fights at far/near {ratios[-1]:g} are not all "
                            f"depth_precision: {fights['classes']}")
        for r in RASTERIZERS:
            for f in FORMATS:
                if rate(r, f, ratios[0]) > 0.0:
                    problems.append(f"{r} {f} fights at far/near {ratios[0]:g}")
            for ratio in ratios:
                if rate(r, "d32f_reversed", ratio) > 0.0:
                    problems.append(f"{r} d32f_reversed fights at far/near {ratio:g}")
        for p in problems:
            print("FAIL:", p)
        return 1 if problems else 0
    return 0


if __name__ == "__main__":
    sys.exit(main())
