#!/usr/bin/env python3
"""Writes the example meshes in this folder (standard library only, deterministic).

    python3 scenes/models/make_models.py        # rewrites the files beside this script

torus.obj    torus with per-vertex normals (OBJ, text)            2304 triangles
blob.ply     lumpy subdivided icosahedron, no normals (PLY, binary) 5120 triangles
vase.gltf    surface of revolution with normals, base64-embedded buffer and a node
             transform (glTF 2.0)                                    1536 triangles
crystal.3ds  twisted five-pointed star prism, flat (3DS)             ~300 triangles

Each model sits on y = 0 (its lowest point) and is about 1 unit across, so scenes only
translate and scale them.
"""

import base64
import json
import math
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))


def fmt(x):
    s = f"{x:.6f}".rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


# --------------------------------------------------------------------------- torus (OBJ)
def torus(major=0.5, minor=0.2, nu=48, nv=24):
    lines = ["# torus: major radius %s, minor radius %s, lying in the xz plane" % (major, minor),
             "# written by make_models.py", "o torus"]
    normals = []
    for i in range(nu):
        u = 2 * math.pi * i / nu
        for j in range(nv):
            v = 2 * math.pi * j / nv
            nx, ny, nz = math.cos(v) * math.cos(u), math.sin(v), math.cos(v) * math.sin(u)
            x = (major + minor * math.cos(v)) * math.cos(u)
            z = (major + minor * math.cos(v)) * math.sin(u)
            y = minor * math.sin(v) + minor  # rests on y = 0
            lines.append(f"v {fmt(x)} {fmt(y)} {fmt(z)}")
            normals.append(f"vn {fmt(nx)} {fmt(ny)} {fmt(nz)}")
    lines += normals

    def idx(i, j):
        return (i % nu) * nv + (j % nv) + 1

    for i in range(nu):
        for j in range(nv):
            a, b, c, d = idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)
            # counter-clockwise seen from outside
            lines.append(f"f {a}//{a} {d}//{d} {c}//{c}")
            lines.append(f"f {a}//{a} {c}//{c} {b}//{b}")
    return "\n".join(lines) + "\n"


# --------------------------------------------------------------------------- blob (PLY)
def icosphere(levels):
    t = (1 + math.sqrt(5)) / 2
    verts = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t),
             (0, -1, -t), (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    verts = [normalize(v) for v in verts]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
             (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
             (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(levels):
        cache = {}

        def mid(a, b):
            key = (min(a, b), max(a, b))
            if key not in cache:
                va, vb = verts[a], verts[b]
                verts.append(normalize(tuple((va[k] + vb[k]) / 2 for k in range(3))))
                cache[key] = len(verts) - 1
            return cache[key]

        new_faces = []
        for a, b, c in faces:
            ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
            new_faces += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        faces = new_faces
    return verts, faces


def normalize(v):
    n = math.sqrt(sum(c * c for c in v))
    return tuple(c / n for c in v)


def blob():
    verts, faces = icosphere(4)
    out = []
    for x, y, z in verts:
        # smooth lumps: a few low-frequency waves, radius 0.5 +- 0.1
        r = 0.5 * (1 + 0.12 * math.sin(3 * x + 1.3) * math.cos(2 * y - 0.4)
                   + 0.08 * math.sin(4 * z + 2 * x) + 0.06 * math.cos(5 * y + 3 * z))
        out.append((x * r, y * r * 0.85, z * r))
    low = min(p[1] for p in out)
    out = [(x, y - low, z) for x, y, z in out]
    header = ("ply\nformat binary_little_endian 1.0\ncomment lumpy blob, written by "
              "make_models.py\nelement vertex %d\nproperty float x\nproperty float y\n"
              "property float z\nelement face %d\nproperty list uchar int vertex_indices\n"
              "end_header\n" % (len(out), len(faces)))
    body = b"".join(struct.pack("<3f", *p) for p in out)
    body += b"".join(struct.pack("<B3i", 3, *f) for f in faces)
    return header.encode("ascii") + body


# --------------------------------------------------------------------------- vase (glTF)
def vase(segments=32, rings=24):
    # profile radius along height h in [0, 1]
    def radius(h):
        return 0.18 + 0.17 * math.sin(math.pi * (0.15 + 0.95 * h)) + 0.07 * h * h

    positions, normals, indices = [], [], []
    for j in range(rings + 1):
        h = j / rings
        r = radius(h)
        dr = (radius(min(1, h + 1e-3)) - radius(max(0, h - 1e-3))) / (
            min(1, h + 1e-3) - max(0, h - 1e-3))
        for i in range(segments + 1):
            a = 2 * math.pi * i / segments
            c, s = math.cos(a), math.sin(a)
            positions.append((r * c, h, r * s))
            n = normalize((c, -dr, s))
            normals.append(n)
    row = segments + 1
    for j in range(rings):
        for i in range(segments):
            a, b = j * row + i, j * row + i + 1
            c, d = (j + 1) * row + i + 1, (j + 1) * row + i
            indices += [a, d, c, a, c, b]
    # a flat bottom disc (its own vertices, normal -y)
    centre = len(positions)
    positions.append((0.0, 0.0, 0.0))
    normals.append((0.0, -1.0, 0.0))
    for i in range(segments + 1):
        a = 2 * math.pi * i / segments
        positions.append((radius(0) * math.cos(a), 0.0, radius(0) * math.sin(a)))
        normals.append((0.0, -1.0, 0.0))
    for i in range(segments):
        indices += [centre, centre + 1 + i, centre + 2 + i]

    pos_bytes = b"".join(struct.pack("<3f", *p) for p in positions)
    nrm_bytes = b"".join(struct.pack("<3f", *n) for n in normals)
    idx_bytes = b"".join(struct.pack("<H", i) for i in indices)
    while len(idx_bytes) % 4:
        idx_bytes += b"\0"
    buf = pos_bytes + nrm_bytes + idx_bytes
    lo = [min(p[k] for p in positions) for k in range(3)]
    hi = [max(p[k] for p in positions) for k in range(3)]
    doc = {
        "asset": {"version": "2.0", "generator": "rvr make_models.py"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        # The node scales the 1-unit-high vase to 1.2 units: importers must apply it.
        "nodes": [{"name": "vase", "mesh": 0, "scale": [1.2, 1.2, 1.2]}],
        "meshes": [{"name": "vase", "primitives": [
            {"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2, "mode": 4}]}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": len(positions), "type": "VEC3",
             "min": lo, "max": hi},
            {"bufferView": 1, "componentType": 5126, "count": len(normals), "type": "VEC3"},
            {"bufferView": 2, "componentType": 5123, "count": len(indices), "type": "SCALAR"},
        ],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": len(pos_bytes), "target": 34962},
            {"buffer": 0, "byteOffset": len(pos_bytes), "byteLength": len(nrm_bytes),
             "target": 34962},
            {"buffer": 0, "byteOffset": len(pos_bytes) + len(nrm_bytes),
             "byteLength": len(indices) * 2, "target": 34963},
        ],
        "buffers": [{"byteLength": len(buf), "uri": "data:application/octet-stream;base64,"
                     + base64.b64encode(buf).decode("ascii")}],
    }
    return json.dumps(doc, indent=1) + "\n"


# --------------------------------------------------------------------------- crystal (3DS)
def chunk(cid, payload):
    return struct.pack("<HI", cid, 6 + len(payload)) + payload


def crystal(points=5, layers=6):
    # A five-pointed star extruded upwards with a twist, capped top and bottom.
    outline = []
    for k in range(2 * points):
        a = math.pi * k / points
        r = 0.5 if k % 2 == 0 else 0.22
        outline.append((r * math.cos(a), r * math.sin(a)))
    n = len(outline)
    verts, faces = [], []
    for j in range(layers + 1):
        h = j / layers
        twist = 0.6 * h
        c, s = math.cos(twist), math.sin(twist)
        shrink = 1 - 0.35 * h
        for x, z in outline:
            verts.append(((x * c - z * s) * shrink, 1.1 * h, (x * s + z * c) * shrink))
    for j in range(layers):
        for i in range(n):
            a, b = j * n + i, j * n + (i + 1) % n
            c, d = (j + 1) * n + (i + 1) % n, (j + 1) * n + i
            faces += [(a, d, c), (a, c, b)]
    for cap, y, flip in ((0, 0.0, True), (layers, 1.1, False)):
        centre = len(verts)
        verts.append((0.0, y, 0.0))
        for i in range(n):
            a, b = cap * n + i, cap * n + (i + 1) % n
            faces.append((centre, a, b) if flip else (centre, b, a))
    # 3DS is z-up; Assimp turns it y-up with (x, y, z) -> (x, z, -y), so store (x, -z, y).
    vert_list = struct.pack("<H", len(verts)) + b"".join(
        struct.pack("<3f", x, -z, y) for x, y, z in verts)
    face_list = struct.pack("<H", len(faces)) + b"".join(
        struct.pack("<4H", a, b, c, 0) for a, b, c in faces)
    mesh = chunk(0x4100, chunk(0x4110, vert_list) + chunk(0x4120, face_list))
    obj = chunk(0x4000, b"crystal\0" + mesh)
    editor = chunk(0x3D3D, chunk(0x3D3E, struct.pack("<I", 3)) + obj)
    return chunk(0x4D4D, chunk(0x0002, struct.pack("<I", 3)) + editor)


def main():
    with open(os.path.join(HERE, "torus.obj"), "w") as f:
        f.write(torus())
    with open(os.path.join(HERE, "blob.ply"), "wb") as f:
        f.write(blob())
    with open(os.path.join(HERE, "vase.gltf"), "w") as f:
        f.write(vase())
    with open(os.path.join(HERE, "crystal.3ds"), "wb") as f:
        f.write(crystal())


if __name__ == "__main__":
    main()
