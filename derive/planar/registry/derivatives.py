"""The derivatives of the dynamics of a planar robot (docs/derivatives.md): built by the engine
(:mod:`rpr3gen_derive.codegen.derivatives`) from the efforts' and the forward dynamics' specs."""

from __future__ import annotations

from rpr3gen_derive.codegen import derivatives
from rpr3gen_derive.codegen.spec import FunctionSpec
from rpr3gen_derive.planar.registry.control_model import actuator_efforts, forward_dynamics
from rpr3gen_derive.planar.structures import Structure


def inverse_dynamics_derivatives(structure: Structure) -> FunctionSpec:
    """``rpr3_inverse_dynamics_derivatives``: ``tau`` and ``d tau / d(q, qd, qdd)``."""
    return derivatives.inverse_dynamics_derivatives(actuator_efforts(structure))


def forward_dynamics_derivatives(structure: Structure) -> FunctionSpec:
    """``rpr3_forward_dynamics_derivatives``: ``qdd`` and ``d qdd / d(q, qd, tau)``."""
    return derivatives.forward_dynamics_derivatives(
        forward_dynamics(structure), actuator_efforts(structure)
    )
