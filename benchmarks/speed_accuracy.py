"""Speed against accuracy (issue 7): every simulation level, a dynamic settings grid, pruned
against whole scenes, where the methods break, and peers (pylinkage, bare pymunk) in one run.

    pip install -e '.[bench]'        # pylinkage (with numba), the peer; not a mechc dependency
    python benchmarks/speed_accuracy.py [--quick] [--out DIR] [--write-model [PATH]]

The same as ``mechc bench``; the driver is ``mechc/bench/speed_accuracy.py``, one module per
study beside it in ``mechc/bench/``.
"""

from __future__ import annotations

import sys

from mechc.bench.speed_accuracy import main

if __name__ == "__main__":
    sys.exit(main())
