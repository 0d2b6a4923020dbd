#!/usr/bin/env bash
# The SIMD kernel objects may define no external code and exactly one kernel table each
# (kKernels in raytrace, kFillKernels and kShadeKernels in raster).
# External code (a weak copy of an inline function or template from a shared header, say) could
# be picked by the linker for baseline code too, and would then run AVX2 or AVX-512 instructions
# on any x86-64: a crash on older CPUs that no test here would see. Data the compiler adds itself
# (sanitizer ODR indicators, the exception personality reference) carries no instructions.
# Usage: check_kernel_symbols.sh OBJECT...
set -euo pipefail
status=0
for object in "$@"; do
  symbols=$(nm -C --defined-only "$object")
  # External code: T (text), W (weak, here code: weak data is V), i (indirect function).
  code=$(printf '%s\n' "$symbols" | awk '$2 ~ /^[TWi]$/ { $1 = ""; print }')
  tables=$(printf '%s\n' "$symbols" | grep -cE ' [A-Z] rvr::(soft::)?isa_[a-z0-9]*::k(Fill|Shade)?Kernels$' || true)
  if [ "$tables" != 1 ] || [ -n "$code" ]; then
    echo "FAIL: $object: $tables kernel tables; external code symbols:"
    printf '%s\n' "$code"
    status=1
  else
    echo "ok: $object: one kernel table, no external code"
  fi
done
exit $status
