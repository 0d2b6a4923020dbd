# The arrays are views of the render's own buffers, kept alive by the arrays themselves; renders
# leak neither Python references nor memory.
import gc
import sys
import tracemalloc

import numpy as np

import rvr


def test_arrays_are_views_not_copies():
    r = rvr.render(rvr.Scene("builtin:cornell", width=16, height=12), "softraster", threads=1)
    first, second = r.depth, r.depth
    assert first is not second and not first.flags.owndata
    # Two reads of one buffer are two arrays over the same memory, not two copies.
    assert first.__array_interface__["data"][0] == second.__array_interface__["data"][0]
    assert not r.color.flags.writeable


def test_arrays_outlive_the_render():
    scene = rvr.Scene("builtin:cornell", width=64, height=48)
    r = rvr.render(scene, "raytrace", threads=1)
    depth, color, ids = r.depth, r.color, r.object_id
    kept = depth.copy(), color.copy(), ids.copy()
    del r
    gc.collect()
    # Freed pixel memory is recycled by the next render of the same size: a view that did not
    # hold its buffers would now show this other scene.
    other = rvr.Scene("builtin:tessphere", width=64, height=48)
    for _ in range(3):
        o = rvr.render(other, "raytrace", threads=1)
        _ = o.depth
    assert not np.array_equal(o.depth, kept[0])
    assert np.array_equal(depth, kept[0])
    assert np.array_equal(color, kept[1])
    assert np.array_equal(ids, kept[2])


def resident_bytes():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * 4096


def test_no_leaks_over_a_thousand_renders():
    scene = rvr.Scene("builtin:cornell", width=32, height=32)

    def one():
        r = rvr.render(scene, "softraster", threads=1)
        arrays = [r.color, r.depth, r.object_id, r.primitive_id, r.normal, r.cost]
        assert r.stats["width"] == 32 and isinstance(r.warnings, list)
        return sum(a.nbytes for a in arrays)

    for _ in range(50):  # pools and caches reach their size
        one()
    gc.collect()
    refs = sys.getrefcount(scene)
    objects = len(gc.get_objects())
    rss = resident_bytes()
    tracemalloc.start()
    before, _ = tracemalloc.get_traced_memory()
    per_render = 0
    for _ in range(1000):
        per_render = one()
    gc.collect()
    after, _ = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    assert sys.getrefcount(scene) == refs
    assert len(gc.get_objects()) <= objects + 10
    assert after - before < 64 * 1024
    # A render's buffers kept by mistake would add per_render bytes each: 1000 of them, 20 MB.
    assert resident_bytes() - rss < 200 * per_render
