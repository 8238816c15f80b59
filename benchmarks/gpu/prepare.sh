#!/usr/bin/env bash
# What the bare GPU machine lacks, fetched here (with the package registry reachable) into .device/ (git-ignored),
# which the device tool carries with the working tree (`run` with carry [".device"]):
#   .device/wheels/     the qdldl wheel of environment.txt's pin for the GPU machine's Python (default cp312)
#   .device/reference/  the paper code's N = 9 reference file (../shared/reference/FixedLever_historic.h5)
# Usage: bash benchmarks/gpu/prepare.sh [PYTHON_TAG]   e.g. cp312 (the H200 image's Python 3.12), cp311
# DEVICE_DIR overrides .device (the smoke test's own folder).
set -euo pipefail
cd "$(dirname "$0")/../.."
TAG=${1:-cp312}
DEVICE=${DEVICE_DIR:-.device}
PIN=$(grep -E '^qdldl==' environment.txt | cut -d' ' -f1)
mkdir -p "$DEVICE/wheels" "$DEVICE/reference"
"${PYTHON:-python3}" -m pip download --quiet --no-deps --only-binary=:all: --implementation cp --python-version "${TAG#cp}" \
    --abi "$TAG" --platform manylinux_2_28_x86_64 --platform manylinux_2_24_x86_64 --platform manylinux2014_x86_64 \
    --dest "$DEVICE/wheels" "$PIN"
SHARED=${STICKSLIP_SHARED:-../shared}
if [ -f "$SHARED/reference/FixedLever_historic.h5" ]; then
    cp "$SHARED/reference/FixedLever_historic.h5" "$DEVICE/reference/"
fi
ls -l "$DEVICE/wheels" "$DEVICE/reference"
