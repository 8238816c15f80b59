#!/bin/bash
# The bytes of the fem solver's runs and event replays, to compare two trees of a refactor that must not change them.
#
#   bash benchmarks/fem_bytes.sh OUTDIR     (in a tree whose Python has stickslip installed; ~6 min on 2 vCPU)
#
# Runs N = 9 stacks with every protocol (dynamic, exact, free lever, yield strains extended with a short window,
# thermal with holds, junction aging at 20 and 40 increments), then replays their events (hold trials, aftershocks,
# control holds, interface states, the failures of athermal kicks), and prints a digest of every dataset and the
# sha256 of every file. Run it on both trees and compare the printed lines (`diff`).
set -euo pipefail
out=${1:?usage: fem_bytes.sh OUTDIR}
rm -rf "$out"; mkdir -p "$out"; cd "$out"
export NUMBA_NUM_THREADS=1
sim() { name=$1; shift; stickslip simulate --solver fem -o "$name.h5" "$@" 2>/dev/null; }
P() { for kv in "$@"; do printf -- "--param %s " "$kv"; done; }
sim dyn $(P N=9 plates=3 max_increments=40)
sim exact $(P N=9 plates=3 relaxation=exact max_increments=60 k_drive=0.081)
sim free $(P N=9 plates=3 relaxation=exact max_increments=40 drive=free-lever)
sim extend $(P N=9 plates=2 max_increments=80 window=20)
sim thermal $(P N=9 plates=2 relaxation=exact max_increments=40 temperature=0.05 drive_rate=1e-6 hold_times=1e5 hold_delay=0.5)
sim aging $(P N=9 plates=3 relaxation=exact max_increments=40 temperature=1e-3 drive_rate=2e-8 junction_strengthening=5)
sim aging20 $(P N=9 plates=3 relaxation=exact max_increments=20 temperature=1e-3 drive_rate=2e-8 junction_strengthening=5)
python - <<'PY'
import hashlib

import numpy as np

from stickslip.fem.replay import EventReplay
from stickslip.formats.fem_run import read_increments

out = {}
for name in ("thermal", "aging"):
    replay = EventReplay(f"{name}.h5")
    table = read_increments(f"{name}.h5")
    kicks = [int(i) for i in table["increment"][table["kick"].astype(bool)]][1:4]
    for k in kicks:
        for j, hold in enumerate((0.0, 1e6)):
            out[f"{name}-hold-{k}-{hold}"] = replay.hold(k, hold, 0.02, j, each=1)
        out[f"{name}-after-{k}"] = replay.aftershocks(k, 1e8, 0)
        out[f"{name}-control-{k}"] = replay.aftershocks(kicks[0], 1e8, 1, control=(1, 0.5))
    out[f"{name}-state"] = replay.interface_state(kicks[0])
replay = EventReplay("dyn.h5")
table = read_increments("dyn.h5")
for k in [int(i) for i in table["increment"][table["kick"].astype(bool)]][1:6]:
    out[f"dyn-failures-{k}"] = replay.failures(k).to_numpy()


def digest(value):
    if isinstance(value, dict):
        return {key: digest(item) for key, item in sorted(value.items())}
    array = np.asarray(value)
    return hashlib.sha256(array.tobytes()).hexdigest()[:16] + str(array.shape)


with open("replays.txt", "w") as file:
    for key, value in out.items():
        file.write(f"{key} {digest(value)}\n")
PY
for f in *.h5; do python - "$f" <<'PY'
import hashlib
import sys

import h5py
import numpy as np

digest = hashlib.sha256()
with h5py.File(sys.argv[1]) as file:
    def visit(name, obj):
        if isinstance(obj, h5py.Dataset):
            digest.update(name.encode())
            digest.update(np.ascontiguousarray(obj[...]).tobytes())
    file.visititems(visit)
print(sys.argv[1], "datasets", digest.hexdigest()[:32])
PY
done
sha256sum *.h5 replays.txt
