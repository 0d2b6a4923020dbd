#!/bin/bash
# What starting rvr costs (issue 34): the CPU time (task-clock: user + system, all threads) of
# whole short runs, averaged over N runs each by `perf stat -r N`, and the shared objects each
# run loads (from the dynamic loader's trace). Target: `rvr --version` under 10 ms of CPU.
# Loading a library costs its relocation and symbol lookups (Debian links with -z now), so the
# libraries a run does not need are plugins opened on first use (docs/design.md, "Start-up loads
# only what the run needs"). perf from Debian's linux-perf; without it, the CPU time of the N runs
# from getrusage.
# usage: bench/startup.sh [RVR_BINARY] [RUNS]
set -euo pipefail
rvr=$(realpath "${1:-build/bin/rvr}")
n=${2:-200}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
printf 'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n%s\n' \
  'property float z' >tri.ply
printf 'element face 1\nproperty list uchar int vertex_indices\nend_header\n' >>tri.ply
printf '0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n' >>tri.ply

labels=("rvr --version" "rvr scenes" "rvr bad input (exit 2)" "rvr 16x12 cornell raytrace"
        "rvr 16x12 spheres embree" "rvr 16x12 PLY raytrace")
cmds=("$rvr --version"
      "$rvr scenes"
      "$rvr render builtin:nope -r raytrace -q -o bad.png"
      "$rvr render builtin:cornell -r raytrace --width 16 --height 12 -q -o c.png"
      "$rvr render builtin:spheres -r embree --width 16 --height 12 -q -o e.png"
      "$rvr render tri.ply -r raytrace --width 16 --height 12 -q -o p.png")

# Milliseconds of CPU per run of "$1".
cpu_ms() {
  if command -v perf >/dev/null && perf stat -e task-clock true >/dev/null 2>&1; then
    # A run may fail on purpose (the bad input): perf still reports, and so does this.
    # shellcheck disable=SC2086
    { perf stat -e task-clock -x, -r "$n" $1 2>&1 >/dev/null || true; } |
      awk -F, '/task-clock/ {print $1}'
  else
    /usr/bin/python3 - "$n" "$1" <<'PY'
import resource, shlex, subprocess, sys
n, command = int(sys.argv[1]), shlex.split(sys.argv[2])
for _ in range(n):
    subprocess.run(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
r = resource.getrusage(resource.RUSAGE_CHILDREN)
print((r.ru_utime + r.ru_stime) * 1000 / n)
PY
  fi
}

# The shared objects a run of "$1" loads, and which of rvr's plugins among them.
objects() {
  # shellcheck disable=SC2086
  LD_DEBUG=files $1 2>&1 >/dev/null | grep -oE 'file=[^ ]+ +\[[0-9]+\]; +(needed|dynamically)' |
    awk '{print $1}' | sort -u >objects.txt || true
  printf '%s' "$(wc -l <objects.txt)"
  plugins=$(grep -oE 'librvr_[a-z_]+' objects.txt | sort -u | tr '\n' ' ' || true)
  [ -z "$plugins" ] || printf ' (%s)' "${plugins% }"
}

echo "rvr: $rvr ($("$rvr" --version)); $n runs each; $(uname -m), $(nproc) threads"
printf '%-28s %10s  %s\n' "run" "CPU ms" "shared objects loaded"
for k in "${!cmds[@]}"; do
  ms=$(cpu_ms "${cmds[$k]}")
  printf '%-28s %10.2f  %s\n' "${labels[$k]}" "$ms" "$(objects "${cmds[$k]}")"
  if [ "$k" = 0 ]; then version_ms=$ms; fi
done
verdict=$(awk -v t="$version_ms" 'BEGIN {print (t < 10) ? "met" : "NOT met"}')
echo "target: rvr --version under 10 ms of CPU: $verdict ($version_ms ms)"
echo "(bench/README.md, \"Whole processes\"; readings of record: bench/JOURNAL.md)"
