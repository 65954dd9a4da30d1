"""Layers import one way: the runtime and the generated code never import sympy or jinja2."""

from __future__ import annotations

import subprocess
import sys

BLOCKER = """
import sys
class Block:
    def find_spec(self, name, path=None, target=None):
        if name.split('.')[0] in ('sympy', 'jinja2', 'rpr3gen_derive'):
            raise ImportError('blocked: ' + name)
        return None
sys.meta_path.insert(0, Block())
"""

RUN = """
import numpy as np
import rpr3gen
from rpr3gen.cli import main
model = rpr3gen.load_model()
traj = rpr3gen.paper_trajectory('rectilinear', samples=11)
out = rpr3gen.inverse_dynamics(model, traj.q, traj.qd, traj.qdd)
assert np.isfinite(out['m10_A']).all()
import rpr3gen.plots, rpr3gen.atomic
assert not any(m.split('.')[0] in ('sympy', 'jinja2') for m in sys.modules)
print('ok')
"""


def test_runtime_runs_with_sympy_and_jinja2_blocked() -> None:
    result = subprocess.run(
        [sys.executable, "-c", BLOCKER + RUN], capture_output=True, text=True, check=False
    )
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "ok"


def test_generate_without_derive_dependencies_is_one_clear_line() -> None:
    code = BLOCKER.replace("'rpr3gen_derive'", "'nothing'") + (
        "from rpr3gen.cli import main\nsys.exit(main(['generate', '--check']))\n"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert result.returncode == 2
    assert result.stderr.count("\n") == 1
    assert "rpr3gen[derive]" in result.stderr
    assert "Traceback" not in result.stderr


def test_importing_the_runtime_leaves_scipy_for_later() -> None:
    """``import rpr3gen``, which every command does, does not pay for SciPy (0.7 s of imports):
    the identification and the positions-only trajectories import it when they run."""
    code = "import sys, rpr3gen.cli; print(sorted({m.split('.')[0] for m in sys.modules}))"
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    assert "'numpy'" in result.stdout
    assert "'scipy'" not in result.stdout
