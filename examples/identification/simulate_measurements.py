"""Write ``measured.csv``: what the real robot would give along an exciting motion.

    python examples/identification/simulate_measurements.py [--out measured.csv]
    rpr3gen identify --model models/paper.toml --data measured.csv --friction --smoothing 2e-5

The "real robot" is the paper's with other masses, inertias, off-axis centres of mass and
friction at the motors (``TRUE_PARAMS``, ``FRICTION_*``); it runs five periods of the motion
``rpr3gen excite`` optimises for the paper's model, sampled at 100 Hz; the file holds the
platform pose with 20 µm / 20 µrad of noise and the motor torques with 1 % of their RMS: the
columns ``t,x,y,phi,m10_A,m10_B,m10_C`` of ``rpr3gen identify``'s data file. The seed is fixed,
so the file is the same on every run. ``notebooks/identification.ipynb`` walks through the same
steps with figures.
"""

from __future__ import annotations

import argparse
import dataclasses

import numpy as np

import rpr3gen
from rpr3gen.atomic import write_csv_table

TRUE_PARAMS = {"m2": 1.7, "c2": 0.09, "J2": 0.006, "m3": 6.1, "J3": 0.29, "c1_perp": 0.012}
FRICTION_VISCOUS = np.array([0.20, 0.25, 0.15])  # N m s/rad, motors A, B, C
FRICTION_COULOMB = np.array([0.30, 0.20, 0.25])  # N m


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="measured.csv", help="the data file (measured.csv)")
    args = parser.parse_args()
    model = rpr3gen.load_model()
    true = dataclasses.replace(model, params=dict(model.params) | TRUE_PARAMS)
    motion = rpr3gen.excite(
        model, harmonics=4, period=8.0, samples=161, friction=True, max_iterations=60
    ).motion
    t = np.arange(0.0, 5 * motion.period, 0.01)
    q, qd, qdd = motion.at(t)
    tau = rpr3gen.actuator_efforts(true, q, qd, qdd)
    rate = np.einsum("nij,nj->ni", rpr3gen.actuator_jacobian(true, q), qd)
    tau = tau + FRICTION_VISCOUS * rate + FRICTION_COULOMB * np.sign(rate)
    rng = np.random.default_rng(2013)
    tau = tau + 0.01 * np.sqrt(np.mean(tau**2, axis=0)) * rng.normal(size=tau.shape)
    q = q + 2e-5 * rng.normal(size=q.shape)
    header = ["t", "x", "y", "phi", "m10_A", "m10_B", "m10_C"]
    write_csv_table(args.out, header, np.column_stack([t, q, tau]))
    print(f"wrote {args.out}: {len(t)} samples over {t[-1]:g} s")


if __name__ == "__main__":
    main()
