#!/usr/bin/python3
"""Runs bench/plot.py on two small synthetic rvr_bench JSON files and checks its charts.

1. A run as rvr_bench writes it now: BM_Frame and BM_Visibility rows (renderers, scenes, n at
   1024 wide), the phase counters (visibility_ms, shade_ms; the hybrids' zbuffer_ms and
   trace_ms), BM_Effects with the hybrids. Every chart is written; frame_vs_triangles.png has
   the visibility-only row of panels (twice the height) and hybrid_wins.png the z-buffer share
   panel (three panels wide).
2. An older run without BM_Visibility rows or phase counters, as repetitions' medians: every
   chart is still written, each with its old layout (one row; two panels).
3. The first run with a second one whose kernels were forced (RVR_ISA) and whose tracer is 1.5
   times slower: targets.md gives each target from each run, side by side, with the ratios the
   synthetic times make.

Usage: check_bench_plot.py --plot bench/plot.py [--work-dir DIR]
Exits 1 with one line per failure.
"""

import argparse
import json
import struct
import subprocess
import sys
import tempfile
from pathlib import Path

CHARTS = ["frame_vs_triangles.png", "depth_complexity.png", "effects.png", "effects.md",
          "mirrors.png",
          "hybrid_wins.png",
          "ours_vs_embree.png", "threads.png", "targets.md"]
FAILURES = []


def failure(message):
    FAILURES.append(message)
    print("FAIL: " + message)


def row(name, ms, median=False, **counters):
    """One benchmark row as Google Benchmark writes it (real time in ms)."""
    b = {"name": name + "/real_time", "run_name": name + "/real_time", "real_time": ms,
         "cpu_time": ms, "time_unit": "ms", "iterations": 3, **counters}
    if median:
        b.update(name=b["name"] + "_median", run_type="aggregate", aggregate_name="median")
    else:
        b["run_type"] = "iteration"
    return b


def synthetic_run(new):
    """A few rows of each chart's benchmarks; `new`: with BM_Visibility and phase counters."""
    rows = []
    for scene in ["tessphere", "soup"]:
        for n in [100, 10000, 1000000]:
            for r, ms in [("softraster", 20.0), ("raytrace", 60.0), ("hybrid_soft", 80.0)]:
                ms *= 1 + n / 1e5
                phases = {}
                if new and r.startswith("hybrid"):
                    phases = {"zbuffer_ms": ms / 4, "trace_ms": ms / 2}
                elif new:
                    phases = {"visibility_ms": ms / 3, "shade_ms": ms / 2}
                rows.append(row(f"BM_Frame/{r}/{scene}/{n}/1024", ms, not new, **phases))
                if new:
                    rows.append(row(f"BM_Visibility/{r}/{scene}/{n}/1024", ms / 2))
    for effect in ["primary", "hard_shadows"]:
        rows.append(row(f"BM_Effects/{effect}", 30.0, not new))
        rows.append(row(f"BM_Effects/hybrid_soft/{effect}", 40.0, not new, zbuffer_ms=10.0,
                        trace_ms=28.0))
    # A z-buffer's technique for an effect it renders (four parts: renderer, effect, technique),
    # with its error against the tracer (the whole image's only: shadows have no effect mask).
    rows.append(row("BM_Effects/softraster/hard_shadows/shadow_maps", 25.0, not new,
                    psnr_db=41.25))
    rows.append(row("BM_Effects/glass", 60.0, not new))
    rows.append(row("BM_Effects/raster/glass/cube_map", 90.0, not new, effect_psnr_db=18.22,
                    psnr_db=999.0))
    for n in [1, 16, 256]:
        rows.append(row(f"BM_Mirrors/raytrace/{n}", 30.0, not new))
        rows.append(row(f"BM_Mirrors/softraster/{n}", 5.0 * n, not new, mirror_views=float(n)))
        rows.append(row(f"BM_CurvedMirrors/raytrace/{n}", 30.0, not new))
        rows.append(row(f"BM_CurvedMirrors/softraster/{n}", 8.0 * n, not new,
                        cube_faces=6.0 * n))
    rows.append(row("BM_Threads/softraster/1", 50.0, not new))
    rows.append(row("BM_Threads/softraster/2", 27.0, not new))
    context = {"date": "2026-12-01T00:00:00+00:00", "num_cpus": 2, "mhz_per_cpu": 2445}
    return {"context": context, "benchmarks": rows}


def png_size(path):
    """(width, height) from a PNG's IHDR chunk."""
    data = path.read_bytes()[:24]
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        return None
    return struct.unpack(">II", data[16:24])


def check_run(plot, work, new):
    label = "new run" if new else "old run"
    json_path = work / f"{label.replace(' ', '_')}.json"
    json_path.write_text(json.dumps(synthetic_run(new)))
    out = work / label.replace(" ", "_")
    result = subprocess.run([sys.executable, str(plot), str(json_path), str(out)],
                            capture_output=True, text=True, timeout=100)
    if result.returncode != 0:
        failure(f"{label}: plot.py exited {result.returncode}: {result.stderr.strip()[-800:]}")
        return
    for chart in CHARTS:
        if not (out / chart).is_file() or (out / chart).stat().st_size == 0:
            failure(f"{label}: {chart} not written")
    # effects.md: each technique beside the tracer's frame with the same effect, cost and error.
    table = (out / "effects.md").read_text() if (out / "effects.md").is_file() else ""
    for want in ["| hard_shadows | softraster (shadow_maps) | 25.0 | 0.83 | - | 41.2 |",
                 "| glass | raster (cube_map) | 90.0 | 1.50 | 18.2 | identical |",
                 "| glass | raytrace | 60.0 | 1 | reference | reference |"]:
        if want not in table:
            failure(f"{label}: effects.md has no line {want!r}:\n{table}")
    frame = png_size(out / "frame_vs_triangles.png")
    hybrid = png_size(out / "hybrid_wins.png")
    # figsize x dpi 100: the frame chart 4.5 in a row of panels, the hybrid chart 13 or 19 wide.
    if frame and frame[1] != (900 if new else 450):
        failure(f"{label}: frame_vs_triangles.png is {frame[1]} px high: "
                f"{'no' if new else 'a'} visibility-only row")
    if hybrid and hybrid[0] != (1900 if new else 1300):
        failure(f"{label}: hybrid_wins.png is {hybrid[0]} px wide: "
                f"{'no' if new else 'a'} z-buffer share panel")


def check_forced(plot, work):
    label = "forced run"
    first, forced = synthetic_run(True), synthetic_run(True)
    first["context"]["rvr_kernel"] = "avx512 (chosen from the CPU)"
    forced["context"]["rvr_kernel"] = "avx2 (forced by RVR_ISA)"
    for b in forced["benchmarks"]:
        if b["name"].startswith("BM_Frame/raytrace/"):
            b["real_time"] *= 1.5
    paths = []
    for name, run in [("first", first), ("forced", forced)]:
        paths.append(work / f"{name}.json")
        paths[-1].write_text(json.dumps(run))
    out = work / "forced_run"
    result = subprocess.run([sys.executable, str(plot), str(paths[0]), str(out), str(paths[1])],
                            capture_output=True, text=True, timeout=100)
    if result.returncode != 0:
        failure(f"{label}: plot.py exited {result.returncode}: {result.stderr.strip()[-800:]}")
        return
    table = (out / "targets.md").read_text() if (out / "targets.md").is_file() else ""
    # At N = 100 the synthetic times are 20.02 (softraster), 60.06 (raytrace; 90.09 forced) and
    # 80.08 ms (hybrid_soft).
    for want in ["| target | avx512 (chosen from the CPU) | wanted | met | avx2 (forced by RVR_ISA) | wanted | met |",
                 "| BM_Frame tessphere/100/1024: raytrace time / softraster time (the per-pixel fixed cost) "
                 "| 3 | <= 1.5 | no | 4.5 | <= 1.5 | no |",
                 "| BM_Frame tessphere/100/1024: hybrid_soft time / raytrace time | 1.33 | <= 0.8 | no "
                 "| 0.889 | <= 0.8 | no |",
                 "not run (`bench/whole_process.sh`)"]:
        if want not in table:
            failure(f"{label}: targets.md has no line {want!r}:\n{table}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--plot", required=True, type=Path)
    parser.add_argument("--work-dir", type=Path)
    args = parser.parse_args()
    if args.work_dir:
        args.work_dir.mkdir(parents=True, exist_ok=True)
        work = args.work_dir
    else:
        work = Path(tempfile.mkdtemp(prefix="check_bench_plot_"))
    for new in (True, False):
        check_run(args.plot, work, new)
    check_forced(args.plot, work)
    if FAILURES:
        sys.exit(1)
    print(f"check_bench_plot: every chart written, panels as the rows say ({work})")


if __name__ == "__main__":
    main()
