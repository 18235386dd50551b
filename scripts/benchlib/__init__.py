"""The parts of scripts/bench.py, the benchmark runner: `core` (running sdfc, parsing, tables)
and the suites (`frames`, `first`, `kernels`, `looks`, `peers`)."""
