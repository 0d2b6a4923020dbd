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
  depth_precision.py ... --check   # exit 1 unless softraster's d24 fights at the largest ratio,
                                   # nothing fights at the smallest, d32f_reversed never does
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
    return 1.0 - metrics["visibility"]["id_agreement"]


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
                    rate = mismatch(args.rvr, work, FAR / ratio, args.size, rasterizer, fmt)
                    points.append({"rasterizer": rasterizer, "format": fmt, "far_over_near": ratio,
                                   "near": FAR / ratio, "mismatch": rate})
                    print(f"{rasterizer:10s} {fmt:14s} far/near {ratio:8.0e}  mismatch {rate:.5f}")
    with open(os.path.join(args.out, "depth_precision.json"), "w") as f:
        json.dump({"far": FAR, "separation": SEPARATION, "size": args.size, "points": points}, f,
                  indent=1)
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(7, 4.5))
        for rasterizer, style in zip(RASTERIZERS, ["-", "--"]):
            for fmt, colour in zip(FORMATS, ["tab:red", "tab:orange", "tab:blue"]):
                xs = [p["far_over_near"] for p in points
                      if p["rasterizer"] == rasterizer and p["format"] == fmt]
                ys = [p["mismatch"] for p in points
                      if p["rasterizer"] == rasterizer and p["format"] == fmt]
                ax.plot(xs, ys, style, color=colour, marker="o", label=f"{rasterizer} {fmt}")
        ax.set_xscale("log")
        ax.set_xlabel("far / near (far = 1000)")
        ax.set_ylabel("id mismatch vs raytrace")
        ax.set_title(f"z-fighting: two planes {SEPARATION:g} apart at depth 6-16")
        ax.legend(fontsize=8)
        ax.grid(True, alpha=0.3)
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
