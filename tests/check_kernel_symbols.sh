#!/usr/bin/env bash
# The SIMD kernel objects may define exactly one external symbol each, their kKernels table.
# Anything else with external linkage (a weak copy of an inline function or template from a
# shared header, say) could be picked by the linker for baseline code too, and would then run
# AVX2 or AVX-512 instructions on any x86-64: a crash on older CPUs that no test here would see.
# Usage: check_kernel_symbols.sh OBJECT...
set -euo pipefail
status=0
for object in "$@"; do
  # Defined symbols with external linkage: upper-case types, plus weak (W, V) and unique (u).
  external=$(nm -C --defined-only "$object" | awk '$2 ~ /^[A-Zuvw]$/ { $1 = ""; print }')
  expected=$(printf '%s\n' "$external" | grep -c 'rvr::isa_[a-z0-9]*::kKernels$' || true)
  others=$(printf '%s\n' "$external" | grep -v 'rvr::isa_[a-z0-9]*::kKernels$' | grep -v '^$' || true)
  if [ "$expected" != 1 ] || [ -n "$others" ]; then
    echo "FAIL: $object: external symbols other than one kKernels table:"
    printf '%s\n' "$external"
    status=1
  else
    echo "ok: $object: only$(printf '%s' "$external" | sed 's/^ *[A-Za-z]//')"
  fi
done
exit $status
