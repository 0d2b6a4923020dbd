#!/usr/bin/env bash
# Mutation check (issue 14): plants, one at a time, bugs that every renderer would share, in a
# COPY of the committed tree (git archive HEAD; the working tree is never touched), rebuilds
# the fast test programs there and lists which ctest cases fail. A mutation no test catches is
# reported as "NOT CAUGHT" and makes the script exit 1.
#
#   tests/mutation/run.sh [-j N] [-L LABEL] [--keep DIR] [mutation ...]
#
# -L LABEL  ctest label of the cases to run (default fast; the fast programs are the ones built)
# --keep DIR  work in DIR (made if missing) and keep it: a second run rebuilds only what
#             changed. Without it a temporary folder is used and deleted at the end.
# mutations: ambient shininess falloff psnr triangle halfpixel (default: all)
set -euo pipefail

repo=$(cd "$(dirname "$0")/../.." && pwd)
jobs=2
label=fast
keep=""
selected=()
while (($#)); do
  case $1 in
    -j) jobs=$2; shift 2 ;;
    -L) label=$2; shift 2 ;;
    --keep) keep=$2; shift 2 ;;
    -h|--help) sed -n '2,13p' "$0"; exit 0 ;;
    *) selected+=("$1"); shift ;;
  esac
done
all=(ambient shininess falloff psnr triangle halfpixel)
((${#selected[@]})) || selected=("${all[@]}")

if [[ -n $keep ]]; then
  work=$keep
  mkdir -p "$work"
else
  work=$(mktemp -d /tmp/rvr-mutation.XXXXXX)
  trap 'rm -rf "$work"' EXIT
fi
fresh=$work/fresh  # HEAD as committed
src=$work/src      # the tree that is built; mutated one file at a time
build=$work/build
mkdir -p "$src"

# Makes $src equal to $fresh, rewriting only files that differ (so make rebuilds only what a
# mutation touched).
sync_tree() {
  (cd "$fresh" && find . -type f) | while read -r f; do
    if ! cmp -s "$fresh/$f" "$src/$f"; then
      mkdir -p "$(dirname "$src/$f")"
      cp "$fresh/$f" "$src/$f"
    fi
  done
}

rm -rf "$fresh"
mkdir -p "$fresh"
git -C "$repo" archive HEAD | tar -x -C "$fresh"
sync_tree
echo "source: $(git -C "$repo" rev-parse --short HEAD) in $src"

# The fast test programs: every tests/test_*.cpp not listed in RVR_SLOW_TESTS.
slow=$(sed -n '/^set(RVR_SLOW_TESTS/,/)/p' "$src/tests/CMakeLists.txt" | tr -d '()' |
  tr ' ' '\n' | grep '^test_' || true)
targets=()
for f in "$src"/tests/test_*.cpp; do
  t=$(basename "$f" .cpp)
  grep -qx "$t" <<<"$slow" || targets+=("$t")
done

build_and_test() {  # $1: name for the log; prints the failed cases, one per line
  cmake --build "$build" -j "$jobs" --target "${targets[@]}" >"$work/$1.build.log" 2>&1 || {
    echo "BUILD FAILED (see $work/$1.build.log)"
    return
  }
  ctest --test-dir "$build" -L "$label" -j "$jobs" --output-on-failure >"$work/$1.test.log" 2>&1 ||
    true
  sed -n 's/^[[:space:]]*[0-9]* - \(.*\) (\(Failed\|Timeout\|SEGFAULT\|Subprocess aborted\|Exception\|Not Run\)).*/\1/p' \
    "$work/$1.test.log" | sed 's/  # GetParam() = .*//'
}

# Each mutation: file, then a sed program; the sed must change the file.
mutate() {  # $1 name
  case $1 in
    ambient)  # emission + ambient * diffuse -> emission, in C++ and GLSL
      apply core/include/rvr/core/shading.h 's/return m.emission + ambient \* m.diffuse;/return m.emission;/'
      apply raster/src/gl_shaders.h 's/u_emission + u_ambient \* u_diffuse/u_emission/' ;;
    shininess)  # the exponent halved, in C++ and GLSL
      apply core/include/rvr/core/shading.h 's/specular_power(n_dot_h, m.shininess)/specular_power(n_dot_h, 0.5f * m.shininess)/'
      apply raster/src/gl_shaders.h 's/specular_power(n_dot_h, u_shininess)/specular_power(n_dot_h, 0.5 * u_shininess)/' ;;
    falloff)  # I / d instead of I / d^2, in C++ and GLSL
      apply core/include/rvr/core/shading.h 's|lights\[i\].intensity / dist2;|lights[i].intensity / std::sqrt(dist2);|'
      apply raster/src/gl_shaders.h 's|light_intensity / dist2;|light_intensity / sqrt(dist2);|' ;;
    psnr)  # 10 log10 instead of 20 log10 of 1 / RMSE
      apply compare/src/compare.cpp 's/20.0 \* std::log10(1.0 \/ rmse)/10.0 * std::log10(1.0 \/ rmse)/' ;;
    triangle)  # the last triangle of every tessellated mesh (spheres, squares) dropped
      apply core/src/tessellate.cpp 's/^  return mesh;$/  mesh.triangles.pop_back();\n  return mesh;/' ;;
    halfpixel)  # softraster's vertices shifted half a pixel right: it samples at x, not x + 0.5
      apply raster/src/soft/triangle_setup.cpp 's/\* 0.5 + 0.5) \* width_;/* 0.5 + 0.5) * width_ + 0.5;/' ;;
    *) echo "unknown mutation $1" >&2; exit 2 ;;
  esac
}
apply() {  # $1 file (relative to the tree), $2 sed program
  sed -i "$2" "$src/$1"
  if cmp -s "$fresh/$1" "$src/$1"; then
    echo "mutation did not apply: $1: $2" >&2
    exit 2
  fi
}

if [[ ! -f $build/CMakeCache.txt ]]; then
  cmake -S "$src" -B "$build" -DCMAKE_BUILD_TYPE=Release >"$work/configure.log" 2>&1
fi

echo "== baseline (no mutation): fast programs: ${targets[*]}"
baseline=$(build_and_test baseline)
if [[ $baseline == "BUILD FAILED"* ]]; then
  echo "baseline: $baseline"
  exit 2
fi
if [[ -n $baseline ]]; then
  echo "baseline failures (left out of every mutation's list):"
  sed 's/^/  /' <<<"$baseline"
fi

# Failed cases grouped: "Suite.Case (n)" for the parameterised ones (Prefix/Suite.Case/param).
summarise() {
  sed -E 's#^[^/]+/([^/]+)/.*#\1#' | sort | uniq -c |
    awk '{printf "%s%s%s", (NR > 1 ? ", " : ""), $2, ($1 > 1 ? " (" $1 ")" : "")}'
}

status=0
table=""
for m in "${selected[@]}"; do
  sync_tree
  mutate "$m"
  echo "== $m: $(cd "$src" && for f in $(cd "$fresh" && find . -type f); do cmp -s "$fresh/$f" "$f" || echo -n "${f#./} "; done)"
  failed=$(build_and_test "$m")
  if [[ -n $baseline ]]; then
    failed=$(grep -vxF -f <(printf '%s\n' "$baseline") <<<"$failed" || true)
  fi
  if [[ $failed == "BUILD FAILED"* ]]; then  # a mutation that does not compile proves nothing
    echo "   $failed"
    status=1
    table+="| $m | build failed |"$'\n'
  elif [[ -z $failed ]]; then
    echo "   NOT CAUGHT"
    status=1
    table+="| $m | NOT CAUGHT |"$'\n'
  else
    sed 's/^/   caught by: /' <<<"$failed"
    table+="| $m | $(grep -c . <<<"$failed"): $(summarise <<<"$failed") |"$'\n'
  fi
done
sync_tree  # leave the kept tree as committed

echo
echo "| mutation | ctest cases that failed (label $label): how many, then by case (renderers) |"
echo "|---|---|"
printf '%s' "$table"
exit $status
