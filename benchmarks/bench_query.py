"""CPU time of what ``stickslip.study(...).events()`` adds to the SQL query: the JSON column ``extra`` expanded
into columns and every column typed by the vocabulary (:func:`stickslip.vocabulary.expand_json`, ``typed``).

    python benchmarks/bench_query.py [ROWS]

Rows like an experimental event's (eight further columns), 200 000 by default; prints CPU seconds and per row.
"""

import json
import sys
import time

import numpy as np
import pandas as pd

from stickslip.vocabulary import expand_json, typed


def main(rows):
    extra = json.dumps({"t_start": 223.8, "t_end": 225.8, "dF": 1.2397720836123556, "T": 36.19999999999999,
                        "slip_from_dF": 0.060652475978454724, "B_a": 0.05690570217792517,
                        "drift": 0.009240225644225664, "slow_slip_before": True})
    frame = pd.DataFrame({"id": np.arange(rows), "dmu": np.random.default_rng(0).random(rows),
                          "multi": np.zeros(rows, dtype=np.int64), "extra": [extra] * rows})
    start = time.process_time()
    table = typed(expand_json(frame, "extra"))
    seconds = time.process_time() - start
    print(f"{rows} rows, {table.shape[1]} columns: {seconds:.2f} CPU-s, {1e6 * seconds / rows:.1f} us per row")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 200_000)
