"""The 1 kHz computed-torque loop of control_loop.c, in Python, with rpr3gen.SampleEvaluator.

The controller evaluates the generated C inverse dynamics of the nominal model for the desired
acceleration plus a PD correction; the plant is the same robot with masses and inertias a few
percent off, integrated from the actuator loads. Prints the tracking error and the latency
distribution of the controller's call.

    python control_loop.py [--model FILE] [--trajectory rectilinear|rotation] [--seconds T]
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import time

import numpy as np

import rpr3gen

RATE_HZ = 1000
SUBSTEPS = 4
KP, KD = 900.0, 60.0
PERTURBED = {"m1": 1.03, "m2": 0.96, "m3": 1.05, "J1": 1.04, "J2": 0.97, "J3": 1.05}


def reference(amplitude: np.ndarray, t: float, duration: float) -> tuple[np.ndarray, ...]:
    """Paper eq. (3) and its derivatives."""
    w = math.pi / duration
    return (
        amplitude * (1 - math.cos(w * t)),
        amplitude * w * math.sin(w * t),
        amplitude * w * w * math.cos(w * t),
    )


def forward_dynamics(
    plant: rpr3gen.SampleEvaluator, actuator: list[int], tau: np.ndarray
) -> np.ndarray:
    """Platform acceleration from the actuator loads, tau = A qdd + b (plant.q, plant.qd set)."""
    plant.qdd[:] = 0.0
    if plant():
        raise RuntimeError("the plant reached a singular pose")
    bias = plant.out[actuator].copy()
    a = np.empty((3, 3))
    for j in range(3):
        plant.qdd[:] = 0.0
        plant.qdd[j] = 1.0
        if plant():
            raise RuntimeError("the plant reached a singular pose")
        a[:, j] = plant.out[actuator] - bias
    return np.linalg.solve(a, tau - bias)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model")
    parser.add_argument("--trajectory", choices=sorted(rpr3gen.trajectory.PAPER_TRAJECTORIES),
                        default="rectilinear")  # fmt: skip
    parser.add_argument("--seconds", type=float, default=3.0)
    args = parser.parse_args()

    model = rpr3gen.load_model(args.model)
    true_params = {k: v * PERTURBED.get(k, 1.0) for k, v in model.params.items()}
    truth = dataclasses.replace(model, params=true_params)
    controller = rpr3gen.SampleEvaluator(model)
    plant = rpr3gen.SampleEvaluator(truth)
    family = "m10" if model.actuation == "revolute" else "f21z"
    actuator = [controller.index[f"{family}_{leg}"] for leg in "ABC"]
    amplitude = np.array(rpr3gen.trajectory.PAPER_TRAJECTORIES[args.trajectory])

    duration, dt = 3.0, 1.0 / RATE_HZ
    steps = round(args.seconds * RATE_HZ)
    q, qd = np.array([0.001, -0.001, 0.0]), np.zeros(3)
    latency = np.empty(steps)
    errors = np.empty((steps, 2))
    clock = time.perf_counter_ns
    for step in range(steps):
        t = step * dt
        q_des, qd_des, qdd_des = reference(amplitude, t, duration)
        controller.q[:] = q
        controller.qd[:] = qd
        controller.qdd[:] = qdd_des + KD * (qd_des - qd) + KP * (q_des - q)
        start = clock()
        status = controller()
        latency[step] = clock() - start
        if status:
            raise RuntimeError(f"controller call failed at t = {t} s: {status}")
        tau = controller.out[actuator].copy()
        for _ in range(SUBSTEPS):
            plant.q[:] = q
            plant.qd[:] = qd
            qd = qd + forward_dynamics(plant, actuator, tau) * dt / SUBSTEPS
            q = q + qd * dt / SUBSTEPS
        q_des, _, _ = reference(amplitude, t + dt, duration)
        errors[step] = math.hypot(*(q - q_des)[:2]), abs(q[2] - q_des[2])
    p50, p99 = np.percentile(latency, [50, 99])
    print(f"trajectory {args.trajectory}, {steps} steps at {RATE_HZ} Hz, {model.actuation} "
          "actuation, plant masses off by 3-5%")  # fmt: skip
    print(
        f"tracking error: position max {errors[:, 0].max() * 1e3:.4f} mm, "
        f"rms {math.sqrt(np.mean(errors[:, 0] ** 2)) * 1e3:.4f} mm, "
        f"final {errors[-1, 0] * 1e3:.4f} mm; angle max {errors[:, 1].max() * 1e3:.4f} mrad"
    )
    print(
        f"SampleEvaluator call latency: p50 {p50 / 1e3:.2f} us, p99 {p99 / 1e3:.2f} us, "
        f"max {latency.max() / 1e3:.2f} us"
    )


if __name__ == "__main__":
    main()
