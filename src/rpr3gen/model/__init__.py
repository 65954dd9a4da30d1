"""Robot model files: read, validate and turn into the numeric parameter vector.

A model file (TOML, see ``docs/interfaces.md``) describes one planar 3-leg robot, or a spatial
one (a hexapod or a Delta, ``docs/spatial-robots.md``).
:func:`load_model` reads it, checks every key and value, applies the defaults of
``docs/conventions.md`` and returns a :class:`Model` whose ``params`` hold the structure's
parameters in SI units (angles in rad), the inputs of the generated functions.

Every problem is reported as a :class:`~rpr3gen.errors.ModelError` with a one-line message that
names the file and the dotted key, e.g. ``my.toml: geometry.l0: must be a positive number, got
-0.1``.

The package, bottom up (each module imports only those before it):

- :mod:`~rpr3gen.model.checks`: the checks of a :class:`Model`'s fields, built in code;
- :mod:`~rpr3gen.model.types`: the :class:`Model` dataclass and its constants;
- :mod:`~rpr3gen.model.reading`: the reader's helpers both formats share;
- :mod:`~rpr3gen.model.paper`: the paper's format (the 3-RPR);
- :mod:`~rpr3gen.model.general`: the general format (any planar 3-leg robot);
- :mod:`~rpr3gen.model.spatial_home` and :mod:`~rpr3gen.model.spatial`: the spatial format's
  geometry at home and its reader (hexapods and Deltas);
- :mod:`~rpr3gen.model.load`: :func:`load_model`, :func:`model_from_dict`, which pick the format.
"""

from rpr3gen.model.load import load_model, model_from_dict, read_model_data
from rpr3gen.model.paper import MODEL_KEYS
from rpr3gen.model.types import ACTUATIONS, DEFAULT_GRAVITY, LEGS, PARAM_NAMES, IsModel, Model

__all__ = [
    "ACTUATIONS",
    "DEFAULT_GRAVITY",
    "LEGS",
    "MODEL_KEYS",
    "PARAM_NAMES",
    "IsModel",
    "Model",
    "load_model",
    "model_from_dict",
    "read_model_data",
]
