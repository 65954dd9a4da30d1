"""Symbolic derivation of the 3-RPR inverse dynamics (S. Staicu), and its code emission.

This folder is installed as the package ``rpr3gen_derive``. It needs sympy and jinja2 and is
imported only to regenerate ``generated/`` (``rpr3gen generate``) or to read the derivation in the
notebooks; the runtime ``rpr3gen`` never imports it.

Layers, one way only: ``symbols`` → ``frames`` → ``kinematics`` → ``dynamics`` →
``virtual_work`` → ``specs`` → ``cse`` / ``printers`` → ``render`` (templates) → ``generated/``.
"""

from rpr3gen_derive.specs import ACTUATIONS, FunctionSpec, build_spec

__all__ = ["ACTUATIONS", "FunctionSpec", "build_spec"]
