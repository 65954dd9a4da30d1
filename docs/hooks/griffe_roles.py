"""A griffe extension for the API reference: the Sphinx roles of the docstrings as code.

The docstrings cross-reference with Sphinx roles (``:func:`workspace```, ``:class:`Plan```),
which mkdocstrings would print as they are; on the site they read as the code they name.
"""

from __future__ import annotations

import re
from typing import Any

import griffe

ROLE = re.compile(r":(?:py:)?(?:func|meth|class|data|mod|attr|exc|obj|const):`[~.]?([^`]+)`")


class SphinxRoles(griffe.Extension):
    """Rewrite ``:role:`name``` as ```name``` in every docstring of a loaded package."""

    def on_package(self, *, pkg: griffe.Module, **kwargs: Any) -> None:
        seen: set[int] = set()
        stack: list[griffe.Object] = [pkg]
        while stack:
            obj = stack.pop()
            if id(obj) in seen:
                continue
            seen.add(id(obj))
            if obj.docstring is not None:
                obj.docstring.value = ROLE.sub(r"`\1`", obj.docstring.value)
            stack.extend(m for m in obj.members.values() if not m.is_alias)
