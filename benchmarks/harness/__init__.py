"""rpr3gen's benchmark harness: samples, the C timing harness's builds, the report.

Imports go one way: ``samples`` (what is measured, on which samples) <- ``cbench`` (C builds
and runs) and ``pybench`` (pyperf benchmarks) <- ``run`` (the command) -> ``report`` (tables
from the results file). ``report`` imports none of the others; ``generation`` (a structure's
first use, timed in fresh interpreters) imports only the runtime, in its child processes.
"""
