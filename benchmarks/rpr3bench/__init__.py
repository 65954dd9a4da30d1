"""The benchmarks of rpr3gen, run by ``benchmarks/run.py`` (see ``benchmarks/README.md``).

- :mod:`.common`: paths, the measured variant and trajectory, which functions get samples;
- :mod:`.workers`: the measurements that run in a fresh interpreter, and how they are started;
- :mod:`.charness`: the C harnesses (``bench.c``; ``bench_control.c`` and ``bench_mujoco.c`` for
  the control model), built and run against the generated C;
- :mod:`.sections`: each section of the report, what it runs and its table;
- :mod:`.control`: the section "Control model" (issue 12);
- :mod:`.report`: tables and number formats, the machine block, targets and verdicts.
"""
