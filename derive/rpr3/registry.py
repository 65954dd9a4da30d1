"""The 3-RPR's registry of generated functions: one spec builder per function, per variant.

Each entry of :data:`FUNCTIONS` turns an actuation scheme into a
:class:`~rpr3gen_derive.codegen.spec.FunctionSpec`; :func:`module` gathers them, with the
parameter vector, return codes and thresholds they share, into the
:class:`~rpr3gen_derive.codegen.spec.ModuleSpec` of one variant (one folder of ``generated/``).
Adding a generated function is adding an entry here.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from functools import cache

import sympy as sp
from rpr3gen_derive.codegen.program import Program
from rpr3gen_derive.codegen.spec import (
    Argument,
    Check,
    Component,
    FunctionSpec,
    ModuleSpec,
    Output,
    ReturnCode,
    Threshold,
)
from rpr3gen_derive.rpr3 import control, direct_kinematics, identification
from rpr3gen_derive.rpr3 import symbols as syms
from rpr3gen_derive.rpr3.derivation import (
    ACTUATIONS,
    OUTPUT_DOCS,
    OUTPUT_FAMILIES,
    OUTPUT_NAMES,
    PARAM_DOCS,
    SAMPLE_OUTPUTS,
    derive,
)
from rpr3gen_derive.rpr3.symbols import LEGS, PARAM_NAMES

__all__ = [
    "ACTUATIONS",
    "FUNCTIONS",
    "OUTPUT_FAMILIES",
    "OUTPUT_NAMES",
    "PARAM_NAMES",
    "SAMPLE_OUTPUTS",
    "clear_cache",
    "derive",
    "module",
]

PREFIX = "rpr3"

PARAMS = Argument(
    name="params",
    symbols=tuple(syms.params[name] for name in PARAM_NAMES),
    components=tuple(Component(name, unit, meaning) for name, unit, meaning in PARAM_DOCS),
    doc="model parameters",
    table="param_names",
)

POSE = Argument(
    "q",
    tuple(syms.q),
    (
        Component("x", "m", "platform centre G, world x0"),
        Component("y", "m", "platform centre G, world y0"),
        Component("phi", "rad", "platform rotation from the central configuration"),
    ),
    "platform centre G in the world frame (m), platform angle (rad)",
)
VELOCITY = Argument(
    "qd",
    tuple(syms.qd),
    tuple(Component(f"d{c.name}", f"{c.unit}/s", f"d({c.name})/dt") for c in POSE.components),
    "its time derivative (m/s, rad/s)",
)
ACCELERATION = Argument(
    "qdd",
    tuple(syms.qdd),
    tuple(Component(f"dd{c.name}", f"{c.unit}/s^2", f"d2({c.name})/dt2") for c in POSE.components),
    "its second time derivative (m/s^2, rad/s^2)",
)

RETURN_CODES: tuple[ReturnCode, ...] = (
    ReturnCode("OK", 0, "success"),
    ReturnCode("NOT_FINITE", 1, "an input is NaN or infinite"),
    ReturnCode(
        "SINGULAR",
        2,
        "singular or degenerate pose: a piston joint on or behind its base pivot (reach below "
        "MIN_REACH), conditioning below MIN_CONDITIONING, or a result that would not be finite",
    ),
    ReturnCode("NO_MODE", 3, "no assembly mode for these actuator coordinates"),
)

THRESHOLDS: tuple[Threshold, ...] = (
    Threshold(
        "MIN_REACH",
        "1e-9",
        'Output "reach" (min over legs of |A1A2| / l0; 1 in the central configuration) under '
        "which a pose is refused: a piston joint on or behind its base pivot, which also keeps "
        "every leg clear of the serial singularity |A1A3| = 0.",
    ),
    Threshold(
        "MIN_CONDITIONING",
        "1e-9",
        'Output "conditioning" (0 at a parallel singularity, 1 at best) under which a pose '
        "counts as singular: the loads there are dominated by round-off. Applications usually "
        "want a larger margin of their own (rpr3gen simulate refuses poses under 1e-3 by "
        "default).",
    ),
)

#: The failure conditions of a function of the pose, in the order they are tested.
SINGULAR_POSE_CHECKS: tuple[Check, ...] = (
    Check("inputs_not_finite", "NOT_FINITE"),
    Check("below", "SINGULAR", "out", "reach", "MIN_REACH"),
    Check("below", "SINGULAR", "out", "conditioning", "MIN_CONDITIONING"),
    Check("outputs_not_finite", "SINGULAR"),
)


def inverse_dynamics(actuation: str) -> FunctionSpec:
    """``rpr3_inverse_dynamics``: leg kinematics and every joint load (eqs. 5-17)."""
    prog, outputs = derive(actuation)
    actuated = "m10 at A1 (f21z = 0)" if actuation == "revolute" else "f21z at A2 (m10 = 0)"
    doc = (
        f"Inverse dynamics of the 3-RPR planar parallel robot, {actuation} actuation: "
        f"actuator load {actuated}. Leg kinematics (eqs. 5, 6, 9) and every joint load "
        "(eqs. 12-17) from the platform pose q = (x, y, phi), its velocity qd and acceleration qdd."
    )
    return FunctionSpec(
        name="inverse_dynamics",
        doc=doc,
        inputs=(POSE, VELOCITY, ACCELERATION),
        outputs=(
            Output(
                "out",
                tuple(outputs.values()),
                tuple(Component(name, unit, meaning) for name, unit, meaning in OUTPUT_DOCS),
                "row k receives OUTPUT_NAMES[k] (loads: exerted by body k-1 on body k); the rows "
                "of a singular pose hold inf or nan",
                table="output_names",
            ),
        ),
        program=prog,
        checks=SINGULAR_POSE_CHECKS,
    )


# -- the control model: actuator coordinates, Jacobian, task-space and forward dynamics, FK ----


def actuator_argument(actuation: str) -> Argument:
    """``qa``: the actuator coordinates (docs/interfaces.md, "Control model")."""
    family = control.ACTUATORS[actuation].coordinate
    unit = "rad" if actuation == "revolute" else "m"
    meaning = "cylinder rotation" if actuation == "revolute" else "piston displacement"
    return Argument(
        "qa",
        tuple(control.qa),
        tuple(Component(f"{family}_{leg}", unit, f"{meaning}, leg {leg}") for leg in LEGS),
        f"actuator coordinates ({family}_A, _B, _C, from the central configuration)",
    )


def effort_argument(actuation: str) -> Argument:
    """``tau``: the actuator efforts."""
    family = control.ACTUATORS[actuation].effort
    unit = "N m" if actuation == "revolute" else "N"
    return Argument(
        "tau",
        tuple(control.tau),
        tuple(Component(f"{family}_{leg}", unit, f"actuator effort, leg {leg}") for leg in LEGS),
        f"actuator efforts ({family}_A, _B, _C)",
    )


def _pose_checks(prog: Program, actuation: str) -> tuple[Check, ...]:
    """The failure conditions of the inverse dynamics, on the same values, as guards."""
    outputs = control.include_inverse_dynamics(prog, actuation).outputs
    return (
        Check("inputs_not_finite", "NOT_FINITE"),
        Check("below", "SINGULAR", threshold="MIN_REACH", guard=("reach", outputs["reach"])),
        Check(
            "below",
            "SINGULAR",
            threshold="MIN_CONDITIONING",
            guard=("conditioning", outputs["conditioning"]),
        ),
        Check("outputs_not_finite", "SINGULAR"),
    )


def _matrix(
    name: str,
    m: sp.Matrix,
    units: tuple[str, ...],
    meaning: str,
    entry: Callable[[int, int], str] = lambda i, j: "",
) -> Output:
    """A 3 x 3 matrix output, row-major; ``units`` per column (3) or per entry (9)."""
    return Output(
        name,
        tuple(m[i, j] for i in range(3) for j in range(3)),
        tuple(
            Component(
                f"{name}{i + 1}{j + 1}",
                units[j] if len(units) == 3 else units[3 * i + j],
                entry(i, j),
            )
            for i in range(3)
            for j in range(3)
        ),
        meaning,
    )


def _triple(name: str, v: sp.Matrix, names: tuple[str, ...], units: tuple[str, ...], doc: str):
    return Output(
        name,
        tuple(v[k] for k in range(3)),
        tuple(Component(n, u) for n, u in zip(names, units, strict=True)),
        doc,
    )


def _rate_units(actuation: str, per: str) -> tuple[str, ...]:
    unit = "rad" if actuation == "revolute" else "m"
    return (f"{unit}/{per}",) * 3


def actuator_coordinates(actuation: str) -> FunctionSpec:
    """``rpr3_actuator_coordinates``: ``qa`` of a pose, the inverse kinematics of eq. (5)."""
    prog = Program()
    derivation = control.include_inverse_dynamics(prog, actuation)
    family = control.ACTUATORS[actuation].coordinate
    values = sp.Matrix([derivation.outputs[f"{family}_{leg}"] for leg in LEGS])
    qa = actuator_argument(actuation)
    return FunctionSpec(
        name="actuator_coordinates",
        doc=f"Actuator coordinates qa = ({family}_A, _B, _C) of the platform pose q (eq. 5).",
        inputs=(POSE,),
        outputs=(
            _triple(
                "qa",
                values,
                tuple(c.name for c in qa.components),
                (qa.components[0].unit,) * 3,
                qa.doc,
            ),
        ),
        program=prog,
        checks=_pose_checks(prog, actuation),
    )


def actuator_jacobian(actuation: str) -> FunctionSpec:
    """``rpr3_actuator_jacobian``: ``J = d qa / d q``, row-major, so that ``qa' = J q'``."""
    prog = Program()
    J = control.actuator_jacobian(prog, actuation)
    units = ("1/m", "1/m", "1") if actuation == "revolute" else ("1", "1", "m")
    qa_names = [c.name for c in actuator_argument(actuation).components]
    return FunctionSpec(
        name="actuator_jacobian",
        doc="Actuator Jacobian J = d qa / d q (eq. 6 differentiated), row-major, one row per "
        "leg A, B, C: qa' = J q'. det J = 0 at a parallel singularity.",
        inputs=(POSE,),
        outputs=(
            _matrix(
                "J",
                J,
                units,
                "J = d qa / d q, row-major",
                lambda i, j: f"d {qa_names[i]} / d {POSE.components[j].name}",
            ),
        ),
        program=prog,
        checks=_pose_checks(prog, actuation),
    )


def jacobian_rate(actuation: str) -> FunctionSpec:
    """``rpr3_jacobian_rate``: ``J' q'``, so that ``qa'' = J q'' + J' q'`` (eq. 9)."""
    prog = Program()
    rate = control.jacobian_rate_term(prog, actuation)
    qa = actuator_argument(actuation)
    return FunctionSpec(
        name="jacobian_rate",
        doc="J' q': the actuator accelerations at zero platform acceleration (eq. 9), so that "
        "qa'' = J q'' + J' q'.",
        inputs=(POSE, VELOCITY),
        outputs=(
            _triple(
                "Jdqd",
                rate,
                tuple(f"dd{c.name}" for c in qa.components),
                _rate_units(actuation, "s^2"),
                "J' q'",
            ),
        ),
        program=prog,
        checks=_pose_checks(prog, actuation),
    )


def platform_velocity(actuation: str) -> FunctionSpec:
    """``rpr3_platform_velocity``: ``q' = J^-1 qa'``, the velocity map backwards."""
    prog = Program()
    qd = control.platform_velocity(prog, actuation)
    qa = actuator_argument(actuation)
    rates = Argument(
        "qa_dot",
        tuple(control.qa_dot),
        tuple(Component(f"d{c.name}", f"{c.unit}/s", f"rate of {c.name}") for c in qa.components),
        "actuator rates",
    )
    return FunctionSpec(
        name="platform_velocity",
        doc="Platform velocity q' = J^-1 qa' from the actuator rates (a generated 3 x 3 solve by "
        "cofactors): the velocity a controller reconstructs from its encoders.",
        inputs=(POSE, rates),
        outputs=(
            _triple(
                "qd",
                qd,
                tuple(c.name for c in VELOCITY.components),
                tuple(c.unit for c in VELOCITY.components),
                "platform velocity",
            ),
        ),
        program=prog,
        checks=_pose_checks(prog, actuation),
    )


def actuator_efforts(actuation: str) -> FunctionSpec:
    """``rpr3_actuator_efforts``: the actuator efforts alone of the inverse dynamics."""
    prog = Program()
    outputs = control.include_inverse_dynamics(prog, actuation).outputs
    tau = effort_argument(actuation)
    family = control.ACTUATORS[actuation].effort
    return FunctionSpec(
        name="actuator_efforts",
        doc=f"Actuator efforts ({family}_A, _B, _C) that produce the platform acceleration qdd at "
        "(q, qd): the inverse dynamics' actuator loads (eqs. 12-17) alone, which is also "
        "tau = J^-T (M qdd + c), the computed-torque law's efforts for a commanded qdd.",
        inputs=(POSE, VELOCITY, ACCELERATION),
        outputs=(
            _triple(
                "tau",
                sp.Matrix([outputs[f"{family}_{leg}"] for leg in LEGS]),
                tuple(c.name for c in tau.components),
                tuple(c.unit for c in tau.components),
                "actuator efforts",
            ),
        ),
        program=prog,
        checks=_pose_checks(prog, actuation),
    )


def task_space_dynamics(actuation: str) -> FunctionSpec:
    """``rpr3_task_space_dynamics``: ``M`` (row-major) and ``c`` with ``M q'' + c = J^T tau``."""
    prog = Program()
    M, c = control.task_space_dynamics(prog, actuation)
    return FunctionSpec(
        name="task_space_dynamics",
        doc="Dynamics in control form, M q'' + c = J^T tau, from the virtual work of the "
        "required wrenches of eqs. (10)-(17): M (row-major, symmetric positive definite) and c "
        "(Coriolis and centripetal terms, gravity, payload).",
        inputs=(POSE, VELOCITY),
        outputs=(
            _matrix(
                "M",
                M,
                ("kg", "kg", "kg m", "kg", "kg", "kg m", "kg m", "kg m", "kg m^2"),
                "mass matrix in platform coordinates, row-major",
            ),
            _triple("c", c, ("c_x", "c_y", "c_phi"), ("N", "N", "N m"), "bias forces"),
        ),
        program=prog,
        checks=_pose_checks(prog, actuation),
    )


def forward_dynamics(actuation: str) -> FunctionSpec:
    """``rpr3_forward_dynamics``: ``q'' = M^-1 (J^T tau - c)``, by an LDL^T solve."""
    prog = Program()
    qdd = control.forward_dynamics(prog, actuation)
    return FunctionSpec(
        name="forward_dynamics",
        doc="Forward dynamics: the platform acceleration q'' = M^-1 (J^T tau - c) under the "
        "actuator efforts tau, by an explicit LDL^T solve of the task-space dynamics.",
        inputs=(POSE, VELOCITY, effort_argument(actuation)),
        outputs=(
            _triple(
                "qdd",
                qdd,
                tuple(c.name for c in ACCELERATION.components),
                tuple(c.unit for c in ACCELERATION.components),
                "platform acceleration",
            ),
        ),
        program=prog,
        checks=_pose_checks(prog, actuation),
    )


def assembly_modes(actuation: str) -> FunctionSpec:
    """``rpr3_assembly_modes``: the direct kinematics' closed forms.

    Revolute actuation: both modes (x, y, phi) and their margins (a mode exists where its
    margin is >= 0). Prismatic: the coefficients of the sextic in tan(phi/2), whose real roots
    :func:`pose_from_angle` turns into poses.
    """
    prog = Program()
    qa = actuator_argument(actuation)
    checks = (Check("inputs_not_finite", "NOT_FINITE"),)
    if actuation == "revolute":
        modes = direct_kinematics.assembly_modes_revolute(prog)
        return FunctionSpec(
            name="assembly_modes",
            doc="Both assembly modes of the actuator angles qa, in closed form: the closure "
            "reduces to A cos(phi) + B sin(phi) + C = 0. A mode exists where its margin >= 0.",
            inputs=(qa,),
            outputs=(
                Output(
                    "modes",
                    tuple(getattr(m, k) for m in modes for k in ("x", "y", "phi")),
                    tuple(
                        Component(f"{k}{i + 1}", u)
                        for i in range(2)
                        for k, u in (("x", "m"), ("y", "m"), ("phi", "rad"))
                    ),
                    "the two modes (x, y, phi), phi in [-pi, pi]",
                ),
                Output(
                    "margins",
                    tuple(m.margin for m in modes),
                    (Component("margin1"), Component("margin2")),
                    "a mode exists where its margin is >= 0",
                ),
            ),
            program=prog,
            checks=checks,
        )
    coefficients = direct_kinematics.sextic_coefficients(prog)
    return FunctionSpec(
        name="assembly_modes",
        doc="The direct kinematics of the piston displacements qa as a polynomial: coefficients "
        "a0..a6 of sum a_j t^j = 0, t = tan(phi/2) (Gosselin; Merlet), whose real roots give "
        "every assembly mode (then pose_from_angle).",
        inputs=(qa,),
        outputs=(
            Output(
                "a",
                tuple(coefficients),
                tuple(Component(f"a{j}") for j in range(7)),
                "coefficients of t^0 .. t^6",
            ),
        ),
        program=prog,
        checks=checks,
    )


ANGLE = Argument(
    "angle",
    (sp.Symbol("cos_phi_in", real=True), sp.Symbol("sin_phi_in", real=True)),
    (Component("cos_phi"), Component("sin_phi")),
    "cosine and sine of the platform angle",
)


def pose_from_angle(actuation: str) -> FunctionSpec | None:
    """``rpr3_pose_from_angle`` (prismatic actuation): G for a root phi of the sextic."""
    if actuation != "prismatic":
        return None
    prog = Program()
    x, y = direct_kinematics.pose_from_angle(prog, *ANGLE.symbols)
    return FunctionSpec(
        name="pose_from_angle",
        doc="Position of G for a platform angle phi that solves the direct kinematics of the "
        "piston displacements qa (back substitution of the sextic's root).",
        inputs=(actuator_argument(actuation), ANGLE),
        outputs=(Output("xy", (x, y), (Component("x", "m"), Component("y", "m")), "G"),),
        program=prog,
        checks=(Check("inputs_not_finite", "NOT_FINITE"),),
    )


#: The tracked forward kinematics' numbers, for its C body (``c_context``), as in
#: ``tests/fk_reference.py`` (``tracked_forward_kinematics``), whose prototype it ports.
FK_TUNING: tuple[tuple[str, object], ...] = (
    ("max_iter", 8),  # Newton steps from q_near before the fallback
    ("polish_iter", 20),  # Newton steps polishing a mode of the sextic (prismatic)
    ("max_halvings", 12),  # of the step, in the line search
    ("tol", "1e-12"),  # converged: the largest residual |qa(q) - qa| (rad or m)
    ("det_tol", "1e-14"),  # singular J: |det J| under this times the product of its row norms
    ("samples", 256),  # cells of t in [-1, 1], and as many of u = 1/t in [-1, 1] (prismatic)
    ("bisections", 60),  # per root, or per extremum of a cell without a sign change
    ("touch_tol", "1e-9"),  # an extremum within this of the sextic's scale of zero is a root
    ("merge_tol", "1e-9"),  # roots (rad) closer than this are one
    ("parallel_tol", "1e-6"),  # back substitution: |D| <= this |w_B| |w_C| is parallel
    ("max_roots", 16),  # sampled roots kept (a real sextic has 6; t = +-1 is sampled twice)
)


def _forward_kinematics_doc(actuation: str) -> str:
    """The header's comment of ``rpr3_forward_kinematics``, with the numbers of FK_TUNING."""
    n = dict(FK_TUNING)
    if actuation == "revolute":
        modes = "both closed-form modes of assembly_modes (where their margins are >= 0)"
    else:
        modes = (
            "the real roots of the sextic of assembly_modes, without a polynomial solver: "
            f"sampled at {n['samples']} cells of t = tan(phi/2) in [-1, 1] and as many of "
            "1/t in [-1, 1], each sign change bisected, a cell with an extremum split there "
            "(close pairs, double roots); back substituted by pose_from_angle (or, where its "
            "two equations are parallel, by a line and a circle) and polished by the same "
            f"Newton ({n['polish_iter']} steps); none when a leg length l0 + l2 + qa_i is not "
            "positive"
        )
    return (
        "Tracked forward kinematics: the assembly mode of the actuator coordinates qa nearest "
        "the reference pose q_near (distance in (x, y, rho phi), rho the platform's RMS joint "
        "radius), phi unwrapped next to q_near's. (1) Damped Newton from q_near with the "
        "generated Jacobian: J dq = -r (r = qa(q) - qa, angles wrapped), the step limited to "
        f"rho in that metric and halved (at most {n['max_halvings']} times) until the largest "
        f"residual drops by 1 - t/2; converged when it is <= {n['tol']} (rad or m), at most "
        f"{n['max_iter']} steps. (2) Its pose is returned when it converged, every leg has a "
        "positive length and det J has the sign it has at q_near (same aspect). (3) Otherwise "
        "(no convergence, a singular J, a failed line search, another aspect) the fallback: "
        f"every mode, {modes}; the nearest wins. RPR3_NO_MODE, q untouched, when there is no "
        "mode. Limits: through a parallel singularity only a predicted reference "
        "(2 q[k-1] - q[k-2]) follows the robot (the previous pose makes it turn back); the "
        "aspect test cannot tell apart two modes of one aspect; "
        + (
            ""
            if actuation == "revolute"
            else "the sampling misses a root pair that round-off keeps from touching zero and "
            "three roots in one cell; "
        )
        + "the fallback costs several Newton solves. No allocation, no state."
    )


def forward_kinematics(actuation: str) -> FunctionSpec:
    """``rpr3_forward_kinematics``: the assembly mode of ``qa`` nearest a reference pose.

    C only: a hand-written body (``templates/forward_kinematics.c.jinja``) that calls the
    generated kernels of ``actuator_coordinates``, ``actuator_jacobian``, ``assembly_modes`` and
    ``pose_from_angle``; it ports ``tests/fk_reference.py`` (``tracked_forward_kinematics``).

    1. Damped Newton on ``qa(q) = qa`` from ``q_near`` (residual of angles wrapped): ``J dq =
       -r`` by cofactors, the step limited to ``rho`` in the metric ``(x, y, rho phi)``, halved
       (at most 12 times) until the largest residual drops by ``1 - t/2``; converged when the
       largest residual is ``<= 1e-12`` (rad or m), at most 8 steps. It fails on a singular J
       (``|det J| <= 1e-14`` times the product of its row norms), a failed line search or the
       step limit.
    2. Its pose is accepted when it converged, every leg has a positive length (revolute:
       ``(A3 - A1) . e_i`` along the measured leg axis; prismatic: ``|A1A3|``; above
       ``LENGTH_TOL rho``) and ``det J`` has the sign it has at ``q_near`` (no crossing of a
       parallel singularity into the other aspect).
    3. Else the fallback: every assembly mode, each with ``phi`` wrapped, then unwrapped next to
       ``q_near[2]``, and the nearest in ``(x, y, rho phi)``. Revolute: both closed-form modes
       of ``assembly_modes`` where their margins are ``>= 0``. Prismatic: no mode when a leg
       length ``l0 + l2 + qa_i <= LENGTH_TOL rho`` or the sextic vanishes; its real roots by
       sampling ``p(t)`` at 257 points of ``t`` in ``[-1, 1]`` and ``u^6 p(1/u)`` at 257 points
       of ``u = 1/t`` in ``[-1, 1]``, 60 bisections per sign change, a cell without one but
       with a sign change of ``p'`` split at the extremum (two close roots, or a double root if
       ``p`` touches zero there to ``1e-9`` of its scale); roots merged within 1e-9 rad, at most
       6; back substitution by ``pose_from_angle``, or where ``|D| <= 1e-6 |w_B| |w_C|`` by the
       line ``u . w = rho`` of the longer ``w`` and the circle ``|u| = L_A`` (none if both
       ``w`` vanish); each candidate polished by the same Newton (20 steps), dropped when it
       does not converge. No mode at all: ``RPR3_NO_MODE``, the output untouched.

    Limits (``docs/control-model.md``, "Known limitations"): through a parallel singularity only
    a predicted reference follows the robot; ``sign det J`` cannot tell apart two modes of one
    aspect; the sampling misses a root pair that round-off keeps from touching zero, and three
    roots in one cell; the fallback costs 5 to 20 Newton solves.

    Fixed-size arrays, fixed loop bounds, no allocation or state. The numbers are
    :data:`FK_TUNING`; ``trace=True`` (test builds only) makes the body call
    ``rpr3_fk_trace(steps, how)`` (``how``: 0 Newton, 1 fallback, 2 none), which the test's
    harness defines.
    """
    qa = actuator_argument(actuation)
    near = Argument(
        "q_near",
        tuple(sp.Symbol(f"{c.name}_near", real=True) for c in POSE.components),
        tuple(Component(c.name, c.unit, c.meaning) for c in POSE.components),
        "the reference pose: the previous solution, or better a prediction from the last two",
    )
    return FunctionSpec(
        name="forward_kinematics",
        doc=_forward_kinematics_doc(actuation),
        inputs=(qa, near),
        outputs=(
            Output(
                "q",
                (sp.Integer(0),) * 3,
                POSE.components,
                "the pose found",
            ),
        ),
        program=Program(),
        checks=(Check("inputs_not_finite", "NOT_FINITE"), Check("custom", "NO_MODE")),
        c_body="forward_kinematics.c.jinja",
        c_kernels=("trig", "minmax"),
        c_values=("actuator_coordinates", "actuator_jacobian"),
        c_context=(
            ("actuation", actuation),
            ("max_modes", direct_kinematics.MAX_MODES[actuation]),
            ("length_tol", repr(direct_kinematics.LENGTH_TOL)),
            ("param_names", PARAM_NAMES),
            *FK_TUNING,
            ("trace", False),
        ),
    )


# -- dynamic identification: the regressor and the payload's efforts (docs/identification.md) --

#: Unit of each inertial quantity (docs/identification.md).
_PI_UNITS = {"m": "kg", "mcx": "kg m", "mcy": "kg m", "Jzz": "kg m^2"}
#: Unit of Y's entries per actuation and quantity: the effort's unit over the parameter's.
_Y_UNITS = {
    "revolute": {"m": "m^2/s^2", "mcx": "m/s^2", "mcy": "m/s^2", "Jzz": "1/s^2"},
    "prismatic": {"m": "m/s^2", "mcx": "1/s^2", "mcy": "1/s^2", "Jzz": "1/(m s^2)"},
}


_QUANTITY = {"m": "mass", "mcx": "first moment x", "mcy": "first moment y", "Jzz": "inertia"}
_BODY = {"1": "cylinder", "2": "piston", "3": "platform"}


def _pi_component(name: str) -> Component:
    """``mcx_2B`` -> unit and meaning (docs/identification.md)."""
    quantity, body = name.split("_")
    leg = f" of leg {body[1]}" if len(body) > 1 else ""
    return Component(
        name, _PI_UNITS[quantity], f"{_QUANTITY[quantity]} of the {_BODY[body[0]]}{leg}"
    )


#: The inertial parameters pi, the columns of Y: C table ``rpr3_inertial_parameter_names``.
INERTIAL_PARAMETERS = Argument(
    "pi",
    tuple(identification.pi_symbols[n] for n in identification.INERTIAL_PARAMETER_NAMES),
    tuple(_pi_component(n) for n in identification.INERTIAL_PARAMETER_NAMES),
    "inertial parameters (per moving body: m, m cx, m cy, Jzz about its joint point)",
    table="inertial_parameter_names",
)


def regressor(actuation: str) -> FunctionSpec:
    """``rpr3_regressor``: ``Y`` (3 x P, row-major) with ``tau = Y pi + tau_payload``."""
    prog = Program()
    checks = _pose_checks(prog, actuation)
    Y = identification.regressor(prog, actuation)
    family = control.ACTUATORS[actuation].effort
    names = identification.INERTIAL_PARAMETER_NAMES
    units = _Y_UNITS[actuation]
    return FunctionSpec(
        name="regressor",
        doc=f"Identification regressor Y (3 x {len(names)}, row-major; row i: {family} of leg "
        "A, B, C; column j: INERTIAL_PARAMETER_NAMES[j]) with tau = Y pi + tau_payload: the "
        "actuator efforts of eqs. (10)-(17) differentiated by the inertial parameters pi (per "
        "moving body m, m cx, m cy, Jzz about its joint point; docs/identification.md).",
        inputs=(POSE, VELOCITY, ACCELERATION),
        outputs=(
            Output(
                "Y",
                tuple(Y[i, j] for i in range(3) for j in range(len(names))),
                tuple(
                    Component(
                        f"Y_{leg}__{name}",
                        units[name.split("_")[0]],
                        f"d {family}_{leg} / d {name} ({_PI_UNITS[name.split('_')[0]]})",
                    )
                    for leg in LEGS
                    for name in names
                ),
                f"Y = d tau / d pi, row-major (3 x {len(names)}; columns: "
                "rpr3_inertial_parameter_names)",
            ),
        ),
        program=prog,
        checks=checks,
    )


def payload_efforts(actuation: str) -> FunctionSpec:
    """``rpr3_payload_efforts``: the efforts that hold the payload wrench at rest."""
    prog = Program()
    checks = _pose_checks(prog, actuation)
    tau = identification.payload_efforts(prog, actuation)
    arg = effort_argument(actuation)
    return FunctionSpec(
        name="payload_efforts",
        doc="tau_payload: the actuator efforts holding the payload wrench (fx, fy at G, mz) at "
        "rest, the part of tau = Y pi + tau_payload that scales with no inertial parameter "
        "(eqs. 12-17 with only the payload acting); a function of the pose alone.",
        inputs=(POSE,),
        outputs=(
            _triple(
                "tau_payload",
                tau,
                tuple(c.name for c in arg.components),
                tuple(c.unit for c in arg.components),
                "efforts holding the payload",
            ),
        ),
        program=prog,
        checks=checks,
    )


FunctionBuilder = Callable[[str], FunctionSpec | None]

#: Every generated function, by name: a builder from the actuation scheme to its spec. A builder
#: may return None for a variant that has no such function.
FUNCTIONS: Mapping[str, FunctionBuilder] = {
    "inverse_dynamics": inverse_dynamics,
    "actuator_coordinates": actuator_coordinates,
    "actuator_jacobian": actuator_jacobian,
    "jacobian_rate": jacobian_rate,
    "platform_velocity": platform_velocity,
    "actuator_efforts": actuator_efforts,
    "task_space_dynamics": task_space_dynamics,
    "forward_dynamics": forward_dynamics,
    "assembly_modes": assembly_modes,
    "pose_from_angle": pose_from_angle,
    "forward_kinematics": forward_kinematics,
    "regressor": regressor,
    "payload_efforts": payload_efforts,
}


@cache
def _spec(builder: FunctionBuilder, actuation: str) -> FunctionSpec | None:
    return builder(actuation)


def clear_cache() -> None:
    """Forget the specs derived so far (they are derived once per process otherwise)."""
    _spec.cache_clear()


def module(actuation: str, functions: Mapping[str, FunctionBuilder] | None = None) -> ModuleSpec:
    """The generated module of one actuation scheme: every function of ``functions``."""
    if actuation not in ACTUATIONS:
        raise ValueError(f"actuation must be one of {ACTUATIONS}, got {actuation!r}")
    functions = FUNCTIONS if functions is None else functions
    return ModuleSpec(
        prefix=PREFIX,
        variant=actuation,
        doc=(
            f"Generated functions of the 3-RPR planar parallel robot (S. Staicu), {actuation} "
            "actuation. Model numbers are inputs (params), so one build serves every robot of "
            "this structure."
        ),
        params=PARAMS,
        functions=tuple(
            spec
            for builder in functions.values()
            if (spec := _spec(builder, actuation)) is not None
        ),
        return_codes=RETURN_CODES,
        thresholds=THRESHOLDS,
        tables=(INERTIAL_PARAMETERS,),
        defines=(
            ("ACTUATION", f'"{actuation}"', ""),
            (
                "MAX_MODES",
                str(direct_kinematics.MAX_MODES[actuation]),
                "most assembly modes of one qa",
            ),
        ),
    )
