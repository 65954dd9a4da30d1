"""The subcommands of ``rpr3gen``, one module each: ``NAME``, ``add_parser(sub)`` building its
parser and ``run(args)`` returning the exit status. :data:`COMMANDS` is their order in
``rpr3gen --help``.

Shared by several: :mod:`~rpr3gen.commands.args` (the parser class and the numeric types),
:mod:`~rpr3gen.commands.options` (the common options), :mod:`~rpr3gen.commands.reports`
(warnings and summaries). A command module imports those and the runtime, never another command.
"""

from __future__ import annotations

from rpr3gen.commands import (
    animate,
    excite,
    export,
    fk,
    generate,
    identify,
    paper,
    params,
    retime,
    simulate,
    sweep,
    workspace,
)

COMMANDS = (
    simulate,
    paper,
    params,
    fk,
    identify,
    excite,
    animate,
    workspace,
    sweep,
    export,
    retime,
    generate,
)
"""Every command module, in the order of ``rpr3gen --help``."""
