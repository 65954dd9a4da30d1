"""The 1 kHz task-space computed-torque loop of control_loop.c, closed on encoders, in Python.

The plant is the robot with masses and inertias a few percent off, integrated by RK4 of the
generated forward dynamics (four substeps per tick). The controller reads only the quantised
actuator positions, estimates the actuator rates from the differences of the counts (low-pass
filtered), reconstructs the pose by tracked forward kinematics and the velocity through the
actuator Jacobian, and commands tau = J^-T (M (qdd_d + Kd e' + Kp e) + c) from the nominal
model's task-space dynamics. Every generated function is called through
rpr3gen.SampleEvaluator (the generated C, preallocated buffers); the tick's own arithmetic is on
Python floats (a NumPy operation on a 3-vector costs more than the C it feeds). Prints the
tracking error, the failed calls and the latency (p50, p99, max) of the forward kinematics, of
the rest of the tick and of the whole controller tick. As in control_loop.c, the ticks alternate
between the two measures: an even tick is split at the end of its forward kinematics, an odd
tick is timed whole, with no clock read inside it.

The arguments are control_loop.c's, plus --model and --actuation (the C program's are its build):

    python control_loop.py [--params FILE] [--trajectory rectilinear|rotation] [--seconds T]
                           [--offset MM] [--model FILE] [--actuation revolute|prismatic]
                           [rectilinear|rotation]
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import time

import numpy as np

import rpr3gen

RATE_HZ = 1000  # controller ticks per second
SUBSTEPS = 4  # RK4 steps of the plant per tick (4 kHz)
KP, KD = 900.0, 60.0  # s^-2, s^-1: critically damped at 30 rad/s
RATE_CUTOFF_HZ = 100.0  # first-order low-pass on the differenced counts
TRANSIENT = 0.05  # s, left out of the "after" tracking error
COUNTS_PER_REV = 2**17  # revolute actuation: angle encoders
METRES_PER_COUNT = 1e-6  # prismatic actuation: linear encoders
DURATION = 3.0  # s, the paper's motions (eq. 3)
PERTURBED = {"m1": 1.03, "m2": 0.96, "m3": 1.05, "J1": 1.04, "J2": 0.97, "J3": 1.05}


def reference(amplitude: np.ndarray, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Paper eq. (3), q = q* (1 - cos(pi t / T)), and its first two derivatives."""
    w = math.pi / DURATION
    c, s = math.cos(w * t), math.sin(w * t)
    return amplitude * (1.0 - c), amplitude * (w * s), amplitude * (w * w * c)


class Plant:
    """The true robot: state (q, qd) of the platform, RK4 of the generated forward dynamics."""

    def __init__(self, truth: rpr3gen.Model, q: np.ndarray, resolution: float):
        self.dynamics = rpr3gen.SampleEvaluator(truth, function="forward_dynamics")
        self.coordinates = rpr3gen.SampleEvaluator(truth, function="actuator_coordinates")
        self.q, self.qd = q.astype(float), np.zeros(3)
        self.resolution = resolution

    def _acceleration(self, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        fd = self.dynamics
        fd.q[:], fd.qd[:] = q, qd
        if fd():
            raise RuntimeError(f"the plant reached a singular pose, q = {q.tolist()}")
        return fd.qdd.copy()

    def step(self, tau: np.ndarray, dt: float) -> None:
        """Advance by dt under the constant efforts tau (zero-order hold), RK4 in substeps."""
        self.dynamics.tau[:] = tau
        h = dt / SUBSTEPS
        q, qd = self.q, self.qd
        for _ in range(SUBSTEPS):
            a1 = self._acceleration(q, qd)
            v2 = qd + 0.5 * h * a1
            a2 = self._acceleration(q + 0.5 * h * qd, v2)
            v3 = qd + 0.5 * h * a2
            a3 = self._acceleration(q + 0.5 * h * v2, v3)
            v4 = qd + h * a3
            a4 = self._acceleration(q + h * v3, v4)
            q = q + h / 6.0 * (qd + 2.0 * v2 + 2.0 * v3 + v4)
            qd = qd + h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4)
        self.q, self.qd = q, qd

    def encoders(self) -> tuple[int, int, int]:
        """The encoder counts: the actuator coordinates rounded to whole counts."""
        self.coordinates.q[:] = self.q
        if self.coordinates():
            raise RuntimeError(f"the plant reached a singular pose, q = {self.q.tolist()}")
        a, b, c = np.rint(self.coordinates.qa / self.resolution).tolist()
        return int(a), int(b), int(c)


class Controller:
    """Encoder counts in, actuator efforts out; the nominal model's generated C functions."""

    def __init__(self, model: rpr3gen.Model, resolution: float, amplitude: np.ndarray):
        # Each a generated C function behind preallocated buffers; the velocity map and the
        # computed-torque law are generated too, so the tick does no 3 x 3 algebra in Python:
        # platform_velocity solves J qd = qa'; actuator_efforts at the commanded acceleration a
        # is tau = J^-T (M a + c) (the C program writes that law out with task_space_dynamics).
        # They share buffers: the pose the forward kinematics writes is the q the other two
        # read, the velocity platform_velocity writes is the qd actuator_efforts reads.
        self.fk = rpr3gen.SampleEvaluator(model, function="forward_kinematics")
        self.velocity = rpr3gen.SampleEvaluator(
            model, function="platform_velocity", buffers={"q": self.fk.q}
        )
        self.efforts = rpr3gen.SampleEvaluator(
            model, function="actuator_efforts", buffers={"q": self.fk.q, "qd": self.velocity.qd}
        )
        self.resolution, self.amplitude = resolution, amplitude.tolist()
        self.alpha = 1.0 - math.exp(-2.0 * math.pi * RATE_CUTOFF_HZ / RATE_HZ)
        self.q1 = [0.0, 0.0, 0.0]  # the last two pose estimates; the robot was parked at home
        self.q2 = [0.0, 0.0, 0.0]
        self.counts: tuple[int, int, int] | None = None
        self.rate = [0.0, 0.0, 0.0]  # filtered actuator rates
        self.qd = [0.0, 0.0, 0.0]
        self.tau = [0.0, 0.0, 0.0]
        self.failed = {"forward kinematics": 0, "jacobian": 0, "dynamics": 0}
        # ns: forward kinematics, the rest (a split tick), the whole tick (another); NaN unmeasured
        self.latency = [math.nan, math.nan, math.nan]

    def tick(self, counts: tuple[int, int, int], t: float, split: bool = False) -> list[float]:
        """Encoder counts at time t in, efforts out; latencies in :attr:`latency`: with
        ``split``, of the forward kinematics and of the rest (a clock read between them), else
        of the whole tick (no clock read inside it)."""
        clock = time.perf_counter_ns
        start = clock()
        res = self.resolution
        # actuator positions and rates from the counts
        fk = self.fk
        fk.qa[:] = (counts[0] * res, counts[1] * res, counts[2] * res)
        first = self.counts is None
        if not first:
            scale, alpha, old = res * RATE_HZ, self.alpha, self.counts
            self.rate = [r + alpha * ((c - o) * scale - r)
                         for r, c, o in zip(self.rate, counts, old, strict=True)]  # fmt: skip
        self.counts = counts
        # the reference (eq. 3) needs no measurement: first, as in control_loop.c
        w = math.pi / DURATION
        c, s = math.cos(w * t), math.sin(w * t)
        # the pose: tracked forward kinematics from the constant-velocity prediction
        q1, q2 = self.q1, self.q2
        near = (2.0 * q1[0] - q2[0], 2.0 * q1[1] - q2[1], 2.0 * q1[2] - q2[2])
        fk.q_near[:] = near
        status = fk()
        fk_end = clock() if split else 0
        if status:
            self.failed["forward kinematics"] += 1
            fk.q[:] = near  # coast on the prediction
        q = fk.q.tolist()
        self.q2, self.q1 = (q if first else q1), q  # at first, at rest
        # the velocity: J qd = qa' (the "jacobian" count is this solve's failures)
        vel = self.velocity
        vel.qa_dot[:] = self.rate
        if vel():
            self.failed["jacobian"] += 1
        else:
            self.qd = qd = vel.qd.tolist()
            # computed torque in task space: tau = J^-T (M (qdd_d + Kd e' + Kp e) + c)
            eff = self.efforts
            eff.qdd[:] = [a * (w * w * c) + KD * (a * (w * s) - v) + KP * (a * (1.0 - c) - x)
                          for a, v, x in zip(self.amplitude, qd, q, strict=True)]  # fmt: skip
            if eff():
                self.failed["dynamics"] += 1
            else:
                self.tau = eff.tau.tolist()
        end = clock()
        if split:
            self.latency = [fk_end - start, end - fk_end, math.nan]
        else:
            self.latency = [math.nan, math.nan, end - start]
        return self.tau


def percentiles(ns: np.ndarray) -> tuple[float, float, float]:
    """p50, p99 and max of the measured (not NaN) values, as control_loop.c picks them (ranks
    n/2 and 0.99 (n - 1) of the sorted); NaN when there is none."""
    s = np.sort(ns[~np.isnan(ns)])
    if len(s) == 0:
        return math.nan, math.nan, math.nan
    return float(s[len(s) // 2]), float(s[int(0.99 * (len(s) - 1))]), float(s[-1])


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", help="model file (default: the paper robot)")
    parser.add_argument("--actuation", choices=["revolute", "prismatic"],
                        help="override the model's actuation")  # fmt: skip
    trajectories = sorted(rpr3gen.trajectory.PAPER_TRAJECTORIES)
    parser.add_argument("--trajectory", choices=trajectories, default="rectilinear")
    parser.add_argument("--seconds", type=float, default=DURATION)
    parser.add_argument("--offset", type=float, default=0.0, metavar="MM",
                        help="start the plant MM millimetres off in x and -MM in y")  # fmt: skip
    parser.add_argument("--params", metavar="FILE",
                        help="numbers as `rpr3gen params` writes them")  # fmt: skip
    parser.add_argument("positional", nargs="?", choices=trajectories, metavar="TRAJECTORY",
                        help="the trajectory, as --trajectory")  # fmt: skip
    args = parser.parse_args()
    if not args.seconds > 0:
        parser.error("--seconds must be positive")
    args.trajectory = args.positional or args.trajectory

    model = rpr3gen.load_model(args.model)
    if args.actuation:
        model = dataclasses.replace(model, actuation=args.actuation)
    if args.params:
        with open(args.params, encoding="utf-8") as handle:
            given = {name: float(value) for name, value in (line.split() for line in handle)}
        model = dataclasses.replace(model, params={**model.params, **given})
    truth = dataclasses.replace(
        model, params={k: v * PERTURBED.get(k, 1.0) for k, v in model.params.items()}
    )
    revolute = model.actuation == "revolute"
    resolution = 2.0 * math.pi / COUNTS_PER_REV if revolute else METRES_PER_COUNT
    amplitude = np.array(rpr3gen.trajectory.PAPER_TRAJECTORIES[args.trajectory])
    plant = Plant(truth, np.array([1e-3, -1e-3, 0.0]) * args.offset, resolution)
    controller = Controller(model, resolution, amplitude)

    dt = 1.0 / RATE_HZ
    steps = round(args.seconds * RATE_HZ)
    latency = np.empty((steps, 3))
    error = np.empty((steps, 2))  # position (m), angle (rad), at the end of each tick
    estimate = np.empty((steps, 2))  # pose estimate vs plant, at each tick's reading
    velocity = np.empty((steps, 3))  # velocity estimate vs plant
    efforts = np.empty((steps, 3))
    for step in range(steps):
        t = step * dt
        counts = plant.encoders()
        tau = controller.tick(counts, t, split=step % 2 == 0)
        latency[step] = controller.latency
        d = np.array(controller.q1) - plant.q
        estimate[step] = math.hypot(d[0], d[1]), abs(d[2])
        velocity[step] = controller.qd - plant.qd
        efforts[step] = tau
        plant.step(tau, dt)
        d = plant.q - reference(amplitude, t + dt)[0]
        error[step] = math.hypot(d[0], d[1]), abs(d[2])

    if revolute:
        sensor = f"{COUNTS_PER_REV} counts/rev ({resolution * 1e6:.1f} urad/count)"
    else:
        sensor = f"{METRES_PER_COUNT * 1e6:g} um/count"
    print(f"trajectory {args.trajectory}, {steps} ticks at {RATE_HZ} Hz, {model.actuation} "
          f"actuation, start offset ({args.offset:.3f}, {0.0 - args.offset:.3f}) mm")  # fmt: skip
    print(f"plant: masses and inertias off by 3-5%, RK4 at {SUBSTEPS * RATE_HZ} Hz; encoders "
          f"{sensor}, rates from count differences, low-pass {RATE_CUTOFF_HZ:g} Hz")  # fmt: skip
    after = error[round(TRANSIENT * RATE_HZ) :]
    for label, e in ((f"after {TRANSIENT * 1e3:g} ms", after), ("overall", error)):
        if len(e) == 0:
            continue
        print(
            f"tracking error {label}: position rms {math.sqrt(np.mean(e[:, 0] ** 2)) * 1e3:.4f}"
            f" mm, max {e[:, 0].max() * 1e3:.4f} mm; angle rms "
            f"{math.sqrt(np.mean(e[:, 1] ** 2)) * 1e3:.4f} mrad, max {e[:, 1].max() * 1e3:.4f} mrad"
        )
    print(
        f"estimate error: pose max {estimate[:, 0].max() * 1e3:.4f} mm, "
        f"{estimate[:, 1].max() * 1e3:.4f} mrad; velocity rms "
        f"{math.sqrt(np.mean(np.sum(velocity[:, :2] ** 2, axis=1))) * 1e3:.3f} mm/s, "
        f"{math.sqrt(np.mean(velocity[:, 2] ** 2)) * 1e3:.3f} mrad/s"
    )
    unit = "N m" if revolute else "N"
    change = np.abs(np.diff(efforts, axis=0))
    print(
        f"efforts: rms {math.sqrt(np.mean(efforts**2)):.3f} {unit}; change per tick rms "
        f"{math.sqrt(np.mean(change**2)) if len(change) else 0.0:.4f} {unit}, "
        f"max {change.max() if len(change) else 0.0:.4f} {unit}"
    )
    print("failed calls: " + ", ".join(f"{k} {v}" for k, v in controller.failed.items()))
    for k, label in enumerate(("forward kinematics", "rest of the tick", "whole tick")):
        p50, p99, worst = percentiles(latency[:, k])
        if math.isnan(p50):
            print(f"latency {label}: no tick measured")
            continue
        print(
            f"latency {label}: p50 {p50 / 1e3:.2f} us, p99 {p99 / 1e3:.2f} us, "
            f"max {worst / 1e3:.2f} us"
        )
    return 1 if any(controller.failed.values()) else 0


if __name__ == "__main__":
    raise SystemExit(main())
