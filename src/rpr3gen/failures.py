"""The failure policy's first level: which samples the generated functions refuse, with which
return code, for any backend.

The failure conditions of each function, with their thresholds and codes, come from the manifest
(:mod:`rpr3gen.manifest`; e.g. ``conditioning`` under ``MIN_CONDITIONING`` = 1e-9 is
``SINGULAR``). The generated C applies them itself; :func:`return_codes` applies the same
conditions to any backend's results, so the NumPy and C paths agree on every code, and
:func:`apply` blanks the failed samples (NaN). What a command refuses on top is
:mod:`rpr3gen.policy`.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from rpr3gen.manifest import CheckInfo, FunctionInfo

__all__ = ["apply", "finite_rows", "none_failed", "return_codes"]


def finite_rows(array: np.ndarray) -> np.ndarray:
    """(n,) bool: every value of the row is finite, for an (n, k) array of either layout.

    One pass over the values in memory order answers the usual case, all finite; only then is
    each row looked at (``isfinite(...).all(axis=1)`` over rows of 3 would cost ten times more).
    """
    if np.isfinite(array).all():
        return np.ones(array.shape[0], dtype=bool)
    return np.isfinite(array.T).all(axis=0)


def _tested(
    check: CheckInfo,
    function: FunctionInfo,
    inputs: Sequence[np.ndarray],
    outputs: Sequence[np.ndarray],
) -> list[np.ndarray] | np.ndarray | None:
    """What ``check`` tests: the arrays that must be finite (a list), the (n,) values that must
    not be below its threshold (an array), or None (a custom check: the C applies it)."""
    if check.kind == "inputs_not_finite":
        return list(inputs)
    if check.kind == "custom":
        return None
    if check.kind == "below":
        assert check.output is not None
        assert check.component is not None
        return outputs[check.output][:, check.component]
    return [o for o, i in zip(outputs, function.outputs, strict=True) if not i.hidden]


def none_failed(
    function: FunctionInfo,
    inputs: Sequence[np.ndarray],
    outputs: Sequence[np.ndarray],
    output_sums: np.ndarray | None = None,
) -> bool:
    """Every sample passes every check that :func:`return_codes` applies (a NaN fails them):
    one reduction per array, where the per-sample codes cost a dozen more passes.

    ``output_sums``: the sums of the output rows over the samples, as the generated NumPy
    functions write them (their ``sums`` argument, taken while each row is in cache): then the
    outputs are finite when these sums are, and are not read again. A sum that overflows makes
    this answer False; the per-sample codes then decide.
    """
    with np.errstate(invalid="ignore"):
        for check in function.checks:
            if check.kind == "outputs_not_finite" and output_sums is not None:
                if not np.isfinite(output_sums).all():
                    return False
                continue
            tested = _tested(check, function, inputs, outputs)
            if isinstance(tested, list):
                if not all(np.isfinite(a).all() for a in tested):
                    return False
            elif tested is not None and not (tested >= check.threshold).all():
                return False
    return True


def return_codes(
    function: FunctionInfo,
    inputs: Sequence[np.ndarray],
    outputs: Sequence[np.ndarray],
    applied: bool = False,
) -> np.ndarray:
    """Per sample, the code the generated C returns for it: 0, or the first failed check's.

    Args:
        function: the function, from the manifest.
        inputs: its inputs, each (n, size).
        outputs: all its outputs as computed, hidden ones included, each (n, size).
        applied: the backend applied the checks itself and wrote a failed sample as a row of
            NaN (the generated C batch): then a failed sample's code is the input check's when
            an input is not finite, else the one code all the other checks share.

    Returns:
        (n,) int array.
    """
    n = inputs[0].shape[0]
    codes = np.zeros(n, dtype=np.intc)
    pending = np.ones(n, dtype=bool)
    if applied:
        public = [o for o, info in zip(outputs, function.outputs, strict=True) if not info.hidden]
        failed = np.zeros(n, dtype=bool)
        for out in public:
            failed |= np.isnan(out).all(axis=1)
        for check in function.checks:
            if check.kind == "inputs_not_finite":
                bad = ~np.all([finite_rows(a) for a in inputs], axis=0)
                codes[bad] = check.code
                pending &= ~bad
        later = [c.code for c in function.checks if c.kind != "inputs_not_finite"]
        if later:
            codes[failed & pending] = later[0]
        return codes
    if none_failed(function, inputs, outputs):  # the usual case: one pass over each array
        return codes
    with np.errstate(invalid="ignore"):
        for check in function.checks:
            tested = _tested(check, function, inputs, outputs)
            if tested is None:  # C only, applied there
                continue
            if isinstance(tested, list):
                failed = ~np.all([finite_rows(a) for a in tested], axis=0)
            else:
                failed = ~(tested >= check.threshold)
            hit = failed & pending
            codes[hit] = check.code
            pending &= ~hit
    return codes


def apply(
    function: FunctionInfo,
    inputs: Sequence[np.ndarray],
    outputs: Sequence[np.ndarray],
    applied: bool = False,
) -> np.ndarray:
    """Blank (NaN) every output row of a failed sample, in place; return the codes.

    ``applied``: as in :func:`return_codes`.
    """
    codes = return_codes(function, inputs, outputs, applied)
    failed = codes != 0
    if failed.any():
        for out in outputs:
            out[failed] = np.nan
    return codes
