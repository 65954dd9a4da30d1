"""Symbolic derivation and code emission for rpr3gen; installed as the package ``rpr3gen_derive``.

It needs sympy and jinja2 and is imported only to regenerate ``generated/`` (``rpr3gen
generate``) or to read the derivation in the notebooks; the runtime ``rpr3gen`` never imports it.

Two halves, one way only:

- ``codegen/``: a generic engine (programs, specs, CSE, one backend per language with its
  printer and templates, rendering, regeneration check) that imports nothing of the robot;
- ``planar/``: the robot, any planar 3-leg one (leg types and structures → geometry →
  kinematics → dynamics → virtual work, the control model, identification), its
  ``registry/`` of function specs, and ``generate``, which runs the engine on them.

docs/architecture.md draws the layers.
"""
