#!/usr/bin/env bash
# Lists the instruction sets below this CPU's best that the test command runs vkrt's tests with (tools/test.sh):
#   isa_matrix.sh embree   Embree's kernel sets (VKRT_EMBREE_ISA) this CPU runs, below its best: of avx2, avx and
#                          sse4.2 (SSE2 differs from SSE4.2 only in a few instructions of Embree's BVH code).
#   isa_matrix.sh jit      the x86-64 baselines (VKRT_JIT_CPU) this CPU runs: x86-64-v2 (no AVX, no F16C) and
#                          x86-64-v3 (AVX2, FMA, F16C), each below the host CPU the compiler targets by default.
set -euo pipefail
flags=" $(grep -m1 '^flags' /proc/cpuinfo | cut -d: -f2) "
has() { for f in "$@"; do [[ $flags == *" $f "* ]] || return 1; done; }
case "${1:-}" in
  embree)
    # Embree's own requirements for each set (its AVX-512 kernels are Skylake's).
    best=sse2
    has sse4_2 popcnt && best=sse4.2
    has sse4_2 avx && best=avx
    has avx2 fma bmi1 bmi2 && best=avx2
    has avx512f avx512cd avx512dq avx512bw avx512vl && best=avx512
    below=()
    for isa in avx2 avx sse4.2; do
      case "$best:$isa" in
        avx512:*) below+=("$isa") ;;
        avx2:avx | avx2:sse4.2 | avx:sse4.2) below+=("$isa") ;;
      esac
    done
    echo "${below[@]}"
    ;;
  jit)
    below=()
    has sse4_2 popcnt ssse3 cx16 && below+=(x86-64-v2)
    has avx2 fma bmi1 bmi2 f16c movbe && below+=(x86-64-v3)
    echo "${below[@]}"
    ;;
  *)
    echo "usage: $0 embree|jit" >&2
    exit 2
    ;;
esac
