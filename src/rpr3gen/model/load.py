"""Reading a model file or mapping: the format's reader picked by its keys.

:func:`load_model` reads a TOML file, checks every key and value, applies the defaults of
``docs/conventions.md`` and returns a :class:`~rpr3gen.model.Model`; a file whose top-level
``leg`` is a spatial leg type (UPS, RUS, PUS, RSS2, PSS2) describes a hexapod or a Delta
(:mod:`rpr3gen.model.spatial`, docs/spatial-robots.md), one with another ``leg`` is of the
general planar format (:mod:`rpr3gen.model.general`), one without it the paper's
(:mod:`rpr3gen.model.paper`).
"""

from __future__ import annotations

import dataclasses
import importlib.resources
import os
import tomllib
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from rpr3gen.errors import ModelError
from rpr3gen.model.general import is_general, read_general
from rpr3gen.model.paper import read_paper
from rpr3gen.model.reading import one_line
from rpr3gen.model.spatial import is_spatial, read_spatial
from rpr3gen.model.types import Model
from rpr3gen.validation import Instance, Optional, PathArg, checked

__all__ = ["load_model", "model_from_dict", "read_model_data"]


@checked(path=Optional(PathArg()), generated=Optional(PathArg()))
def load_model(
    path: str | os.PathLike[str] | None = None,
    generated: str | os.PathLike[str] | None = None,
) -> Model:
    """Read and validate a model file.

    Args:
        path: A TOML model file; ``None`` loads the packaged paper robot (``models/paper.toml``).
        generated: A folder written by ``rpr3gen generate --out DIR`` whose code evaluates the
            model; ``None`` uses the installed generated package.

    Returns:
        The validated model, with the defaults of ``docs/conventions.md`` filled in.

    Raises:
        ModelError: If the file cannot be read, is not valid TOML, or any key or value is wrong;
            the one-line message names the file and the dotted key.
    """
    source, data = read_model_data(path)
    model = model_from_dict(data, source=source)
    if generated is None:
        return model
    return dataclasses.replace(model, generated=os.fspath(generated))


def read_model_data(path: str | os.PathLike[str] | None = None) -> tuple[str, dict[str, Any]]:
    """Read a model file as parsed TOML, not yet validated (see :func:`model_from_dict`).

    Args:
        path: A TOML model file; ``None`` reads the packaged paper robot.

    Returns:
        The file's name for messages and its tables as nested dictionaries.

    Raises:
        ModelError: If the file cannot be read or is not valid UTF-8 TOML.
    """
    if path is None:
        resource = importlib.resources.files("rpr3gen") / "models" / "paper.toml"
        source, read_bytes = str(resource), resource.read_bytes
    else:
        source = os.fspath(path)
        read_bytes = Path(source).read_bytes
    try:
        raw = read_bytes()
    except FileNotFoundError:
        raise ModelError(f"{source}: model file not found") from None
    except IsADirectoryError:
        raise ModelError(f"{source}: is a directory, not a model file") from None
    except OSError as exc:
        raise ModelError(f"{source}: cannot read model file: {exc.strerror or exc}") from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ModelError(f"{source}: not UTF-8 text (bad byte at offset {exc.start})") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ModelError(f"{source}: invalid TOML: {one_line(str(exc))}") from None
    return source, data


@checked(data=Instance(Mapping, "a mapping (the parsed TOML)"), source=Instance(str, "a str"))
def model_from_dict(data: Mapping[str, Any], source: str = "<dict>") -> Model:
    """Validate a model given as nested mappings (the parsed TOML) and build the :class:`Model`.

    Args:
        data: Same structure as a model file: ``name``, ``actuation`` and the tables
            ``geometry``, ``mass``, optional ``environment`` and ``payload`` (the paper's
            format), or ``leg``, ``actuated``, ``legs``, ``platform``... (the general planar
            format, or a spatial robot's when ``leg`` is UPS, RUS, PUS, RSS2 or PSS2:
            docs/spatial-robots.md). Lists may be lists, tuples or numpy arrays.
        source: Name used in error messages.

    Raises:
        ModelError: On the first problem found, naming ``source`` and the dotted key.
    """
    if isinstance(data, Mapping) and is_spatial(data):
        return read_spatial(data, source)
    if isinstance(data, Mapping) and is_general(data):
        return read_general(data, source)
    return read_paper(data, source)
