#!/bin/bash
# Whole runs as a script sees them (issue 15): rvr's start-up, a bad input, a tiny render, and a
# 69,560-triangle OBJ at 1024x768 on one thread against POV-Ray 3.7 on the same mesh, camera and
# light (local shading: one shadowless point light and ambient, no anti-aliasing). Interleaved
# repetitions, medians of wall time. POV-Ray is optional (apt-get install povray).
# usage: bench/whole_process.sh [RVR_BINARY] [REPETITIONS]
set -euo pipefail
rvr=$(realpath "${1:-build/bin/rvr}")
n=${2:-11}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"

python3 - <<'PY'
# A UV sphere with a noisy radius, 187 x 188 grid: 69,560 triangles (the Stanford bunny's size).
import math, random
random.seed(1)
n_lat, n_lon = 186, 188
v = []
for i in range(n_lat + 1):
    th = math.pi * i / n_lat
    for j in range(n_lon):
        ph = 2 * math.pi * j / n_lon
        r = 1 + 0.03 * math.sin(7 * th) * math.cos(5 * ph) + 0.01 * random.random()
        v.append((r * math.sin(th) * math.cos(ph), r * math.cos(th), r * math.sin(th) * math.sin(ph)))
f = []
for i in range(n_lat):
    for j in range(n_lon):
        a, b = i * n_lon + j, i * n_lon + (j + 1) % n_lon
        c, d = a + n_lon, b + n_lon
        if i > 0: f.append((a, b, d))
        if i < n_lat - 1: f.append((a, d, c))
with open('model.obj', 'w') as o:
    o.writelines('v %.6f %.6f %.6f\n' % p for p in v)
    o.writelines('f %d %d %d\n' % (t[0] + 1, t[1] + 1, t[2] + 1) for t in f)
PY

have_povray=0
if command -v povray >/dev/null; then
  have_povray=1
  "$rvr" scenes --export model.obj -o exported.json
  python3 - <<'PY'
# The scene rvr frames for the model, as POV-Ray (left-handed: z negated) sees it.
import json, math
d = json.load(open('exported.json'))
c, light = d['camera'], d['lights'][0]
vec = lambda p: '<%r,%r,%r>' % (p[0], p[1], -p[2])
hfov = 2 * math.degrees(math.atan(math.tan(math.radians(c['fov_y_deg'] / 2)) * 4 / 3))
verts, faces = [], []
for line in open('model.obj'):
    p = line.split()
    if p and p[0] == 'v': verts.append(vec([float(x) for x in p[1:4]]))
    if p and p[0] == 'f': faces.append('<%d,%d,%d>' % tuple(int(x) - 1 for x in p[1:4]))
with open('model.pov', 'w') as o:
    o.write('global_settings { ambient_light rgb 1 assumed_gamma 1.0 }\n')
    o.write('camera { perspective location %s look_at %s right x*4/3 up y angle %r }\n'
            % (vec(c['eye']), vec(c['target']), hfov))
    o.write('light_source { %s color rgb 1 shadowless }\n' % vec(light['position']))
    o.write('mesh2 { vertex_vectors { %d, %s } face_indices { %d, %s }\n' %
            (len(verts), ','.join(verts), len(faces), ','.join(faces)))
    o.write('  texture { pigment { rgb 0.8 } finish { ambient 0.15 diffuse 0.8 } } }\n')
PY
fi

labels=("rvr --version" "rvr scenes" "rvr bad input" "rvr 64x48 cornell"
        "rvr OBJ 1024x768 1 thread")
cmds=("$rvr --version" "$rvr scenes" "$rvr render builtin:nope -r raytrace -o bad.png"
      "$rvr render builtin:cornell -r raytrace --image 64x48 -q -o c.png"
      "$rvr render model.obj -r raytrace --mode local --threads 1 --image 1024x768 -q -o rvr.png")
if [ $have_povray = 1 ]; then
  labels+=("povray OBJ 1024x768 1 thread")
  cmds+=("povray -D +WT1 +W1024 +H768 -A -GA +FN +Opov.png model.pov")
fi
for k in "${!cmds[@]}"; do : > "t$k"; done
for i in $(seq "$n"); do
  for k in "${!cmds[@]}"; do
    /usr/bin/time -f %e -a -o "t$k" bash -c "${cmds[$k]} >/dev/null 2>&1" || true
  done
done
median() { grep -E '^[0-9.]+$' "$1" | sort -n | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
for k in "${!cmds[@]}"; do
  printf '%-32s median %s s (min %s, %s runs)\n' "${labels[$k]}" "$(median "t$k")" \
    "$(grep -E '^[0-9.]+$' "t$k" | sort -n | head -1)" "$n"
done
if [ $have_povray = 1 ]; then
  r=$(median t4); p=$(median t5)
  echo "POV-Ray / rvr on the OBJ: $(python3 -c "print(round($p / $r, 2))")x (goal: 5x)"
else
  echo "povray not installed: the comparison row is missing (apt-get install povray)"
fi
