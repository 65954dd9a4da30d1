"""The functions of the direct kinematics: the closed forms of the assembly modes (a sextic's
coefficients where the locked legs hold circles), their back substitution, and the tracked
forward kinematics, a hand-written C body on those kernels (docs/control-model.md)."""

from __future__ import annotations

import sympy as sp
from rpr3gen_derive.codegen.program import Program
from rpr3gen_derive.codegen.spec import Argument, Check, Component, FunctionSpec, Output
from rpr3gen_derive.planar import direct_kinematics, structures
from rpr3gen_derive.planar.geometry import LEGS
from rpr3gen_derive.planar.registry.arguments import POSE, actuator_argument
from rpr3gen_derive.planar.registry.control_model import jacobian_output
from rpr3gen_derive.planar.structures import Structure


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
    harness defines. Its hidden output ``jacobian`` is the actuator Jacobian at the pose found,
    which its Newton evaluated there (``actuator_coordinates_jacobian``'s values kernel gives
    the residual and J at every iterate): :func:`forward_kinematics_jacobian` returns it.
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
        outputs=(
            Output("q", (sp.Integer(0),) * 3, POSE.components, "the pose found"),
            jacobian_output(structure, sp.zeros(3, 3), "jacobian", hidden=True),
        ),
        program=Program(),
        checks=(Check("inputs_not_finite", "NOT_FINITE"), Check("custom", "NO_MODE")),
        c_body="forward_kinematics.c.jinja",
        c_kernels=("minmax",),
        c_values=(
            "actuator_coordinates_jacobian",
            "actuator_coordinates_hessian",
            "jacobian_rate",
        ),
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


def forward_kinematics_jacobian(structure: Structure) -> FunctionSpec:
    """``rpr3_forward_kinematics_jacobian``: the tracked forward kinematics and the actuator
    Jacobian at the pose it finds, in one call.

    C only: its body (``templates/forward_kinematics_jacobian.c.jinja``) is the call of
    :func:`forward_kinematics`' kernel, whose hidden output is that Jacobian: its Newton
    evaluated it at the pose it accepts (by ``actuator_coordinates_jacobian``'s kernels, so the
    bits of ``rpr3_actuator_coordinates_jacobian``), and its fallback evaluates it at the mode
    it returns. A control tick that needs J right after the pose (the velocity from
    ``J q' = qa'``, the efforts from ``J^T tau = ...``) saves the second evaluation.
    """
    fk = forward_kinematics(structure)
    return FunctionSpec(
        name="forward_kinematics_jacobian",
        doc="Tracked forward kinematics and the actuator Jacobian at the pose found, in one call: "
        "q is forward_kinematics' (same bits, same return code), J = d qa / d q at q, row-major, "
        "the bits of actuator_coordinates_jacobian at q (the tracked Newton evaluated it there; "
        "actuator_jacobian's to round-off). Non-zero, "
        "q and J untouched, when there is no mode.",
        inputs=fk.inputs,
        outputs=(fk.output("q"), jacobian_output(structure, sp.zeros(3, 3))),
        program=Program(),
        checks=fk.checks,
        c_body="forward_kinematics_jacobian.c.jinja",
    )
