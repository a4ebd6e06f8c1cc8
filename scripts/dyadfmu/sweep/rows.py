"""The mechanism FMU's model over many rows in one call: ``dyadfmu_evaluate_rows``, which
every dyadfmu FMU binary exports beside the FMI API (fmu/fmu_instance.c,
``fmu_evaluate_rows``). A kinetostatic study evaluates all the crank angles of a chunk
of designs in one call instead of two FMI calls per angle from Python; the values are
those the FMI calls give, bit for bit (each row goes through the same set and get).
"""

from __future__ import annotations

import ctypes
from pathlib import Path

import numpy as np
from fmpy.model_description import ModelDescription

from .. import paths
from ..fmi.slave import unpacked

__all__ = ["RowsEntry", "rows_entry"]

_UINT_P = ctypes.POINTER(ctypes.c_uint)
_DOUBLE_P = ctypes.POINTER(ctypes.c_double)
_INT_P = ctypes.POINTER(ctypes.c_int)


class RowsEntry:
    """``dyadfmu_evaluate_rows`` of one FMU binary, by variable names."""

    def __init__(self, function: ctypes._CFuncPtr, md: ModelDescription):
        self._f = function
        self.md = md
        self._token = md.guid.encode()
        self._vr = {v.name: v.valueReference for v in md.modelVariables}
        function.restype = ctypes.c_int
        function.argtypes = [ctypes.c_char_p]
        function.argtypes += [_UINT_P, ctypes.c_size_t, _DOUBLE_P] * 2
        function.argtypes += [_UINT_P, ctypes.c_size_t, _DOUBLE_P, _INT_P, ctypes.c_size_t]

    def _refs(self, names: tuple) -> ctypes.Array:
        return (ctypes.c_uint * max(len(names), 1))(*(self._vr[n] for n in names))

    def evaluate(
        self, p_names: tuple, p: np.ndarray, x_names: tuple, x: np.ndarray, y_names: tuple
    ) -> tuple[np.ndarray, np.ndarray]:
        """(outputs ``y_names`` per row, FMU status per row: 0 is OK) of the rows of
        parameters ``p`` and inputs ``x``."""
        rows = len(x)
        p = np.ascontiguousarray(p, dtype=float).reshape(rows, len(p_names))
        x = np.ascontiguousarray(x, dtype=float).reshape(rows, len(x_names))
        y = np.empty((rows, len(y_names)))
        status = np.empty(rows, dtype=np.intc)
        done = self._f(
            self._token,
            self._refs(p_names), len(p_names), p.ctypes.data_as(_DOUBLE_P),
            self._refs(x_names), len(x_names), x.ctypes.data_as(_DOUBLE_P),
            self._refs(y_names), len(y_names), y.ctypes.data_as(_DOUBLE_P),
            status.ctypes.data_as(_INT_P), rows,
        )  # fmt: skip
        if done != 0:
            raise RuntimeError(f"dyadfmu_evaluate_rows refused the call (status {done})")
        return y, status


_ENTRIES: dict = {}


def rows_entry(fmu: str | Path) -> RowsEntry | None:
    """The rows entry of an FMU's binary for this platform, None where it has none (an
    FMU from another tool, say)."""
    key = str(fmu)
    if key not in _ENTRIES:
        md, directory = unpacked(fmu)
        version = int(md.fmiVersion.split(".")[0])
        identifier = md.coSimulation.modelIdentifier
        binary = Path(directory) / "binaries" / paths.PLATFORM[version] / f"{identifier}.so"
        try:
            function = ctypes.CDLL(str(binary)).dyadfmu_evaluate_rows
        except (OSError, AttributeError):
            _ENTRIES[key] = None
        else:
            _ENTRIES[key] = RowsEntry(function, md)
    return _ENTRIES[key]
