#!/usr/bin/env bash
# The GPU check of the cuda backend in one call on a bare machine (benchmarks/gpu/gpu_check.py, docs/benchmarks.md):
#   bash benchmarks/gpu/prepare.sh            # here, with the package registry: .device/ (qdldl wheel, reference)
#   bash benchmarks/gpu/run.sh OUTDIR         # there: the device tool's run, carrying .device
# A 10 s preflight (device, NVVM, packages; qdldl from the carried wheel if the machine lacks it) stops the call at
# once if it fails; then one Python process per part, each under its limit (they sum to 350 s), the CPU baseline
# beside them. Results go to a scratch folder; OUTDIR gets 4 files: summary.txt, results.jsonl, gpu.log and
# rest.tar.gz (the part logs, the run files). The summary is printed last; the exit status is 1 if the preflight
# failed or a part FAILED or is MISSING (summary.py), else 0.
# Smoke mode on numba's simulator: GPU_CHECK_SMOKE=1 NUMBA_ENABLE_CUDASIM=1 bash benchmarks/gpu/run.sh OUTDIR
# (tiny sizes: the script and its parts run; its figures mean nothing; tests/test_gpu_check.py).
set -u
OUT=${1:?usage: run.sh OUTDIR}
mkdir -p "$OUT"
OUT=$(cd "$OUT" && pwd)
cd "$(dirname "$0")/../.."
ROOT=$PWD
PY=${PYTHON:-python3}
DEVICE=${DEVICE_DIR:-$ROOT/.device}
SCRATCH=$(mktemp -d "${TMPDIR:-/tmp}/stickslip-gpu-check.XXXXXX")
trap 'rm -rf "$SCRATCH"' EXIT  # what OUTDIR needs is copied there (finish)
mkdir -p "$SCRATCH/site" "$SCRATCH/logs"
export PYTHONPATH=$SCRATCH/site:$ROOT${PYTHONPATH:+:$PYTHONPATH}
export PYTHONUNBUFFERED=1 NUMBA_NUM_THREADS=1 OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1
export GPU_CHECK_REFERENCE=$DEVICE/reference/FixedLever_historic.h5
start=$SECONDS
check="$PY benchmarks/gpu/gpu_check.py"
# limits [s] of the parts (350 s together with the preflight's 10); the simulator's smoke run gets more
PARTS="sanity:50 fidelity:120 speed:100 events:70"
SCALE=1; [ "${GPU_CHECK_SMOKE:-}" = 1 ] && SCALE=2

finish() {
    $PY benchmarks/gpu/summary.py "$SCRATCH" > "$SCRATCH/summary.txt" 2>&1
    status=$?
    echo "wall seconds: $((SECONDS - start))" >> "$SCRATCH/summary.txt"
    cp "$SCRATCH/summary.txt" "$OUT/summary.txt"
    [ -f "$SCRATCH/results.jsonl" ] && cp "$SCRATCH/results.jsonl" "$OUT/results.jsonl"
    cat "$SCRATCH"/logs/gpu-*.log > "$OUT/gpu.log" 2>/dev/null
    tar -czf "$OUT/rest.tar.gz" -C "$SCRATCH" --exclude site --exclude summary.txt \
        --exclude results.jsonl . 2>/dev/null
    cat "$OUT/summary.txt"
    return $status
}

# preflight: qdldl from the carried wheel of this Python where the machine lacks it; the device and NVVM
if ! $PY -c "import qdldl" 2>/dev/null; then
    tag=$($PY -c 'import sys; print(f"cp{sys.version_info[0]}{sys.version_info[1]}")')
    wheel=$(ls "$DEVICE"/wheels/qdldl-*-"$tag"-*.whl 2>/dev/null | head -n 1)
    [ -n "$wheel" ] && $PY -m zipfile -e "$wheel" "$SCRATCH/site"
fi
if ! timeout $((10 * SCALE)) $check preflight "$SCRATCH" > "$SCRATCH/logs/gpu-preflight.log" 2>&1; then
    echo "preflight failed (no device, no NVVM or a missing package; see gpu.log): the check stops" \
        >> "$SCRATCH/logs/gpu-preflight.log"
    finish
    exit 1
fi
# the CPU baseline beside the GPU parts (one thread)
timeout $((300 * SCALE)) $check cpu-step "$SCRATCH" > "$SCRATCH/logs/cpu-step.log" 2>&1 &
for part in $PARTS; do
    name=${part%%:*}
    timeout $((${part##*:} * SCALE)) $check "$name" "$SCRATCH" > "$SCRATCH/logs/gpu-$name.log" 2>&1 \
        || echo "part $name ended with exit status $?" >> "$SCRATCH/logs/gpu-$name.log"
done
wait
finish
