#!/usr/bin/env bash
# The GPU check of the cuda backend in one call on a bare machine (benchmarks/gpu/gpu_check.py, docs/benchmarks.md):
#   bash benchmarks/gpu/prepare.sh            # here, with the package registry: .device/ (qdldl wheel, reference)
#   bash benchmarks/gpu/run.sh OUTDIR         # there: the device tool's run, carrying .device, timeout_s=420
# A preflight (device and CUDA context, NVVM, packages; qdldl from the carried wheel if the machine lacks it) stops
# the call at once if it fails; the CPU kernels are compiled once (warmup, beside the preflight) before any timed
# part; then one
# Python process per part, most important first, each under its limit and keeping to a budget a little under it
# (what does not fit is recorded as skipped), the CPU baseline beside them. The limits sum to 350 s on a GPU (a
# 420 s call) and 380 s in the smoke mode, shared out by the parts' CPU seconds measured from a cold numba cache on a
# loaded 2-core machine (docs/benchmarks.md, "GPU").
# Results go to a scratch folder; OUTDIR gets 4 files: summary.txt, results.jsonl, gpu.log and rest.tar.gz (the part
# logs, the run files). The summary is printed last; the exit status is 1 if the preflight failed or a part FAILED
# or is MISSING (summary.py), else 0.
# Smoke mode on numba's simulator: GPU_CHECK_SMOKE=1 NUMBA_ENABLE_CUDASIM=1 bash benchmarks/gpu/run.sh OUTDIR
# (tiny sizes: the script and its parts run; its figures mean nothing; tests/test_gpu_check.py). There the warmup
# compiles the CPU kernels from a cold cache as on the GPU machine and cpu-step loads them; the simulated parts run
# numba's CPU code as plain Python (NUMBA_DISABLE_JIT=1), which at N = 9 costs less than compiling it again.
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
# name:limit on a GPU:limit in the smoke mode [s], in the order they run (gpu_check.py says what each measures)
PREFLIGHT="preflight:60:120"  # beside the warmup, whose limit is longer: no time of the call
WARMUP="warmup:80:170"
PARTS="fidelity:75:90 speed:110:50 sanity:35:30 events:50:40"
CPU_STEP="cpu-step:280:150"  # beside the parts, after the warmup
SMOKE=${GPU_CHECK_SMOKE:-0}

limit() {  # the limit of part $1 (name:gpu:smoke) in this mode
    local rest=${1#*:}
    if [ "$SMOKE" = 1 ]; then echo "${rest#*:}"; else echo "${rest%%:*}"; fi
}

start_part() {  # start part spec $1 in the background under its limit, with a budget a little under it (log $2);
    local name=${1%%:*} seconds jit=0  # its timeout's process id in $started
    seconds=$(limit "$1")
    # the smoke mode's simulated parts run numba's CPU code as Python: only warmup and cpu-step compile (and load) it
    [ "$SMOKE" = 1 ] && [ "$name" != warmup ] && [ "$name" != cpu-step ] && jit=1
    NUMBA_DISABLE_JIT=$jit GPU_CHECK_BUDGET=$((seconds - 5)) timeout "$seconds" $check "$name" "$SCRATCH" > "$2" 2>&1 &
    started=$!
}

end_part() {  # wait for the part started as process $1 (log $2); its exit status
    local status=0
    wait "$1" || { status=$?; echo "part ended with exit status $status" >> "$2"; }
    return $status
}

run_part() {  # run part spec $1 (log $2); its exit status
    start_part "$1" "$2"
    end_part "$started" "$2"
}

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
start_part "$WARMUP" "$SCRATCH/logs/gpu-warmup.log"  # the CPU kernels compile beside the preflight
warmup=$started
if ! run_part "$PREFLIGHT" "$SCRATCH/logs/gpu-preflight.log"; then
    echo "preflight failed (no device, no NVVM or a missing package; see gpu.log): the check stops" \
        >> "$SCRATCH/logs/gpu-preflight.log"
    kill "$warmup" 2>/dev/null  # timeout passes the signal on to the part
    end_part "$warmup" "$SCRATCH/logs/gpu-warmup.log"
    finish
    exit 1
fi
end_part "$warmup" "$SCRATCH/logs/gpu-warmup.log"
start_part "$CPU_STEP" "$SCRATCH/logs/cpu-step.log"  # the CPU baseline beside the GPU parts (one thread)
cpu_step=$started
for part in $PARTS; do
    run_part "$part" "$SCRATCH/logs/gpu-${part%%:*}.log"
done
end_part "$cpu_step" "$SCRATCH/logs/cpu-step.log"
finish
