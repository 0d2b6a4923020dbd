#!/usr/bin/env python3
"""Charts from an rvr_bench JSON file (Google Benchmark's --benchmark_out format).

usage: plot.py RESULTS.json OUT_DIR [FORCED_ISA_RESULTS.json]
Writes frame_vs_triangles.png, depth_complexity.png, effects.png, effects.md (each technique's cost
and error), hybrid_wins.png, ours_vs_embree.png, threads.png and targets.md (the performance
targets, each a ratio of figures from one run; with a third file, a run with our kernels forced
by RVR_ISA, its column beside the first), and prints the targets.
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
    medians = [dict(b, name=b["run_name"]) for b in data["benchmarks"]
               if b.get("run_type") == "aggregate" and b.get("aggregate_name") == "median"]
    if medians:  # --benchmark_repetitions: the median of each benchmark
        return data.get("context", {}), medians
    rows = [b for b in data["benchmarks"] if b.get("run_type", "iteration") == "iteration"]
    return data.get("context", {}), rows


def ms(b):
    scale = {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}[b.get("time_unit", "ns")]
    return b["real_time"] * scale


def parts(b):
    return b["name"].replace("/real_time", "").split("/")


def subtitle(context):
    return f'{context.get("date", "")}, {context.get("num_cpus", "?")} CPUs at {context.get("mhz_per_cpu", "?")} MHz'


def sweep_series(rows, family, scene):
    """A frame sweep's rows at 1024x768 (BM_Frame, BM_Visibility): {renderer: [(n, ms)]}, sorted."""
    series = defaultdict(list)
    for b in rows:
        p = parts(b)
        if p[0] == family and len(p) == 5 and p[2] == scene and p[4] == "1024":
            series[p[1]].append((int(p[3]), ms(b)))
    return {name: sorted(pts) for name, pts in sorted(series.items())}


def frame_vs_triangles(rows, context, out):
    """Whole frames (BM_Frame) per scene and, below them when the run has BM_Visibility, the
    same frames with ids and depth only: the loop without the shading, on the same axes."""
    families = [("BM_Frame", "frame time (ms)", "")]
    if any(parts(b)[0] == "BM_Visibility" for b in rows):
        families.append(("BM_Visibility", "visibility-only frame time (ms)", ", ids + depth only"))
    scenes = ["tessphere", "soup"]
    series = {(f, s): sweep_series(rows, f, s) for f, _, _ in families for s in scenes}
    names = sorted({name for by_name in series.values() for name in by_name})
    colours = {name: f"C{i % 10}" for i, name in enumerate(names)}  # one colour per renderer
    fig, axes = plt.subplots(len(families), 2, figsize=(12, 4.5 * len(families)), sharex=True,
                             sharey=True, squeeze=False)
    for row, (family, ylabel, what) in enumerate(families):
        for ax, scene in zip(axes[row], scenes):
            for name, pts in series[(family, scene)].items():
                ax.plot([x for x, _ in pts], [y for _, y in pts], marker="o", color=colours[name],
                        label=name)
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_title(f"{scene}, 1024x768{what}")
            ax.grid(True, which="both", alpha=0.3)
        axes[row][0].set_ylabel(ylabel)
    for ax in axes[-1]:
        ax.set_xlabel("triangles")
    legend_axes = [ax for ax in axes.flat if ax.get_legend_handles_labels()[1]]
    if legend_axes:
        legend_axes[0].legend()
    fig.suptitle("Frame time vs triangles: z-buffer vs ray tracing (" + subtitle(context) + ")")
    fig.tight_layout()
    fig.savefig(out / "frame_vs_triangles.png", dpi=100)


def plot_renderers_against_n(ax, rows, family):
    """One line per renderer of `family`'s rows named <family>/<renderer>/<N>: frame time
    against N. Returns how many lines were drawn."""
    series = defaultdict(list)
    for b in rows:
        p = parts(b)
        if p[0] == family and len(p) >= 3:
            series[p[1]].append((int(p[2]), ms(b)))
    for name, pts in sorted(series.items()):
        pts.sort()
        ax.plot([x for x, _ in pts], [y for _, y in pts], marker="o", label=name)
    return len(series)


def depth_complexity(rows, context, out):
    """Front to back (hi-z can skip what is hidden) and back to front (it cannot), side by side."""
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.5), sharey=True)
    for ax, family, title in [(axes[0], "BM_DepthComplexity", "drawn front to back"),
                              (axes[1], "BM_DepthComplexityBackToFront", "drawn back to front")]:
        plot_renderers_against_n(ax, rows, family)
        ax.set_xscale("log", base=2)
        ax.set_xlabel("depth complexity N (occluders:N, 512x384)")
        ax.set_title(title)
        ax.grid(True, alpha=0.3)
    axes[0].set_ylabel("frame time (ms)")
    axes[0].legend()
    fig.suptitle("Hidden surfaces: the z-buffer pays for them unless hi-z skips them (" + subtitle(context) + ")")
    fig.tight_layout()
    fig.savefig(out / "depth_complexity.png", dpi=100)


def mirrors(rows, context, out):
    """Frame time against the number of mirrors: flat ones (BM_Mirrors: the tracer pays per mirror
    pixel, a z-buffer a whole view per mirror) and curved ones (BM_CurvedMirrors: a z-buffer a
    cube map, six views, per ball); where the lines cross is the crossover."""
    fig, axes = plt.subplots(1, 2, figsize=(13, 4.5))
    for ax, family, label, title in [
            (axes[0], "BM_Mirrors", "flat mirrors N (mirrors:N, 640x480, full mode)",
             "flat: a ray per mirror pixel vs a view per mirror"),
            (axes[1], "BM_CurvedMirrors", "mirror balls N (mirror_balls:N, 640x480, full mode)",
             "curved: a ray per mirror pixel vs a cube map per ball")]:
        drawn = plot_renderers_against_n(ax, rows, family)
        ax.set_xscale("log", base=2)
        ax.set_yscale("log")
        ax.set_xlabel(label)
        ax.set_ylabel("frame time (ms)")
        ax.set_title(title)
        ax.grid(True, alpha=0.3)
        if drawn:
            ax.legend()
        else:
            ax.text(0.5, 0.5, "no " + family + " rows", ha="center", va="center",
                    transform=ax.transAxes)
    fig.suptitle("Mirrors: the tracer's rays vs the z-buffer's views (" + subtitle(context) + ")")
    fig.tight_layout()
    fig.savefig(out / "mirrors.png", dpi=100)


def effect_rows(rows):
    """BM_Effects medians in ms: {renderer: {effect: ms}}, renderer raytrace, hybrid, hybrid_soft,
    and the z-buffers' techniques as "raster (accumulation)" (BM_Effects/<zbuffer>/<effect>/<technique>)."""
    table = defaultdict(dict)
    for b in rows:
        p = parts(b)
        if p[0] != "BM_Effects":
            continue
        if len(p) == 2:
            table["raytrace"][p[1]] = ms(b)
        elif len(p) == 3:
            table[p[1]][p[2]] = ms(b)
        elif len(p) == 4:
            table[f"{p[1]} ({p[3]})"][p[2]] = ms(b)
    return {r: dict(sorted(e.items(), key=lambda kv: effect_rank(kv[0]))) for r, e in table.items()}


# Registration order (the JSON's is the random interleaving's): cheapest effect first.
EFFECT_ORDER = (["primary", "hard_shadows", "area_light_4x4"] + [f"mirror_depth_{d}" for d in range(1, 6)]
                + ["planar_mirror", "curved_mirror", "glass", "clear_pane", "dof_16", "csg"])


def effect_rank(effect):
    return EFFECT_ORDER.index(effect) if effect in EFFECT_ORDER else len(EFFECT_ORDER)


def effects_table(rows, context, out):
    """effects.md: per effect, each technique's frame time, its ratio to the tracer's frame with
    that effect (BM_Effects/<effect>), and its error against the tracer's frame: the PSNR inside
    the effect's mask (effect_psnr_db: reflection, refraction, lens, csg) and over the whole image
    (psnr_db), as rvr_bench measures them once per row. Cost and error on one page."""
    tracer = {}
    techniques = defaultdict(list)
    for b in rows:
        p = parts(b)
        if p[0] != "BM_Effects":
            continue
        if len(p) == 2:
            tracer[p[1]] = ms(b)
        elif len(p) in (3, 4):
            label = p[1] if len(p) == 3 else f"{p[1]} ({p[3]})"
            techniques[p[2]].append((label, ms(b), b.get("effect_psnr_db"), b.get("psnr_db")))

    def db(v):
        return "-" if v is None else ("identical" if v >= 999 else f"{v:.1f}")

    lines = [f"# What each technique costs and how far it is from the tracer ({subtitle(context)})", "",
             "cornell, 640x480, full mode (`primary`: local mode) (`BM_Effects`); PSNR against the tracer's frame, linear RGB, "
             "peak 1: inside the effect's mask where it has one, and over the whole image.", "",
             "Shading: the tracer and the hybrids shade their hits on matt materials with the SIMD shading kernels, "
             "a block at a time (shadow rays traced between the kernel's two passes); `softraster`'s shadow-map pass "
             "still adds its light samples pixel by pixel (scalar), a small part of a frame that drawing its cube maps "
             "dominates; `raster` shades in its GLSL fragment shader.", "",
             "| effect | renderer (technique) | ms | × tracer | PSNR in mask (dB) | PSNR image (dB) |",
             "|---|---|---|---|---|---|"]
    for effect in sorted(set(tracer) | set(techniques), key=lambda e: (effect_rank(e), e)):
        if effect in tracer:
            lines.append(f"| {effect} | raytrace | {tracer[effect]:.1f} | 1 | reference | reference |")
        for label, t, mask_db, image_db in sorted(techniques.get(effect, [])):
            ratio = f"{t / tracer[effect]:.2f}" if effect in tracer else "-"
            lines.append(f"| {effect} | {label} | {t:.1f} | {ratio} | {db(mask_db)} | {db(image_db)} |")
    text = "\n".join(lines) + "\n"
    (out / "effects.md").write_text(text)


HYBRIDS = [("hybrid", "tab:blue", "hybrid (GL z-buffer + rays)"),
           ("hybrid_soft", "tab:green", "hybrid_soft (softraster + rays)")]


def effects(rows, context, out):
    """Each effect's frame time relative to the tracer's primary-rays-only frame: the tracer
    (BM_Effects/<effect>) and, beside it, the hybrids (BM_Effects/hybrid[_soft]/<effect>): where a
    hybrid's bar is lower, the z-buffer's primary visibility paid off."""
    table = effect_rows(rows)
    tracer = table.get("raytrace", {})
    if "primary" not in tracer:
        return
    names = list(tracer)
    series = [("raytrace", "tab:orange", "raytrace")] + [h for h in HYBRIDS if table.get(h[0])]
    # The z-buffers' answers to the effects they render, technique by technique.
    hybrid_names = {"raytrace"} | {h[0] for h in HYBRIDS}
    zbuffer_colours = ["tab:purple", "tab:brown", "tab:pink", "tab:gray", "tab:olive", "tab:cyan"]
    series += [(key, zbuffer_colours[i % len(zbuffer_colours)], key)
               for i, key in enumerate(sorted(k for k in table if k not in hybrid_names))]
    width = 0.8 / len(series)
    fig, ax = plt.subplots(figsize=(10, 4.5))
    for i, (key, colour, label) in enumerate(series):
        offset = (i - (len(series) - 1) / 2) * width
        ax.bar([x + offset for x in range(len(names))],
               [table[key].get(n, float("nan")) / tracer["primary"] for n in names], width,
               color=colour,
               label=label)
    ax.legend()
    ax.set_xticks(list(range(len(names))))
    ax.set_xticklabels(names)
    ax.set_ylabel("frame time / tracer's primary-only frame")
    ax.set_title("What each effect costs on cornell (640x480)\n" + subtitle(context))
    ax.tick_params(axis="x", rotation=40)
    ax.grid(True, axis="y", alpha=0.3)
    fig.tight_layout()
    fig.savefig(out / "effects.png", dpi=100)


def hybrid_split(rows):
    """The hybrids' time split from their counters, where the run has them (zbuffer_ms: the
    z-buffer passes, trace_ms: the tracer's part): per effect {hybrid: {effect: zbuffer_ms}} and
    per frame {(hybrid, scene): [(n, zbuffer_ms / (zbuffer_ms + trace_ms))]} at 1024x768."""
    effects, frames = defaultdict(dict), defaultdict(list)
    for b in rows:
        p = parts(b)
        if "zbuffer_ms" not in b or "trace_ms" not in b:
            continue
        if p[0] == "BM_Effects" and len(p) == 3:
            effects[p[1]][p[2]] = b["zbuffer_ms"]
        elif p[0] == "BM_Frame" and len(p) == 5 and p[4] == "1024":
            total = b["zbuffer_ms"] + b["trace_ms"]
            if total > 0:
                frames[(p[1], p[2])].append((int(p[3]), b["zbuffer_ms"] / total))
    return effects, {k: sorted(v) for k, v in frames.items()}


def hybrid_effects_panel(ax, table, hybrids, zbuffer_ms):
    """Per effect: each hybrid's time over the tracer's; hatched, the z-buffer's part of it."""
    tracer = table.get("raytrace", {})
    names = [n for n in tracer if any(n in table.get(h[0], {}) for h in hybrids)]
    width = 0.8 / len(hybrids)
    hatch_label = "z-buffer passes (hatched)"
    for i, (key, colour, label) in enumerate(hybrids):
        xs = [x + (i - (len(hybrids) - 1) / 2) * width for x in range(len(names))]
        ratios = [table.get(key, {}).get(n, float("nan")) / tracer[n] for n in names]
        bars = ax.bar(xs, ratios, width, color=colour, label=label)
        ax.bar_label(bars, labels=[f"{r:.2f}" for r in ratios], fontsize=7, rotation=90,
                     padding=2)
        if zbuffer_ms.get(key):
            parts_ = [zbuffer_ms[key].get(n, float("nan")) / tracer[n] for n in names]
            ax.bar(xs, parts_, width, fill=False, hatch="///", edgecolor=(0, 0, 0, 0.45), linewidth=0,
                   label=hatch_label)
            hatch_label = None
    ax.axhline(1.0, color="black", linewidth=1)
    ax.set_xticks(list(range(len(names))))
    ax.set_xticklabels(names)
    ax.tick_params(axis="x", rotation=40)
    ax.set_ylabel("hybrid time / raytrace time (below 1: the hybrid wins)")
    ax.set_title("per effect, cornell 640x480 (full mode)")
    ax.grid(True, axis="y", alpha=0.3)
    ax.legend(fontsize=8)


def hybrid_frames_panel(ax, frames, hybrids):
    """Per frame against triangles: each hybrid's time over the tracer's, per scene."""
    for key, colour, label in hybrids:
        for scene, style in (("tessphere", "-"), ("soup", "--")):
            ours, base = frames.get((key, scene), {}), frames.get(("raytrace", scene), {})
            pts = sorted((n, ours[n] / base[n]) for n in ours if n in base)
            if pts:
                ax.plot([n for n, _ in pts], [r for _, r in pts], style, marker="o", color=colour,
                        label=f"{key} {scene}")
    ax.axhline(1.0, color="black", linewidth=1)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("triangles")
    ax.set_title("per frame vs triangles, 1024x768 (local mode)")
    ax.grid(True, which="both", alpha=0.3)
    if ax.get_legend_handles_labels()[1]:
        ax.legend(fontsize=8)


def hybrid_split_panel(ax, shares, hybrids):
    """Per frame against triangles: the z-buffer's share of each hybrid's z-buffer + trace time."""
    for key, colour, label in hybrids:
        for scene, style in (("tessphere", "-"), ("soup", "--")):
            pts = shares.get((key, scene), [])
            if pts:
                ax.plot([n for n, _ in pts], [f for _, f in pts], style, marker="o", color=colour,
                        label=f"{key} {scene}")
    ax.set_xscale("log")
    ax.set_ylim(0, 1)
    ax.set_xlabel("triangles")
    ax.set_ylabel("zbuffer_ms / (zbuffer_ms + trace_ms)")
    ax.set_title("z-buffer's share of the hybrid's frame, 1024x768 (local mode)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)


def hybrid_wins(rows, context, out):
    """Where the third loop order wins: each hybrid's frame time over the tracer's on the same
    frame, per effect (cornell 640x480) and against triangle count (1024x768, local mode).
    Below 1 the hybrid is faster, and the bar or point says by how much. Where the run has the
    hybrids' zbuffer_ms and trace_ms counters, the split of their time: hatched in the effect
    bars, and a third panel with the z-buffer's share of each frame."""
    table = effect_rows(rows)
    frames = defaultdict(dict)  # (renderer, scene) -> {n: ms}
    for b in rows:
        p = parts(b)
        if p[0] == "BM_Frame" and len(p) == 5 and p[4] == "1024":
            frames[(p[1], p[2])][int(p[3])] = ms(b)
    hybrids = [h for h in HYBRIDS if table.get(h[0]) or any(k[0] == h[0] for k in frames)]
    if not hybrids or not (table.get("raytrace") or any(k[0] == "raytrace" for k in frames)):
        return
    zbuffer_ms, shares = hybrid_split(rows)
    fig, axes = plt.subplots(1, 3 if shares else 2, figsize=(19 if shares else 13, 4.8))
    hybrid_effects_panel(axes[0], table, hybrids, zbuffer_ms)
    hybrid_frames_panel(axes[1], frames, hybrids)
    if shares:
        hybrid_split_panel(axes[2], shares, hybrids)
    fig.suptitle("Where the hybrid (z-buffer for primary visibility, rays for the rest) wins (" +
                 subtitle(context) + ")")
    fig.tight_layout()
    fig.savefig(out / "hybrid_wins.png", dpi=100)


def ours_vs_embree(rows, context, out):
    """Traversal (single rays and packets) and build: bvh2, bvh and Embree side by side."""
    trace, packet, build = {}, {}, {}
    for b in rows:
        p = parts(b)
        if p[0] == "BM_Trace":
            trace[(p[1], p[2], p[3])] = b.get("rays/s", 0) / 1e6
        if p[0] == "BM_TracePacket":
            packet[(p[1], p[2])] = b.get("rays/s", 0) / 1e6
        if p[0] == "BM_Build":
            build[(p[1], int(p[2]))] = b.get("prims/s", 0) / 1e6
    fig, (ax1, ax2, ax3) = plt.subplots(1, 3, figsize=(17, 4.8), gridspec_kw={"width_ratios": [3, 1.4, 2]})
    cases = sorted({(r, s) for (_, r, s) in trace})
    xs = range(len(cases))
    accels = ["bvh2", "bvh", "embree"]
    for i, accel in enumerate(accels):
        ax1.bar([x + 0.27 * i for x in xs], [trace.get((accel, r, s), 0) for r, s in cases], 0.27, label=accel)
    ax1.set_xticks([x + 0.27 for x in xs], [f"{r}\n{s}" for r, s in cases])
    ax1.set_yscale("log")
    ax1.set_ylabel("Mrays/s, one thread (log)")
    ax1.set_title("Closest hit, single rays:\nbinary BVH, wide SIMD BVH, rtcIntersect1")
    ax1.legend()
    scenes = sorted({s for (_, s) in packet})
    for i, accel in enumerate(["bvh", "embree"]):
        ax2.bar([x + 0.4 * i for x in range(len(scenes))], [packet.get((accel, s), 0) for s in scenes], 0.4,
                label="our packets" if accel == "bvh" else "rtcIntersect8/16")
    ax2.set_xticks([x + 0.2 for x in range(len(scenes))], scenes)
    ax2.set_ylabel("Mrays/s, one thread")
    ax2.set_title("Primary rays as packets\n(8x8 tiles)")
    ax2.legend()
    sizes = sorted({n for (_, n) in build})
    for accel in ["bvh2", "bvh", "embree_medium", "embree_high"]:
        if any((accel, n) in build for n in sizes):
            ax3.plot(sizes, [build.get((accel, n), 0) for n in sizes], marker="o", label=accel)
    ax3.set_xscale("log")
    ax3.set_xlabel("triangles (soup)")
    ax3.set_ylabel("Mprims/s, one thread")
    ax3.set_title("BVH build")
    ax3.legend()
    kernels = f'our kernels {context.get("rvr_kernel", "?")}, Embree {context.get("embree_kernel", "?")}'
    fig.suptitle("Ours vs Embree (" + subtitle(context) + "; " + kernels + ")")
    fig.tight_layout()
    fig.savefig(out / "ours_vs_embree.png", dpi=100)


def threads(rows, context, out):
    series = defaultdict(dict)
    for b in rows:
        p = parts(b)
        if p[0] == "BM_Threads":
            series[p[1]][int(p[2])] = ms(b)
    if not series:
        return
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    names = sorted(series)
    for i, name in enumerate(names):
        t1 = series[name].get(1)
        counts = sorted(series[name])
        ax.bar([c + 0.35 * i for c in counts], [t1 / series[name][c] if t1 else 0 for c in counts], 0.35,
               label=name)
    ax.axhline(1.9, color="grey", linestyle="--", label="target 1.9x at 2 threads")
    ax.set_xticks([1.175, 2.175], ["1 thread", "2 threads"])
    ax.set_ylabel("speed-up over one thread")
    ax.set_title("Parallel scaling, tessphere:100000 at 1024x768\n" + subtitle(context))
    ax.legend()
    ax.grid(True, axis="y", alpha=0.3)
    fig.tight_layout()
    fig.savefig(out / "threads.png", dpi=100)


def target_checks(rows, context):
    """Each performance target as (what, measured, wanted, met), from one run's rows: issue 37's
    targets for both loop orders, and the thread scaling and AOV cost kept from earlier issues."""
    by_name = {b["name"].replace("/real_time", ""): b for b in rows}

    def value(name, key=None):
        b = by_name.get(name)
        if b is None:
            return None
        return b.get(key) if key else ms(b)

    def ratio(a, b):
        return a / b if a and b else None

    checks = []

    def at_least(what, v, want):
        checks.append((what, v, f">= {want:g}", v is not None and v >= want))

    def at_most(what, v, want):
        checks.append((what, v, f"<= {want:g}", v is not None and v <= want))

    def reference(what, v):  # a figure a target is read against, with no target of its own
        checks.append((what, v, "(reference)", None))

    kernel = context.get("rvr_kernel", "?")
    tps = value("BM_Frame/softraster/tessphere/1000000/1024", "triangles/s")
    at_least("BM_Frame softraster tessphere/1000000/1024: triangles/s (millions)",
             tps and tps / 1e6, 60 if kernel.startswith("avx512") else 30)
    for scene in ["tessphere/100000", "tessphere/1000000", "soup/1000000"]:
        at_most(f"BM_Frame {scene}/1024: softraster time / raster (llvmpipe) time",
                ratio(value(f"BM_Frame/softraster/{scene}/1024"), value(f"BM_Frame/raster/{scene}/1024")), 0.10)
    r = ratio(value("BM_Frame/softraster/tessphere/10000000/1024"), value("BM_Frame/softraster/tessphere/1000000/1024"))
    at_most("BM_Frame softraster tessphere 10^7 / 10^6 time", r, 12)
    for rays in ["primary", "random"]:
        for scene in ["tessphere/100000", "soup/1000000"]:
            at_least(f"BM_Trace {rays} {scene}: our wide BVH / Embree rtcIntersect1, rays/s",
                     ratio(value(f"BM_Trace/bvh/{rays}/{scene}", "rays/s"),
                           value(f"BM_Trace/embree/{rays}/{scene}", "rays/s")), 1.0)
    for scene in ["tessphere/100000", "soup/1000000"]:
        at_least(f"BM_TracePacket {scene}: our packets / Embree rtcIntersect8|16, rays/s",
                 ratio(value(f"BM_TracePacket/bvh/{scene}", "rays/s"),
                       value(f"BM_TracePacket/embree/{scene}", "rays/s")), 1.0)
    for n in ["100000", "1000000"]:
        at_least(f"BM_Build {n}: our wide BVH build / Embree MEDIUM, prims/s",
                 ratio(value(f"BM_Build/bvh/{n}", "prims/s"), value(f"BM_Build/embree_medium/{n}", "prims/s")), 1.0)
        at_most(f"BM_Build {n}: wide BVH bytes per triangle", value(f"BM_Build/bvh/{n}", "bytes/tri"), 48)
        reference(f"BM_Build {n}: Embree MEDIUM bytes per triangle (what its build keeps)",
                  value(f"BM_Build/embree_medium/{n}", "bytes/tri"))
    at_most("BM_Frame tessphere/100/1024: raytrace time / softraster time (the per-pixel fixed cost)",
            ratio(value("BM_Frame/raytrace/tessphere/100/1024"), value("BM_Frame/softraster/tessphere/100/1024")),
            1.5)
    for n in ["100", "10000", "100000"]:
        at_most(f"BM_Frame tessphere/{n}/1024: hybrid_soft time / raytrace time",
                ratio(value(f"BM_Frame/hybrid_soft/tessphere/{n}/1024"), value(f"BM_Frame/raytrace/tessphere/{n}/1024")),
                0.8)
    for effect in ["primary", "hard_shadows"]:
        at_most(f"BM_Effects {effect} (cornell): hybrid_soft time / raytrace time",
                ratio(value(f"BM_Effects/hybrid_soft/{effect}"), value(f"BM_Effects/{effect}")), 0.9)
    for name in ["raytrace", "softraster"]:
        at_least(f"BM_Threads/{name}: speed-up with 2 threads",
                 ratio(value(f"BM_Threads/{name}/1"), value(f"BM_Threads/{name}/2")), 1.9)
    at_most("BM_WriteAovs depth,id,normal,cost: writing the AOVs / rendering the frame (cornell 640x480)",
            value("BM_WriteAovs/depth,id,normal,cost", "write/render"), 1)
    return checks


# Measured outside make bench: a whole-process race against another program.
ELSEWHERE = [("end to end: POV-Ray 3.7 time / rvr time (bunny 1024x768, one thread each)", ">= 10",
              "bench/whole_process.sh")]


def targets(rows, context, out, forced=None):
    """targets.md: each target measured in this one run (ratios of figures from the same run), and
    beside it in a second run with our kernels forced (forced = (rows, context) of that run, or
    None)."""
    runs = [(rows, context)] + ([forced] if forced else [])
    columns = [target_checks(r, c) for r, c in runs]

    def shown(v):
        return "not run" if v is None else f"{v:.3g}"

    def met(v, ok):
        return "-" if v is None or ok is None else "yes" if ok else "no"

    header = "| target |"
    rule = "|---|"
    for _, c in runs:
        header += f" {c.get('rvr_kernel', '?')} | wanted | met |"
        rule += "---|---|---|"
    lines = [header, rule]
    for i, (what, _, _, _) in enumerate(columns[0]):
        line = f"| {what} |"
        for checks in columns:
            _, v, want, ok = checks[i]
            line += f" {shown(v)} | {want} | {met(v, ok)} |"
        lines.append(line)
    for what, want, where in ELSEWHERE:
        lines.append(f"| {what} |" + f" not run (`{where}`) | {want} | - |" * len(runs))
    lines.append("")
    for r, c in runs:
        lines.append(f'Run with our {c.get("rvr_kernel", "?")} kernels; Embree {c.get("embree_kernel", "?")} '
                     f'(Embree {c.get("embree_version", "?")}).')
    text = "\n".join(lines) + "\n"
    (out / "targets.md").write_text(text)
    print(text)


def main():
    if len(sys.argv) not in (3, 4):
        sys.exit(__doc__)
    context, rows = load(sys.argv[1])
    out = Path(sys.argv[2])
    out.mkdir(parents=True, exist_ok=True)
    for chart in (frame_vs_triangles, depth_complexity, effects, effects_table, mirrors, hybrid_wins,
                  ours_vs_embree, threads):
        chart(rows, context, out)
    forced = None
    if len(sys.argv) == 4:
        forced_context, forced_rows = load(sys.argv[3])
        forced = (forced_rows, forced_context)
    targets(rows, context, out, forced)
    print(f"wrote charts to {out}/")


if __name__ == "__main__":
    main()
