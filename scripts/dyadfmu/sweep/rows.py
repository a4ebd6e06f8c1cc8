"""The mechanism FMU's model over many rows in one call: ``dyadfmu_evaluate_rows``, which
every dyadfmu FMU binary exports beside the FMI API (fmu/fmu_instance.c,
``fmu_evaluate_rows``). A kinetostatic study evaluates all the crank angles of a chunk
of designs in one call instead of two FMI calls per angle from Python; the values are
those the FMI calls give, bit for bit (each row goes through the same set and get).
``dyadfmu_evaluate_columns`` (``fmu_evaluate_columns``) gives the same values from
columns, the inputs and parameters written straight into the model's input block and
its outputs read straight out, for a model without states.
"""

from __future__ import annotations

import ctypes
import os
from pathlib import Path

import numpy as np
from fmpy.model_description import ModelDescription

from .. import paths
from ..batch import _address, _bounds, _refuse_overlap
from ..fmi.slave import unpacked

__all__ = ["ColumnsEntry", "RowsEntry", "columns_entry", "rows_entry"]

_UINT_P = ctypes.POINTER(ctypes.c_uint)
_DOUBLE_P = ctypes.POINTER(ctypes.c_double)
_INT_P = ctypes.POINTER(ctypes.c_int)
_STEP_P = ctypes.POINTER(ctypes.c_ssize_t)
#: The values of DYADFMU_LANES, the widest lanes the columns entry may take (fmu/README.md)
LANES = ("baseline", "avx2", "avx512")


class _Entry:
    """A function of one FMU binary beside the FMI API, called by variable names."""

    #: The function's argument types after the instantiation token.
    ARGUMENTS: list = []

    def __init__(self, function: ctypes._CFuncPtr, md: ModelDescription):
        self._f = function
        self.md = md
        self._token = md.guid.encode()
        self._vr = {v.name: v.valueReference for v in md.modelVariables}
        function.restype = ctypes.c_int
        function.argtypes = [ctypes.c_char_p, *self.ARGUMENTS]

    def _refs(self, names: tuple) -> ctypes.Array:
        return (ctypes.c_uint * max(len(names), 1))(*(self._vr[n] for n in names))


class RowsEntry(_Entry):
    """``dyadfmu_evaluate_rows`` of one FMU binary, by variable names."""

    ARGUMENTS = [_UINT_P, ctypes.c_size_t, _DOUBLE_P] * 3 + [_INT_P, ctypes.c_size_t]

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


class ColumnsEntry(_Entry):
    """``dyadfmu_evaluate_columns`` of one FMU binary, by variable names: the model at
    many samples, each input a column (one value for every sample, or one per sample)."""

    # the columns by address (an array of void*, as the C arrays of double* are passed):
    # ctypes' pointer objects cost more than a small call's evaluation
    ARGUMENTS = [_UINT_P, ctypes.c_size_t, ctypes.POINTER(ctypes.c_void_p), _STEP_P] * 2
    ARGUMENTS += [ctypes.c_void_p, ctypes.c_size_t]

    def evaluate(
        self,
        x: dict[str, np.ndarray],
        y_names: tuple,
        count: int,
        out: tuple[object, np.ndarray] | None = None,
    ) -> tuple[dict[str, np.ndarray], np.ndarray] | None:
        """(the outputs ``y_names``, each an array of ``count`` samples; the FMU status of
        each sample: 0 is OK) at the inputs and parameters ``x`` (name -> an array of
        ``count`` float64 values, or of one for every sample). None where the binary
        refuses the call (a model with states). ``out``: (one float64 array of ``count``
        values per output, such as the rows of a block; a C int array of ``count``)
        written in place, each at any stride of whole doubles (views of larger arrays,
        say), none sharing memory with another or with an input."""
        if out is None:
            block, status = np.empty((len(y_names), count)), np.empty(count, dtype=np.intc)
            out = (list(block), status)
        else:
            out = _written(out, y_names, count, [_column(a) for a in x.values()])
        return self.write(x, y_names, count, *out)

    def write(
        self, x: dict[str, np.ndarray], y_names: tuple, count: int, ys: list, status: np.ndarray
    ) -> tuple[dict[str, np.ndarray], np.ndarray] | None:
        """evaluate into ``ys`` and ``status``, which the caller has checked as evaluate
        checks its ``out`` (dyadfmu.evaluate checks a whole batch's arrays once)."""
        _check_lanes()
        x_names = tuple(x)
        columns = [_column(x[n]) for n in x_names]
        if any(c.size not in (1, count) for c in columns):
            raise ValueError("every column holds one value or one per sample")
        steps = [0 if c.size == 1 else c.strides[0] // c.itemsize for c in columns]
        done = self._f(
            self._token,
            self._refs(x_names), len(x_names), _addresses(map(_address, columns)), _steps(steps),
            self._refs(y_names), len(y_names), _addresses(map(_address, ys)),
            _steps([y.strides[0] // 8 for y in ys]), _address(status), count,
        )  # fmt: skip
        return None if done != 0 else (dict(zip(y_names, ys, strict=True)), status)


def _check_lanes() -> None:
    """Refuses a DYADFMU_LANES the binary would not know (it would take the widest lanes,
    whatever a typo meant), naming it."""
    lanes = os.environ.get("DYADFMU_LANES", "")
    if lanes not in ("", *LANES):
        raise ValueError(
            f"DYADFMU_LANES = {lanes!r}: not one of {', '.join(LANES)} (the widest lanes the "
            "columns entry may take; unset: the widest this CPU runs)"
        )


def _written(
    out: tuple[object, np.ndarray], y_names: tuple, count: int, columns: list
) -> tuple[list[np.ndarray], np.ndarray]:
    """``out``'s output arrays and statuses, checked: float64 outputs of ``count`` at
    strides of whole doubles, contiguous C int statuses, nothing shared."""
    block, status = out
    ys = list(block)
    arrays = all(isinstance(a, np.ndarray) for a in [*ys, status])
    if not arrays or len(ys) != len(y_names) or any(a.shape != (count,) for a in [*ys, status]):
        raise ValueError("out: one array of count values per output, and count statuses")
    if any(y.dtype != np.float64 or y.strides[0] % 8 or not y.flags.writeable for y in ys):
        raise ValueError("out: writable float64 values at strides of whole doubles")
    contiguous = count < 2 or status.strides[0] == status.itemsize
    if status.dtype != np.intc or not contiguous or not status.flags.writeable:
        raise ValueError("out: writable contiguous C int statuses")
    spans = {name: _bounds(y) for name, y in zip(y_names, ys, strict=True)}
    spans["status"] = _bounds(status)
    _refuse_overlap(spans, [_bounds(c) for c in columns], "the output {}", "an input")
    return ys, status


def _column(values: object) -> np.ndarray:
    """Values as a one-dimensional float64 array the binary reads in place: a view where
    its stride is a whole number of doubles, else a copy."""
    column = np.asarray(values, dtype=np.float64).reshape(-1)
    if column.size > 1 and column.strides[0] % column.itemsize != 0:
        column = np.ascontiguousarray(column)
    return column


def _addresses(addresses: object) -> ctypes.Array:
    listed = list(addresses)
    return (ctypes.c_void_p * max(len(listed), 1))(*listed)


def _steps(steps: list) -> ctypes.Array:
    return (ctypes.c_ssize_t * max(len(steps), 1))(*steps)


_BINARIES: dict = {}


def _binary(fmu: str | Path) -> tuple[ctypes.CDLL | None, ModelDescription]:
    """The loaded binary of an FMU for this platform (None where it cannot load), and its
    model description; loaded once per FMU."""
    key = str(fmu)
    if key not in _BINARIES:
        md, directory = unpacked(fmu)
        version = int(md.fmiVersion.split(".")[0])
        identifier = md.coSimulation.modelIdentifier
        binary = Path(directory) / "binaries" / paths.PLATFORM[version] / f"{identifier}.so"
        try:
            _BINARIES[key] = (ctypes.CDLL(str(binary)), md)
        except OSError:
            _BINARIES[key] = (None, md)
    return _BINARIES[key]


_ENTRIES: dict = {}


def _entry(fmu: str | Path, name: str, kind: type) -> object:
    key = (str(fmu), name)
    if key not in _ENTRIES:
        library, md = _binary(fmu)
        function = getattr(library, name, None) if library is not None else None
        _ENTRIES[key] = kind(function, md) if function is not None else None
    return _ENTRIES[key]


def rows_entry(fmu: str | Path) -> RowsEntry | None:
    """The rows entry of an FMU's binary for this platform, None where it has none (an
    FMU from another tool, say)."""
    return _entry(fmu, "dyadfmu_evaluate_rows", RowsEntry)


def columns_entry(fmu: str | Path) -> ColumnsEntry | None:
    """The columns entry of an FMU's binary for this platform, None where it has none
    (an FMU from another tool, or built before the entry)."""
    return _entry(fmu, "dyadfmu_evaluate_columns", ColumnsEntry)
