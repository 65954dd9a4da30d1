"""The 3-RPR planar parallel robot (S. Staicu), derived by virtual work.

One module per step of the paper: ``symbols`` (inputs and parameters), ``frames`` (eqs. 1-2),
``kinematics`` (eqs. 5, 6, 9), ``dynamics`` (inertia wrenches, eqs. 10-11), ``virtual_work``
(eqs. 7-8, 12-17); ``registry`` turns them into function specs, ``generate`` runs the engine.
"""
