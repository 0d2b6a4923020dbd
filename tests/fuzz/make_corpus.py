#!/usr/bin/env python3
"""Writes the seed corpora: corpus/scene (valid scenes from scenes/ plus broken variants) and
corpus/mesh (small meshes; the first byte picks the extension, see fuzz_common.h)."""
import base64, json, os, struct

here = os.path.dirname(os.path.abspath(__file__))
root = os.path.dirname(os.path.dirname(here))
scene_dir = os.path.join(here, "corpus", "scene")
mesh_dir = os.path.join(here, "corpus", "mesh")
os.makedirs(scene_dir, exist_ok=True)
os.makedirs(mesh_dir, exist_ok=True)


def put(d, name, data):
    with open(os.path.join(d, name), "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())


# --- scenes -----------------------------------------------------------------------------------
for n in sorted(os.listdir(os.path.join(root, "scenes"))):
    if n.endswith(".json"):
        with open(os.path.join(root, "scenes", n), "rb") as f:
            text = f.read()
        put(scene_dir, n, text)
        put(scene_dir, "truncated_" + n, text[: len(text) // 2])

cam = {"eye": [0, 1, 4], "target": [0, 1, 0], "up": [0, 1, 0]}
full = {
    "format": "rvr-scene/1",
    "image": {"width": 64, "height": 48, "background": [0, 0, 0], "samples_per_pixel": 2},
    "camera": dict(cam, fov_y_deg=45, near=0.01, far=1000, aperture_radius=0.1, focus_distance=4),
    "ambient": [0.05, 0.05, 0.05],
    "materials": {
        "white": {"diffuse": [0.8, 0.8, 0.8]},
        "mirror": {"diffuse": [0.1, 0.1, 0.1], "specular": [0.9, 0.9, 0.9], "shininess": 200,
                   "mirror": 0.85},
        "glass": {"diffuse": [0, 0, 0], "transparency": 0.9, "ior": 1.5},
        "lamp": {"emission": [4, 4, 4]},
    },
    "lights": [
        {"type": "point", "position": [0, 3.9, 0], "intensity": [8, 8, 8]},
        {"type": "area", "corner": [-0.5, 3.99, -0.5], "edge_u": [1, 0, 0], "edge_v": [0, 0, 1],
         "intensity": [8, 8, 8], "samples": 4},
    ],
    "objects": [
        {"name": "ball", "type": "sphere", "center": [0, 1, 0], "radius": 1, "material": "mirror"},
        {"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "half_size": 10,
         "material": "white"},
        {"type": "triangle", "vertices": [[0, 0, 0], [1, 0, 0], [0, 1, 0]], "material": "white"},
        {"type": "mesh", "file": "models/crystal.3ds", "material": "glass", "smooth": True,
         "transform": {"scale": 2, "rotate_deg": [0, 30, 0], "translate": [1, 0, -1]}},
        {"type": "csg", "op": "difference", "material": "white",
         "a": {"type": "sphere", "center": [0, 1, 0], "radius": 1},
         "b": {"type": "csg", "op": "union",
               "a": {"center": [0.5, 1.5, 0.5], "radius": 0.6},
               "b": {"center": [0.5, 1.5, 0.5], "radius": 0.6}}},
        {"type": "sphere", "center": [3, 1, 0], "radius": 0.5,
         "transform": {"scale": [-2, 2, 2], "rotate_deg": [10, 20, 30]}},
    ],
}
put(scene_dir, "full.json", json.dumps(full, indent=1))
put(scene_dir, "minimal.json", json.dumps({"camera": cam, "objects": []}))
put(scene_dir, "empty.json", "")
put(scene_dir, "spaces.json", " \n\t ")
put(scene_dir, "trailing_comma.json", '{"camera": {"eye": [0,0,1], "target": [0,0,0],},}')
put(scene_dir, "duplicate_key.json", '{"camera": 1, "camera": 2}')
put(scene_dir, "deep.json", "[" * 600 + "]" * 600)
put(scene_dir, "overflow.json", json.dumps({"camera": cam}).replace("4]", "1e999]"))
put(scene_dir, "bad_utf8.json", b'{"objects": [{"type": "\xff\xfe"}]}')
put(scene_dir, "typo.json", json.dumps({"camera": cam, "objcts": []}))
bad = dict(full, objects=[{"type": "sphere", "center": [0, 1, 0], "radius": -1}])
put(scene_dir, "negative_radius.json", json.dumps(bad))
bad = dict(full, objects=[{"type": "mesh", "file": "models/missing.obj"}])
put(scene_dir, "missing_mesh.json", json.dumps(bad))
bad = dict(full, objects=[{"type": "mesh", "file": "models"}])
put(scene_dir, "mesh_is_dir.json", json.dumps(bad))
bad = dict(full, image={"width": 0, "height": 16385, "samples_per_pixel": 1.5})
put(scene_dir, "bad_image.json", json.dumps(bad))
bad = dict(full, camera={"eye": [0, 0, 0], "target": [0, 1, 0], "up": [0, 1, 0], "near": 2,
                         "far": 1})
put(scene_dir, "bad_camera.json", json.dumps(bad))
deep = {"center": [0, 0, 0], "radius": 1}
for _ in range(70):
    deep = {"op": "union", "a": deep, "b": {"center": [0, 0, 0], "radius": 1}}
put(scene_dir, "deep_csg.json", json.dumps(dict(deep, type="csg")))
put(scene_dir, "deep_csg_object.json", json.dumps({"camera": cam, "objects": [dict(deep, type="csg")]}))

# --- meshes -----------------------------------------------------------------------------------
EXT = ["obj", "ply", "gltf", "3ds", "stl", "off", "glb", "dae"]


def mesh(name, ext, data, smooth=False):
    put(mesh_dir, name, bytes([EXT.index(ext) + (len(EXT) if smooth else 0)]) +
        (data if isinstance(data, bytes) else data.encode()))


obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvn 0 0 1\nf 1//1 2//1 3//1\nf 2 4 3\n"
mesh("tri.obj", "obj", obj)
mesh("tri_smooth.obj", "obj", obj, True)
mesh("quad.obj", "obj", "o q\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\nl 1 2\np 3\n")
mesh("neg_index.obj", "obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -3\nf 1 2 9\n")
ply = ("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
       "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
       "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")
mesh("tri.ply", "ply", ply)
mesh("tri_smooth.ply", "ply", ply, True)
plyb = ("ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
        "property float y\nproperty float z\nelement face 1\n"
        "property list uchar int vertex_indices\nend_header\n").encode()
plyb += struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0) + struct.pack("<B3i", 3, 0, 1, 2)
mesh("tri_binary.ply", "ply", plyb)
buf = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0) + struct.pack("<3H", 0, 1, 2) + b"\0\0"
gltf = {
    "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
    "nodes": [{"mesh": 0, "translation": [0, 0, 1]}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
    "buffers": [{"byteLength": len(buf),
                 "uri": "data:application/octet-stream;base64," + base64.b64encode(buf).decode()}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36},
                    {"buffer": 0, "byteOffset": 36, "byteLength": 6}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                   "min": [0, 0, 0], "max": [1, 1, 0]},
                  {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}],
}
mesh("tri.gltf", "gltf", json.dumps(gltf))
with open(os.path.join(root, "scenes", "models", "crystal.3ds"), "rb") as f:
    mesh("crystal.3ds", "3ds", f.read())
mesh("tri.stl", "stl", "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
     "vertex 0 1 0\nendloop\nendfacet\nendsolid t\n")
stlb = b"\0" * 80 + struct.pack("<I", 1) + struct.pack("<12fH", 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0)
mesh("tri_binary.stl", "stl", stlb)
mesh("tri.off", "off", "OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n3 0 1 2\n3 1 3 2\n")
glb_json = json.dumps(dict(gltf, buffers=[{"byteLength": len(buf)}])).encode()
glb_json += b" " * (-len(glb_json) % 4)
glb = (struct.pack("<III", 0x46546C67, 2, 12 + 8 + len(glb_json) + 8 + len(buf)) +
       struct.pack("<II", len(glb_json), 0x4E4F534A) + glb_json +
       struct.pack("<II", len(buf), 0x004E4942) + buf)
mesh("tri.glb", "glb", glb)
mesh("tri.dae", "dae", """<?xml version="1.0"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
<library_geometries><geometry id="g"><mesh>
<source id="p"><float_array id="pa" count="9">0 0 0 1 0 0 0 1 0</float_array>
<technique_common><accessor source="#pa" count="3" stride="3"><param name="X" type="float"/>
<param name="Y" type="float"/><param name="Z" type="float"/></accessor></technique_common></source>
<vertices id="v"><input semantic="POSITION" source="#p"/></vertices>
<triangles count="1"><input semantic="VERTEX" source="#v" offset="0"/><p>0 1 2</p></triangles>
</mesh></geometry></library_geometries>
<library_visual_scenes><visual_scene id="s"><node><instance_geometry url="#g"/></node></visual_scene>
</library_visual_scenes><scene><instance_visual_scene url="#s"/></scene></COLLADA>
""")
mesh("empty.obj", "obj", "")
mesh("nan.obj", "obj", "v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
