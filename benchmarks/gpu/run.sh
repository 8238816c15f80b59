#!/usr/bin/env bash
# The GPU check of the cuda backend in one call (benchmarks/gpu/gpu_check.py, docs/benchmarks.md):
#   bash benchmarks/gpu/run.sh OUTDIR
# on a machine with an NVIDIA GPU, numba-cuda and the package's dependencies (no network needed). The GPU
# parts run in one process (restarted after a part that crashed or hung, which is then skipped); the CPU
# baselines, one thread each, run beside them on the other cores. Everything goes to OUTDIR; the table is
# OUTDIR/summary.txt. BUDGET (seconds, default 450) bounds the whole call.
set -u
OUT=${1:?usage: run.sh OUTDIR}
BUDGET=${BUDGET:-450}
mkdir -p "$OUT"
cd "$(dirname "$0")/../.."
export PYTHONPATH=$PWD${PYTHONPATH:+:$PYTHONPATH}
export NUMBA_CACHE_DIR=${NUMBA_CACHE_DIR:-/tmp/stickslip-numba-cache}  # the parts share the CPU kernels
export PYTHONUNBUFFERED=1 NUMBA_NUM_THREADS=1 OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1
PY=${PYTHON:-python3}
start=$SECONDS
check="$PY benchmarks/gpu/gpu_check.py"
# the CPU baseline per step first, beside the GPU process only; then the CPU events and ensembles
(
  $check cpu-step "$OUT" > "$OUT/cpu-step.log" 2>&1
  $check cpu-events "$OUT" > "$OUT/cpu-events.log" 2>&1 &
  for regime in stiff compliant; do
    for seed in $($check seeds "$OUT"); do
      $check ensemble-cpu "$OUT" $regime $seed > "$OUT/ensemble-cpu-$regime-$seed.log" 2>&1 &
    done
  done
  wait
) &
for attempt in 1 2 3; do
  left=$((BUDGET - (SECONDS - start)))
  [ $left -gt 10 ] || break
  timeout $left $check gpu "$OUT" >> "$OUT/gpu.log" 2>&1 && break
  echo "gpu sequence ended with $? (attempt $attempt)" >> "$OUT/gpu.log"
done
while [ -n "$(jobs -rp)" ] && [ $((SECONDS - start)) -lt $((BUDGET - 20)) ]; do sleep 2; done
pkill -f "gpu_check.py (cpu-step|cpu-events|ensemble-cpu) $OUT" 2>/dev/null
$check compare "$OUT" > "$OUT/compare.log" 2>&1
$PY benchmarks/gpu/summary.py "$OUT" | tee "$OUT/summary.txt"
echo "wall seconds: $((SECONDS - start))"
