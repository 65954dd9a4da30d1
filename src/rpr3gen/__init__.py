"""rpr3gen: dynamics of planar parallel robots (the 3-RPR of S. Staicu, and any planar 3-leg
robot), from generated code.

>>> import rpr3gen
>>> model = rpr3gen.load_model()                   # the paper's robot
>>> traj = rpr3gen.paper_trajectory("rotation")    # eq. (3)
>>> out = rpr3gen.inverse_dynamics(model, traj.q, traj.qd, traj.qdd)
>>> out["m10_A"].shape
(301,)

The runtime imports numpy (matplotlib for figures, scipy for trajectories of positions only,
pyarrow and Dask for design studies: :func:`workspace`, :func:`sweep`);
regeneration lives in the package ``rpr3gen_derive`` (folder ``derive/``) and writes
``rpr3gen_generated`` (folder ``generated/``).
"""

from rpr3gen.backends import BACKENDS, OUTPUT_NAMES, evaluate, inverse_dynamics
from rpr3gen.control import (
    actuator_coordinates,
    actuator_coordinates_hessian,
    actuator_coordinates_jacobian,
    actuator_efforts,
    actuator_jacobian,
    assembly_modes,
    forward_dynamics,
    forward_kinematics,
    jacobian_rate,
    platform_radius,
    platform_velocity,
    task_space_dynamics,
)
from rpr3gen.design import WorkspaceMap, sweep, workspace, write_workspace
from rpr3gen.errors import (
    GeneratedCodeError,
    GridError,
    IdentificationError,
    IdentificationWarning,
    InputError,
    InputTypeError,
    ModelError,
    Rpr3genError,
    Rpr3genWarning,
    SetupError,
    TrajectoryError,
    TrajectoryWarning,
)
from rpr3gen.excitation import excite
from rpr3gen.identification import identify
from rpr3gen.model import PARAM_NAMES, Model, load_model, model_from_dict
from rpr3gen.parameters import (
    INERTIAL_PARAMETER_NAMES,
    base_parameters,
    base_regressor,
    inertial_parameter_names,
    inertial_parameters,
    payload_efforts,
    regressor,
)
from rpr3gen.retiming import retime
from rpr3gen.sample import SampleEvaluator
from rpr3gen.sensitivity import forward_dynamics_derivatives, inverse_dynamics_derivatives
from rpr3gen.trajectory import Trajectory, paper_trajectory, read_trajectory_csv
from rpr3gen.version import __version__

__all__ = [
    "BACKENDS",
    "INERTIAL_PARAMETER_NAMES",
    "OUTPUT_NAMES",
    "PARAM_NAMES",
    "GeneratedCodeError",
    "GridError",
    "IdentificationError",
    "IdentificationWarning",
    "InputError",
    "InputTypeError",
    "Model",
    "ModelError",
    "Rpr3genError",
    "Rpr3genWarning",
    "SampleEvaluator",
    "SetupError",
    "Trajectory",
    "TrajectoryError",
    "TrajectoryWarning",
    "WorkspaceMap",
    "__version__",
    "actuator_coordinates",
    "actuator_coordinates_hessian",
    "actuator_coordinates_jacobian",
    "actuator_efforts",
    "actuator_jacobian",
    "assembly_modes",
    "base_parameters",
    "base_regressor",
    "evaluate",
    "excite",
    "forward_dynamics",
    "forward_dynamics_derivatives",
    "forward_kinematics",
    "identify",
    "inertial_parameter_names",
    "inertial_parameters",
    "inverse_dynamics",
    "inverse_dynamics_derivatives",
    "jacobian_rate",
    "load_model",
    "model_from_dict",
    "paper_trajectory",
    "payload_efforts",
    "platform_radius",
    "platform_velocity",
    "read_trajectory_csv",
    "regressor",
    "retime",
    "sweep",
    "task_space_dynamics",
    "workspace",
    "write_workspace",
]
