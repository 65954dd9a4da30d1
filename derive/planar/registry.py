"""The registry of generated functions: one spec builder per function, for any structure.

Each entry of :data:`FUNCTIONS` turns a :class:`~.structures.Structure` into a
:class:`~rpr3gen_derive.codegen.spec.FunctionSpec` (or None where a structure has no such
function); :func:`module` gathers them, with the parameter vector, return codes and thresholds
they share, into the :class:`~rpr3gen_derive.codegen.spec.ModuleSpec` of one variant (one
folder of generated code). Adding a generated function is adding an entry here.
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
from rpr3gen_derive.planar import (
    control,
    direct_kinematics,
    general,
    identification,
    outputs,
    paper,
    structures,
)
from rpr3gen_derive.planar import symbols as syms
from rpr3gen_derive.planar.geometry import LEGS
from rpr3gen_derive.planar.structures import Structure

PREFIX = "rpr3"


def _param_doc(structure: Structure, name: str) -> tuple[str, str]:
    return paper.param_doc(name) if structure.paper else general.param_doc(name)


def params_argument(structure: Structure) -> Argument:
    """The parameter vector of a structure's variant (C table ``rpr3_param_names``)."""
    names = structures.param_names(structure)
    symbol = paper.params.__getitem__ if structure.paper else general.param_symbol
    return Argument(
        name="params",
        symbols=tuple(symbol(n) for n in names),
        components=tuple(Component(n, *_param_doc(structure, n)) for n in names),
        doc="model parameters",
        table="param_names",
    )


POSE = Argument(
    "q",
    tuple(syms.q),
    (
        Component("x", "m", "platform centre G, world x0"),
        Component("y", "m", "platform centre G, world y0"),
        Component("phi", "rad", "platform rotation from the central configuration (home)"),
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
        "singular or degenerate pose: a serial singularity of a leg or a pose outside its "
        "reach (reach below MIN_REACH), conditioning below MIN_CONDITIONING, or a result that "
        "would not be finite",
    ),
    ReturnCode("NO_MODE", 3, "no assembly mode for these actuator coordinates"),
)


def thresholds(structure: Structure) -> tuple[Threshold, ...]:
    """The failure thresholds of a variant (their meaning of ``reach`` differs by format)."""
    reach = (
        'Output "reach" (min over legs of |A1A2| / l0; 1 in the central configuration) under '
        "which a pose is refused: a piston joint on or behind its base pivot, which also keeps "
        "every leg clear of the serial singularity |A1A3| = 0."
        if structure.paper
        else 'Output "reach" (min over legs of D / D(home), D the leg\'s serial determinant; 1 '
        "at home) under which a pose is refused: a leg at or near a serial singularity."
    )
    return (
        Threshold("MIN_REACH", "1e-9", reach),
        Threshold(
            "MIN_CONDITIONING",
            "1e-9",
            'Output "conditioning" (0 at a parallel singularity, 1 at best) under which a pose '
            "counts as singular: the loads there are dominated by round-off. Applications "
            "usually want a larger margin of their own (rpr3gen simulate refuses poses under "
            "1e-3 by default).",
        ),
    )


#: The failure conditions of a function of the pose, in the order they are tested.
SINGULAR_POSE_CHECKS: tuple[Check, ...] = (
    Check("inputs_not_finite", "NOT_FINITE"),
    Check("below", "SINGULAR", "out", "reach", "MIN_REACH"),
    Check("below", "SINGULAR", "out", "conditioning", "MIN_CONDITIONING"),
    Check("outputs_not_finite", "SINGULAR"),
)


def inverse_dynamics(structure: Structure) -> FunctionSpec:
    """``rpr3_inverse_dynamics``: leg kinematics and every joint load (eqs. 5-17)."""
    derivation = control.inverse_dynamics(structure)
    family = outputs.effort_family(structure)
    doc = (
        f"Inverse dynamics of the {structure.title}: actuator efforts {family}_A, _B, _C. Leg "
        "kinematics (eqs. 5, 6, 9) and every joint load (eqs. 12-17) from the platform pose "
        "q = (x, y, phi), its velocity qd and acceleration qdd."
    )
    return FunctionSpec(
        name="inverse_dynamics",
        doc=doc,
        inputs=(POSE, VELOCITY, ACCELERATION),
        outputs=(
            Output(
                "out",
                tuple(derivation.outputs.values()),
                tuple(Component(*doc_) for doc_ in outputs.output_docs(structure)),
                "row k receives OUTPUT_NAMES[k] (loads: exerted by the earlier body on the later "
                "one); the rows of a singular pose hold inf or nan",
                table="output_names",
            ),
        ),
        program=derivation.program,
        checks=SINGULAR_POSE_CHECKS,
    )


# -- the control model: actuator coordinates, Jacobian, task-space and forward dynamics, FK ----


def _coordinate_unit(structure: Structure) -> str:
    return "rad" if structure.actuated_kind == "R" else "m"


def _effort_unit(structure: Structure) -> str:
    return "N m" if structure.actuated_kind == "R" else "N"


def actuator_argument(structure: Structure) -> Argument:
    """``qa``: the actuator coordinates (docs/interfaces.md, "Control model")."""
    family = outputs.coordinate_family(structure, structure.actuated)[0]
    unit = _coordinate_unit(structure)
    return Argument(
        "qa",
        tuple(syms.qa),
        tuple(
            Component(f"{family}_{leg}", unit, f"actuated joint {structure.actuated}, leg {leg}")
            for leg in LEGS
        ),
        f"actuator coordinates ({family}_A, _B, _C, from home)",
    )


def effort_argument(structure: Structure) -> Argument:
    """``tau``: the actuator efforts."""
    family = outputs.effort_family(structure)
    unit = _effort_unit(structure)
    return Argument(
        "tau",
        tuple(syms.tau),
        tuple(Component(f"{family}_{leg}", unit, f"actuator effort, leg {leg}") for leg in LEGS),
        f"actuator efforts ({family}_A, _B, _C)",
    )


def _pose_checks(prog: Program, structure: Structure) -> tuple[Check, ...]:
    """The failure conditions of the inverse dynamics, on the same values, as guards."""
    values = control.include_inverse_dynamics(prog, structure).outputs
    return (
        Check("inputs_not_finite", "NOT_FINITE"),
        Check("below", "SINGULAR", threshold="MIN_REACH", guard=("reach", values["reach"])),
        Check(
            "below",
            "SINGULAR",
            threshold="MIN_CONDITIONING",
            guard=("conditioning", values["conditioning"]),
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


def actuator_coordinates(structure: Structure) -> FunctionSpec:
    """``rpr3_actuator_coordinates``: ``qa`` of a pose, the inverse kinematics of eq. (5)."""
    prog = Program()
    values = sp.Matrix(control.actuator_values(prog, structure, "q"))
    qa = actuator_argument(structure)
    return FunctionSpec(
        name="actuator_coordinates",
        doc=f"Actuator coordinates qa ({qa.doc}) of the platform pose q, in each leg's working "
        "mode (eq. 5).",
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
        checks=_pose_checks(prog, structure),
    )


def actuator_jacobian(structure: Structure) -> FunctionSpec:
    """``rpr3_actuator_jacobian``: ``J = d qa / d q``, row-major, so that ``qa' = J q'``."""
    prog = Program()
    J = control.actuator_jacobian(prog, structure)
    units = ("1/m", "1/m", "1") if structure.actuated_kind == "R" else ("1", "1", "m")
    qa_names = [c.name for c in actuator_argument(structure).components]
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
        checks=_pose_checks(prog, structure),
    )


def jacobian_rate(structure: Structure) -> FunctionSpec:
    """``rpr3_jacobian_rate``: ``J' q'``, so that ``qa'' = J q'' + J' q'`` (eq. 9)."""
    prog = Program()
    rate = control.jacobian_rate_term(prog, structure)
    qa = actuator_argument(structure)
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
                (f"{_coordinate_unit(structure)}/s^2",) * 3,
                "J' q'",
            ),
        ),
        program=prog,
        checks=_pose_checks(prog, structure),
    )


def platform_velocity(structure: Structure) -> FunctionSpec:
    """``rpr3_platform_velocity``: ``q' = J^-1 qa'``, the velocity map backwards."""
    prog = Program()
    qd = control.platform_velocity(prog, structure)
    qa = actuator_argument(structure)
    rates = Argument(
        "qa_dot",
        tuple(syms.qa_dot),
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
        checks=_pose_checks(prog, structure),
    )


def actuator_efforts(structure: Structure) -> FunctionSpec:
    """``rpr3_actuator_efforts``: the actuator efforts alone of the inverse dynamics."""
    prog = Program()
    values = sp.Matrix(control.actuator_efforts(prog, structure))
    tau = effort_argument(structure)
    return FunctionSpec(
        name="actuator_efforts",
        doc=f"Actuator efforts ({tau.doc}) that produce the platform acceleration qdd at "
        "(q, qd): the inverse dynamics' actuator loads (eqs. 12-17) alone, which is also "
        "tau = J^-T (M qdd + c), the computed-torque law's efforts for a commanded qdd.",
        inputs=(POSE, VELOCITY, ACCELERATION),
        outputs=(
            _triple(
                "tau",
                values,
                tuple(c.name for c in tau.components),
                tuple(c.unit for c in tau.components),
                "actuator efforts",
            ),
        ),
        program=prog,
        checks=_pose_checks(prog, structure),
    )


def task_space_dynamics(structure: Structure) -> FunctionSpec:
    """``rpr3_task_space_dynamics``: ``M`` (row-major) and ``c`` with ``M q'' + c = J^T tau``."""
    prog = Program()
    M, c = control.task_space_dynamics(prog, structure)
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
        checks=_pose_checks(prog, structure),
    )


def forward_dynamics(structure: Structure) -> FunctionSpec:
    """``rpr3_forward_dynamics``: ``q'' = M^-1 (J^T tau - c)``, by an LDL^T solve."""
    prog = Program()
    qdd = control.forward_dynamics(prog, structure)
    return FunctionSpec(
        name="forward_dynamics",
        doc="Forward dynamics: the platform acceleration q'' = M^-1 (J^T tau - c) under the "
        "actuator efforts tau, by an explicit LDL^T solve of the task-space dynamics.",
        inputs=(POSE, VELOCITY, effort_argument(structure)),
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
        checks=_pose_checks(prog, structure),
    )


def pose_diagnostics(structure: Structure) -> FunctionSpec:
    """``rpr3_pose_diagnostics``: why a pose is refused: each leg's reach and the conditioning."""
    prog = Program()
    derivation = control.include_inverse_dynamics(prog, structure)
    reaches = outputs.leg_reaches(structure, derivation.kinematics)
    what = (
        "(l0 + lambda21) / l0, 1 in the central configuration, <= 0 with the piston joint on or "
        "behind its base pivot"
        if structure.paper
        else "D / D(home), the leg's serial determinant against its value at home: 1 at home, "
        "0 at a serial singularity"
    )
    return FunctionSpec(
        name="pose_diagnostics",
        doc="Diagnostics of a pose, with no failure check (values may be NaN or below the "
        "floors): each leg's reach, " + what + " (NaN where the leg cannot reach the pose in "
        "its working mode), and the conditioning (0 at a parallel singularity).",
        inputs=(POSE,),
        outputs=(
            Output(
                "diagnostics",
                (*reaches, derivation.outputs["conditioning"]),
                (
                    *(Component(f"reach_{leg}", "1", f"leg {leg}'s reach") for leg in LEGS),
                    Component("conditioning", "1", "closeness to a parallel singularity"),
                ),
                "reach_A, reach_B, reach_C, conditioning",
            ),
        ),
        program=prog,
        checks=(Check("inputs_not_finite", "NOT_FINITE"),),
    )


def joint_points(structure: Structure) -> FunctionSpec:
    """``rpr3_joint_points``: where every joint of every leg is, for drawing the robot."""
    prog = Program()
    derivation = control.include_inverse_dynamics(prog, structure)
    values, components = [], []
    for leg in LEGS:
        kin = derivation.kinematics[leg]
        x3 = (syms.x + kin.s[0], syms.y + kin.s[1])
        arms = [kin.pose.world(arm) for arm in kin.pose.arms]
        points = (
            (x3[0] - arms[0][0], x3[1] - arms[0][1]),
            (x3[0] - arms[1][0], x3[1] - arms[1][1]),
            x3,
        )
        for j, point in enumerate(points, start=1):
            for axis, value in zip("xy", point, strict=True):
                values.append(value)
                components.append(
                    Component(
                        f"{axis}{j}_{leg}", "m", f"leg {leg}: joint {j}'s point, world {axis}0"
                    )
                )
    return FunctionSpec(
        name="joint_points",
        doc="The current points of joints 1, 2, 3 of legs A, B, C (world frame) at the platform "
        "pose q, each leg in its working mode (eq. 5): what a drawing of the robot needs.",
        inputs=(POSE,),
        outputs=(
            Output("points", tuple(values), tuple(components), "x1_A, y1_A, ..., x3_C, y3_C"),
        ),
        program=prog,
        checks=_pose_checks(prog, structure),
    )


def fk_kind(structure: Structure) -> str:
    """How a locked leg holds the platform: ``circle``, ``line`` or ``platform_line``."""
    return direct_kinematics.locked_kind(structure.kinds, structure.actuated)


def assembly_modes(structure: Structure) -> FunctionSpec:
    """``rpr3_assembly_modes``: the direct kinematics' closed forms.

    Line holds: both candidate modes (x, y, phi) and their margins (a candidate exists where its
    margin is >= 0; it is a mode when every leg is in its working mode there). Circle holds:
    the coefficients of the sextic in tan(phi/2), whose real roots :func:`pose_from_angle`
    turns into poses.
    """
    prog = Program()
    qa = actuator_argument(structure)
    checks = (Check("inputs_not_finite", "NOT_FINITE"),)
    robot = structures.robot(structure)
    holds = direct_kinematics.locked_legs(robot, structure)
    kind = fk_kind(structure)
    if kind != "circle":
        modes = direct_kinematics.line_modes(prog, robot, holds)
        where = "a world line" if kind == "line" else "a line of the platform"
        return FunctionSpec(
            name="assembly_modes",
            doc=f"Both candidate assembly modes of the actuator coordinates qa, in closed form: "
            f"each locked leg holds the platform on {where}, and the closure reduces to "
            "A cos(phi) + B sin(phi) + C = 0. A candidate exists where its margin >= 0 and is "
            "a mode when every leg is in its working mode there (actuator_coordinates gives "
            "back qa).",
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
                    "the two candidates (x, y, phi), phi in [-pi, pi]",
                ),
                Output(
                    "margins",
                    tuple(m.margin for m in modes),
                    (Component("margin1"), Component("margin2")),
                    "a candidate exists where its margin is >= 0",
                ),
            ),
            program=prog,
            checks=checks,
        )
    coefficients = direct_kinematics.sextic_coefficients(prog, holds)
    return FunctionSpec(
        name="assembly_modes",
        doc="The direct kinematics of the actuator coordinates qa as a polynomial: each locked "
        "leg holds a platform point on a circle; coefficients a0..a6 of sum a_j t^j = 0, "
        "t = tan(phi/2) (Gosselin; Merlet), whose real roots give every assembly mode (then "
        "pose_from_angle; a root is a mode when every leg is in its working mode there).",
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


def pose_from_angle(structure: Structure) -> FunctionSpec | None:
    """``rpr3_pose_from_angle`` (circle holds): G for a root phi of the sextic."""
    if fk_kind(structure) != "circle":
        return None
    prog = Program()
    holds = direct_kinematics.locked_legs(structures.robot(structure), structure)
    x, y = direct_kinematics.pose_from_angle(prog, holds, *ANGLE.symbols)
    return FunctionSpec(
        name="pose_from_angle",
        doc="Position of G for a platform angle phi that solves the direct kinematics of the "
        "actuator coordinates qa (back substitution of the sextic's root).",
        inputs=(actuator_argument(structure), ANGLE),
        outputs=(Output("xy", (x, y), (Component("x", "m"), Component("y", "m")), "G"),),
        program=prog,
        checks=(Check("inputs_not_finite", "NOT_FINITE"),),
    )


def locked_circles(structure: Structure) -> FunctionSpec | None:
    """``rpr3_locked_circles`` (circle holds): each locked leg's circle, for the back
    substitution where :func:`pose_from_angle` is singular."""
    if fk_kind(structure) != "circle":
        return None
    prog = Program()
    holds = direct_kinematics.locked_legs(structures.robot(structure), structure)
    values, components = [], []
    for leg in LEGS:
        hold = holds[leg]
        for label, value, unit, meaning in (
            ("bx", hold.b[0], "m", "centre, world x0"),
            ("by", hold.b[1], "m", "centre, world y0"),
            ("ax", hold.a[0], "m", "platform point, platform frame x"),
            ("ay", hold.a[1], "m", "platform point, platform frame y"),
            ("r2", hold.r2, "m^2", "squared radius"),
        ):
            values.append(value)
            components.append(Component(f"{label}_{leg}", unit, f"leg {leg}'s circle: {meaning}"))
    return FunctionSpec(
        name="locked_circles",
        doc="The circle each leg holds a platform point on when its motor is locked at qa: "
        "|G + R(phi) a - b|^2 = r2, per leg A, B, C (b, a, r2); the direct kinematics' data.",
        inputs=(actuator_argument(structure),),
        outputs=(Output("circles", tuple(values), tuple(components), "(bx, by, ax, ay, r2) x 3"),),
        program=prog,
        checks=(Check("inputs_not_finite", "NOT_FINITE"),),
    )


#: The tracked forward kinematics' numbers, for its C body (``c_context``), as in
#: ``tests/fk_reference.py`` (``tracked_forward_kinematics``), whose prototype it ports.
FK_TUNING: tuple[tuple[str, object], ...] = (
    ("max_iter", 8),  # Newton steps from q_near before the fallback
    ("polish_iter", 20),  # Newton steps polishing a mode of the fallback
    ("max_halvings", 12),  # of the step, in the line search
    ("tol", "1e-12"),  # converged: the largest residual |qa(q) - qa| (rad or m)
    ("det_tol", "1e-14"),  # singular J: |det J| under this times the product of its row norms
    ("samples", 256),  # cells of t in [-1, 1], and as many of u = 1/t in [-1, 1] (circles)
    ("bisections", 60),  # per root, or per extremum of a cell without a sign change
    ("touch_tol", "1e-9"),  # an extremum within this of the sextic's scale of zero is a root
    ("merge_tol", "1e-9"),  # roots (rad) closer than this are one
    ("parallel_tol", "1e-6"),  # back substitution: |D| <= this |w_B| |w_C| is parallel
    ("max_roots", 16),  # sampled roots kept (a real sextic has 6; t = +-1 is sampled twice)
)


def _forward_kinematics_doc(structure: Structure) -> str:
    """The header's comment of ``rpr3_forward_kinematics``, with the numbers of FK_TUNING."""
    n = dict(FK_TUNING)
    if fk_kind(structure) != "circle":
        modes = "both closed-form candidates of assembly_modes (where their margins are >= 0)"
    else:
        modes = (
            "the real roots of the sextic of assembly_modes, without a polynomial solver: "
            f"sampled at {n['samples']} cells of t = tan(phi/2) in [-1, 1] and as many of "
            "1/t in [-1, 1], each sign change bisected, a cell with an extremum split there "
            "(close pairs, double roots); back substituted by pose_from_angle (or, where its "
            "two equations are parallel, by a line and a circle of locked_circles); none when a "
            "circle's radius is not positive"
        )
    return (
        "Tracked forward kinematics: the assembly mode of the actuator coordinates qa nearest "
        "the reference pose q_near (distance in (x, y, rho phi), rho the platform's RMS joint "
        "radius), phi unwrapped next to q_near's. (1) Damped Newton from q_near with the "
        "generated Jacobian: J dq = -r (r = qa(q) - qa"
        + (", angles wrapped" if structure.actuated_kind == "R" else "")
        + f"), the step limited to rho in that metric and halved (at most {n['max_halvings']} "
        f"times) until the largest residual drops by 1 - t/2; converged when it is <= "
        f"{n['tol']} (rad or m), at most {n['max_iter']} steps. (2) Its pose is returned when "
        "it converged, the pose is not singular (reach above MIN_REACH) and det J has the sign "
        "it has at q_near (same aspect). (3) Otherwise (no convergence, a singular J, a failed "
        f"line search, another aspect) the fallback: every mode, {modes}, each polished by the "
        f"same Newton ({n['polish_iter']} steps; a candidate in another working mode does not "
        "converge to it); the nearest wins. RPR3_NO_MODE, q untouched, when there is no mode. "
        "Limits: through a parallel singularity only a predicted reference (2 q[k-1] - "
        "q[k-2]) follows the robot (the previous pose makes it turn back); the aspect test "
        "cannot tell apart two modes of one aspect; "
        + (
            ""
            if fk_kind(structure) != "circle"
            else "the sampling misses a root pair that round-off keeps from touching zero and "
            "three roots in one cell; "
        )
        + "the fallback costs several Newton solves. No allocation, no state."
    )


def forward_kinematics(structure: Structure) -> FunctionSpec:
    """``rpr3_forward_kinematics``: the assembly mode of ``qa`` nearest a reference pose.

    C only: a hand-written body (``templates/forward_kinematics.c.jinja``) that calls the
    generated kernels of ``actuator_coordinates``, ``actuator_jacobian``, ``assembly_modes``,
    ``pose_from_angle`` and ``locked_circles``; it ports ``tests/fk_reference.py``
    (``tracked_forward_kinematics``). See :func:`_forward_kinematics_doc` and
    ``docs/control-model.md``.

    The numbers are :data:`FK_TUNING`; ``trace=True`` (test builds only) makes the body call
    ``rpr3_fk_trace(steps, how)`` (``how``: 0 Newton, 1 fallback, 2 none), which the test's
    harness defines.
    """
    qa = actuator_argument(structure)
    near = Argument(
        "q_near",
        tuple(sp.Symbol(f"{c.name}_near", real=True) for c in POSE.components),
        tuple(Component(c.name, c.unit, c.meaning) for c in POSE.components),
        "the reference pose: the previous solution, or better a prediction from the last two",
    )
    names = structures.param_names(structure)
    platform_points = [
        [names.index(str(s)) for s in structures.robot(structure).legs[leg].platform_point]
        for leg in LEGS
    ]
    return FunctionSpec(
        name="forward_kinematics",
        doc=_forward_kinematics_doc(structure),
        inputs=(qa, near),
        outputs=(Output("q", (sp.Integer(0),) * 3, POSE.components, "the pose found"),),
        program=Program(),
        checks=(Check("inputs_not_finite", "NOT_FINITE"), Check("custom", "NO_MODE")),
        c_body="forward_kinematics.c.jinja",
        c_context=(
            ("kind", fk_kind(structure)),
            ("wrap", structure.actuated_kind == "R"),
            ("max_modes", direct_kinematics.MAX_MODES[fk_kind(structure)]),
            ("length_tol", repr(direct_kinematics.LENGTH_TOL)),
            ("platform_points", platform_points),
            *FK_TUNING,
            ("trace", False),
        ),
    )


# -- dynamic identification: the regressor and the payload's efforts (docs/identification.md) --

#: Unit of each inertial quantity (docs/identification.md).
_PI_UNITS = {"m": "kg", "mcx": "kg m", "mcy": "kg m", "Jzz": "kg m^2"}
_QUANTITY = {"m": "mass", "mcx": "first moment x", "mcy": "first moment y", "Jzz": "inertia"}


def _y_unit(structure: Structure, quantity: str) -> str:
    """Unit of Y's entries: the effort's unit over the parameter's."""
    if structure.actuated_kind == "R":
        return {"m": "m^2/s^2", "mcx": "m/s^2", "mcy": "m/s^2", "Jzz": "1/s^2"}[quantity]
    return {"m": "m/s^2", "mcx": "1/s^2", "mcy": "1/s^2", "Jzz": "1/(m s^2)"}[quantity]


def _pi_component(structure: Structure, name: str) -> Component:
    """``mcx_2B`` -> unit and meaning (docs/identification.md)."""
    quantity, body = name.split("_")
    if structure.paper:
        bodies = {"1": "cylinder", "2": "piston", "3": "platform"}
    else:
        bodies = {"1": "body 1", "2": "body 2", "3": "platform"}
    leg = f" of leg {body[1]}" if len(body) > 1 else ""
    return Component(
        name, _PI_UNITS[quantity], f"{_QUANTITY[quantity]} of the {bodies[body[0]]}{leg}"
    )


def inertial_parameters(structure: Structure) -> Argument:
    """The inertial parameters pi, the columns of Y: C table ``rpr3_inertial_parameter_names``."""
    names = identification.INERTIAL_PARAMETER_NAMES
    return Argument(
        "pi",
        tuple(identification.pi_symbols[n] for n in names),
        tuple(_pi_component(structure, n) for n in names),
        "inertial parameters (per moving body: m, m cx, m cy, Jzz about its first joint point)",
        table="inertial_parameter_names",
    )


def regressor(structure: Structure) -> FunctionSpec:
    """``rpr3_regressor``: ``Y`` (3 x P, row-major) with ``tau = Y pi + tau_payload``."""
    prog = Program()
    checks = _pose_checks(prog, structure)
    Y = identification.regressor(prog, structure)
    family = outputs.effort_family(structure)
    names = identification.INERTIAL_PARAMETER_NAMES
    return FunctionSpec(
        name="regressor",
        doc=f"Identification regressor Y (3 x {len(names)}, row-major; row i: {family} of leg "
        "A, B, C; column j: INERTIAL_PARAMETER_NAMES[j]) with tau = Y pi + tau_payload: the "
        "actuator efforts of eqs. (10)-(17) differentiated by the inertial parameters pi (per "
        "moving body m, m cx, m cy, Jzz about its first joint point; docs/identification.md).",
        inputs=(POSE, VELOCITY, ACCELERATION),
        outputs=(
            Output(
                "Y",
                tuple(Y[i, j] for i in range(3) for j in range(len(names))),
                tuple(
                    Component(
                        f"Y_{leg}__{name}",
                        _y_unit(structure, name.split("_")[0]),
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


def payload_efforts(structure: Structure) -> FunctionSpec:
    """``rpr3_payload_efforts``: the efforts that hold the payload wrench at rest."""
    prog = Program()
    checks = _pose_checks(prog, structure)
    tau = identification.payload_efforts(prog, structure)
    arg = effort_argument(structure)
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


FunctionBuilder = Callable[[Structure], FunctionSpec | None]

#: Every generated function, by name: a builder from the structure to its spec. A builder may
#: return None for a structure that has no such function.
FUNCTIONS: Mapping[str, FunctionBuilder] = {
    "inverse_dynamics": inverse_dynamics,
    "actuator_coordinates": actuator_coordinates,
    "pose_diagnostics": pose_diagnostics,
    "joint_points": joint_points,
    "actuator_jacobian": actuator_jacobian,
    "jacobian_rate": jacobian_rate,
    "platform_velocity": platform_velocity,
    "actuator_efforts": actuator_efforts,
    "task_space_dynamics": task_space_dynamics,
    "forward_dynamics": forward_dynamics,
    "assembly_modes": assembly_modes,
    "pose_from_angle": pose_from_angle,
    "locked_circles": locked_circles,
    "forward_kinematics": forward_kinematics,
    "regressor": regressor,
    "payload_efforts": payload_efforts,
}


@cache
def _spec(builder: FunctionBuilder, structure: Structure) -> FunctionSpec | None:
    return builder(structure)


def clear_cache() -> None:
    """Forget the specs derived so far (they are derived once per process otherwise)."""
    _spec.cache_clear()
    control.inverse_dynamics.cache_clear()


def module(
    structure: Structure, functions: Mapping[str, FunctionBuilder] | None = None
) -> ModuleSpec:
    """The generated module of one structure: every function of ``functions``."""
    if structure.singular:
        raise ValueError(
            f"{structure.title}: every motor measures only the platform's angle; the platform's "
            "translation is not controlled (architecturally singular), so nothing is generated"
        )
    functions = FUNCTIONS if functions is None else functions
    defines = [
        ("LEG", f'"{structure.kinds}"', "joint types of every leg, base to platform"),
        ("ACTUATED", str(structure.actuated), "the joint of every leg that carries its motor"),
        ("FK_KIND", f'"{fk_kind(structure)}"', "how a locked leg holds the platform"),
        (
            "MAX_MODES",
            str(direct_kinematics.MAX_MODES[fk_kind(structure)]),
            "most assembly modes of one qa",
        ),
    ]
    if structure.paper:
        defines.insert(0, ("ACTUATION", f'"{structure.variant}"', ""))
    model = "the paper's parameters" if structure.paper else "the general model file's parameters"
    return ModuleSpec(
        prefix=PREFIX,
        variant=structure.variant,
        doc=(
            f"Generated functions of the {structure.title} planar parallel robot, in {model}. "
            "Model numbers are inputs (params), so one build serves every robot of this "
            "structure."
        ),
        params=params_argument(structure),
        functions=tuple(
            spec
            for builder in functions.values()
            if (spec := _spec(builder, structure)) is not None
        ),
        return_codes=RETURN_CODES,
        thresholds=thresholds(structure),
        tables=(inertial_parameters(structure),),
        defines=tuple(defines),
    )
