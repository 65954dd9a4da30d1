"""A nonlinear model-predictive controller for a parallel robot, on rpr3gen's CasADi bridge.

The modules, each one concept (examples/mpc/README.md):

- :mod:`mpc_example.reference`: the path to track, timed by :func:`rpr3gen.retime`;
- :mod:`mpc_example.controller`: the MPC, multiple shooting of the bridge's forward dynamics
  solved by IPOPT, with an estimate of the effort the model lacks;
- :mod:`mpc_example.plant`: the robot it drives, rpr3gen's own forward dynamics (generated C)
  with a payload and motor friction the controller does not know;
- :mod:`mpc_example.report`: the closed-loop run's numbers, CSV and figure.

``examples/mpc/mpc.py`` runs them together.
"""
