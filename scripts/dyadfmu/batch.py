"""The C core over NumPy arrays: ``dyadfmu.solve(type, **arrays)`` solves every
configuration of a batch in one call of ``dyad_solve_batch`` (no per-row Python).

Keywords name the fields of ``dyad_input`` (units as there): per link ``m_`` or ``n_``
followed by ``dir``, ``length``, ``omega``, ``epsilon``, ``accel_d``, ``com``, ``mass``,
``inertia``, ``force``, ``moment``; then ``guide_k``, ``guide_p``, ``gravity`` and
``singular_threshold``. A vector field takes an array whose last axis has length 2, a scalar
field any array; all broadcast together (NumPy's rules, a vector's last axis aside) to the
batch's shape. A field left out has ``dyad_input_default()``'s value. Every row is solved
exactly as ``dyad_solve`` solves it, bit for bit, and has its own status.
"""

from __future__ import annotations

import ctypes
import functools
import math
from dataclasses import dataclass

import numpy as np

from .core import (
    INPUT_COLUMN_COUNT,
    LINK_KEYS,
    OUTPUT_COLUMN_COUNT,
    STATUS,
    TYPES,
    BatchInput,
    BatchOutput,
    Core,
)

#: Fields of a link that are vectors (x, y); the others are scalars.
_LINK_VECTORS = ("dir", "accel_d", "com", "force")
#: Keywords in the order of dyad_input, each with its number of columns.
FIELDS: tuple[tuple[str, int], ...] = (
    *((f"m_{key}", 2 if key in _LINK_VECTORS else 1) for key in LINK_KEYS),
    *((f"n_{key}", 2 if key in _LINK_VECTORS else 1) for key in LINK_KEYS),
    ("guide_k", 2),
    ("guide_p", 2),
    ("gravity", 2),
    ("singular_threshold", 1),
)
#: Outputs in the order of dyad_result, each with its number of columns.
OUTPUTS: tuple[tuple[str, int], ...] = (
    ("r_mk", 2),
    ("r_np", 2),
    ("r_mn", 2),
    ("n_mk", 1),
    ("n_np", 1),
    ("n_mn", 1),
    ("m_mk", 1),
    ("m_np", 1),
    ("m_mn", 1),
    ("denominator", 1),
    ("conditioning", 1),
    ("amplification", 1),
)
assert sum(width for _, width in FIELDS) == INPUT_COLUMN_COUNT
_WIDTHS = dict(FIELDS)
assert sum(width for _, width in OUTPUTS) == OUTPUT_COLUMN_COUNT


@dataclass(frozen=True)
class Reactions:
    """The outputs of a batch, each an array of the batch's shape (vectors with a last
    axis of 2): forces in N, moments in N m, the rest dimensionless; ``status`` per row
    (0 ok, 1 singular, 2 invalid input, 3 out of range) and ``field``, the dyad_field an
    invalid row names (0 otherwise). A row that is not ok has NaN reactions."""

    r_mk: np.ndarray
    r_np: np.ndarray
    r_mn: np.ndarray
    n_mk: np.ndarray
    n_np: np.ndarray
    n_mn: np.ndarray
    m_mk: np.ndarray
    m_np: np.ndarray
    m_mn: np.ndarray
    denominator: np.ndarray
    conditioning: np.ndarray
    amplification: np.ndarray
    status: np.ndarray
    field: np.ndarray

    @property
    def ok(self) -> np.ndarray:
        """True where the row was solved."""
        return self.status == 0

    def reason(self, index: int | tuple) -> str:
        """Why one row is not ok, in words ("invalid input: link_m.mass"); "ok" if it is."""
        status = STATUS.get(int(self.status[index]), "?")
        field = default_core().field_name(int(self.field[index]))
        return f"{status}: {field}" if field else status


@functools.lru_cache(maxsize=1)
def default_core() -> Core:
    """The core library ``dyadfmu.solve`` calls, loaded once."""
    return Core()


_FLOAT64 = np.dtype(np.float64)


def _shown(value: object) -> str:
    """A value for an error message, cut short."""
    text = repr(value)
    return text if len(text) <= 60 else f"{text[:45]}... ({len(text)} characters)"


def _converted(name: str, value: object) -> np.ndarray:
    """A field's value as float64, refusing complex numbers and values beyond a double's
    range by name (the slow path: a float64 array is taken as it is)."""
    try:
        array = np.asarray(value)
        if array.dtype.kind == "c":
            raise TypeError(f"not complex ({array.dtype}): {_shown(value)}")
        return np.asarray(array, dtype=np.float64)
    except (TypeError, ValueError) as error:
        raise ValueError(f"{name} must be real numbers: {error}") from None
    except OverflowError:
        raise ValueError(
            f"{name} must be real numbers within a double's range, not {_shown(value)}"
        ) from None


def _as_field(name: str, width: int, value: object) -> np.ndarray:
    if type(value) is np.ndarray and value.dtype is _FLOAT64:
        array = value
    else:
        array = _converted(name, value)
    if width == 2 and (array.ndim == 0 or array.shape[-1] != 2):
        raise ValueError(f"{name} is a vector: its last axis must have length 2, not {array.shape}")
    return array


def _checked_fields(arrays: dict) -> dict[str, np.ndarray]:
    widths = _WIDTHS
    unknown = sorted(set(arrays) - set(widths))
    if unknown:
        raise TypeError(
            f"unknown field {', '.join(map(repr, unknown))}; expected some of {', '.join(widths)}"
        )
    return {name: _as_field(name, widths[name], value) for name, value in arrays.items()}


def _batch_shape(fields: dict[str, np.ndarray]) -> tuple[int, ...]:
    shapes = {name: a.shape[:-1] if _WIDTHS[name] == 2 else a.shape for name, a in fields.items()}
    distinct = set(shapes.values())
    if len(distinct) == 1:  # the common case, without NumPy's broadcasting rules
        return distinct.pop()
    try:
        return tuple(np.broadcast_shapes(*shapes.values())) if shapes else ()
    except ValueError:
        listed = ", ".join(f"{name} {shape}" for name, shape in shapes.items())
        raise ValueError(f"the fields do not broadcast to one batch shape: {listed}") from None


def _column_source(array: np.ndarray, width: int, shape: tuple) -> tuple[np.ndarray, int]:
    """An array to read a field's columns from, and its stride in elements along rows:
    the caller's own where it is contiguous and of the batch's shape, one value given once
    (stride 0), else a broadcast copy."""
    rows_shape = array.shape[:-1] if width == 2 else array.shape
    if math.prod(rows_shape) == 1:
        return np.ascontiguousarray(array.reshape(width)), 0
    if (
        len(shape) == 1
        and rows_shape == shape
        and array.strides[0] % 8 == 0
        and (width == 1 or array.strides[1] == 8)
    ):
        # one axis of rows at any stride (a column of a table, say): read in place
        return array, array.strides[0] // 8
    if rows_shape != shape or not array.flags.c_contiguous:
        full = shape + ((2,) if width == 2 else ())
        array = np.ascontiguousarray(np.broadcast_to(array, full))
    return array, width


def _address(array: np.ndarray) -> int:
    """The address of an array's first element. ctypes reads it from the buffer of a
    writable contiguous array (most of a batch's) in a third of the time NumPy's array
    interface takes; any other array goes by that interface."""
    try:
        return ctypes.addressof(ctypes.c_char.from_buffer(array))
    except (TypeError, ValueError, BufferError):
        return array.__array_interface__["data"][0]


def _input_columns(
    fields: dict[str, np.ndarray], shape: tuple
) -> tuple[BatchInput, list, list[tuple[int, int]]]:
    """dyad_batch_input over the fields' arrays, as one int64 table of (data, stride) words:
    built from a plain list, it keeps a call's fixed cost far below a ctypes attribute per
    column. Also what keeps the arrays alive, and the bytes each one spans. A field given
    as NumPy makes it (C-contiguous, of the batch's shape) is read in place at once."""
    words = [0] * (2 * INPUT_COLUMN_COUNT)
    alive, spans, c = [], [], 0
    full = {1: shape, 2: shape + (2,)}
    for name, width in FIELDS:
        array = fields.get(name)
        if array is not None:
            if array.shape == full[width] and array.flags.c_contiguous:
                source, stride = array, width
                address = _address(source)
                spans.append((address, address + source.nbytes))
            else:
                source, stride = _column_source(array, width, shape)
                address = _address(source)
                spans.append(_span(source, address))
            alive.append(source)
            words[2 * c : 2 * c + 2] = address, stride
            if width == 2:
                words[2 * c + 2 : 2 * c + 4] = address + 8, stride
        c += width
    table = np.array(words, np.int64)
    alive.append(table)
    return BatchInput.from_buffer(table), alive, spans


def _new_outputs(shape: tuple) -> tuple[dict[str, np.ndarray], dict[str, int]]:
    """New output arrays, the Reals all views of one allocation (a vector's components
    side by side), and each one's address: worked out from the allocation's own, which
    costs one lookup instead of one per array."""
    count = math.prod(shape)
    reals = np.empty(OUTPUT_COLUMN_COUNT * count, dtype=np.float64)
    flags = np.empty((2, count), dtype=np.uint8)
    arrays, addresses, at = {}, {}, 0
    base, flags_base = _address(reals), _address(flags)
    for name, width in OUTPUTS:
        arrays[name] = reals[at : at + width * count].reshape(shape + ((2,) if width == 2 else ()))
        addresses[name], at = base + 8 * at, at + width * count
    arrays["status"], arrays["field"] = flags[0].reshape(shape), flags[1].reshape(shape)
    addresses["status"], addresses["field"] = flags_base, flags_base + count
    return arrays, addresses


def _given_outputs(out: Reactions, shape: tuple) -> dict[str, np.ndarray]:
    """The arrays of `out` to write into, each checked for its type, shape and layout."""
    if not isinstance(out, Reactions):
        raise TypeError(
            f"out must be the Reactions of an earlier dyadfmu.solve, not {type(out).__name__} "
            f"{_shown(out)}"
        )
    arrays = {}
    kinds = [(name, width, np.float64) for name, width in OUTPUTS]
    for name, width, dtype in kinds + [("status", 1, np.uint8), ("field", 1, np.uint8)]:
        want = shape + ((2,) if width == 2 else ())
        arrays[name] = _writable(f"out.{name}", getattr(out, name, None), dtype, want)
    return arrays


def _writable(label: str, array: object, dtype: type, want: tuple) -> np.ndarray:
    """`array` where it is a writable C-contiguous array of `dtype` and shape `want`;
    otherwise refused with `label` and what it is."""
    if not (
        isinstance(array, np.ndarray)
        and array.dtype == dtype
        and array.shape == want
        and array.flags.c_contiguous
        and array.flags.writeable
    ):
        got = (
            f"{'a read-only ' if not array.flags.writeable else ''}"
            f"{'' if array.flags.c_contiguous else 'non-contiguous '}{array.dtype} array "
            f"of shape {array.shape}"
            if isinstance(array, np.ndarray)
            else f"{type(array).__name__} {_shown(array)}"
        )
        raise ValueError(
            f"{label} must be a writable C-contiguous {np.dtype(dtype).name} array "
            f"of shape {want}, not {got}"
        )
    return array


def _span(array: np.ndarray, address: int) -> tuple[int, int]:
    """The bytes an array's elements occupy, first to one past the last."""
    first = last = address
    if array.flags.c_contiguous:
        return first, first + array.nbytes
    for extent, stride in zip(array.shape, array.strides, strict=True):
        reach = (extent - 1) * stride
        first, last = (first + reach, last) if reach < 0 else (first, last + reach)
    return first, last + array.itemsize


def _bounds(array: np.ndarray) -> tuple[int, int]:
    """_span of an array at its own address (a strided one's read once from NumPy)."""
    if array.flags.c_contiguous:
        first = _address(array)
        return first, first + array.nbytes
    return _span(array, array.__array_interface__["data"][0])


def _refuse_overlap(
    written: dict[str, tuple[int, int]],
    read: list[tuple[int, int]],
    label: str = "out.{}",
    inputs: str = "an input field",
) -> None:
    """A batch's outputs (spans by name; `label` names one in a refusal, `inputs` the
    inputs) must not share memory with its inputs (spans) nor with each other: the rows
    are solved in blocks, and an earlier block's results would become a later one's
    inputs, or be overwritten by another output's. In order of their first byte, a span
    overlaps an earlier one of a kind exactly when it starts before the furthest end of
    that kind's spans so far (the output reaching it is `widest`)."""
    spans = [(first, last, name) for name, (first, last) in written.items() if first < last]
    spans += [(first, last, "") for first, last in read if first < last]
    spans.sort()
    output_end = input_end = 0
    widest = ""
    for first, last, name in spans:
        if not name:  # an input
            if first < output_end:
                name = next(n for n, (f, e) in written.items() if f < last and first < e)
                raise ValueError(f"{label.format(name)} shares memory with {inputs}: pass a copy")
            input_end = max(input_end, last)
        elif first < input_end:
            raise ValueError(f"{label.format(name)} shares memory with {inputs}: pass a copy")
        elif first < output_end:
            raise ValueError(
                f"{label.format(widest)} and {label.format(name)} share memory: each output "
                "needs its own array"
            )
        else:
            output_end, widest = last, name


def _output_columns(shape: tuple, out: Reactions | None) -> tuple[BatchOutput, dict, dict]:
    """dyad_batch_output over `out`'s arrays or new ones, its table as for the inputs,
    and each array's span by name."""
    if out is None:
        arrays, addresses = _new_outputs(shape)
    else:
        arrays = _given_outputs(out, shape)
        addresses = {name: _address(array) for name, array in arrays.items()}
    words = []
    for name, width in OUTPUTS:
        address = addresses[name]
        words += (address, width, address + 8, width) if width == 2 else (address, width)
    words += addresses["status"], addresses["field"]
    spans = {name: (a, a + arrays[name].nbytes) for name, a in addresses.items()}
    arrays["_table"] = np.array(words, np.int64)
    return BatchOutput.from_buffer(arrays["_table"]), arrays, spans


def solve(dyad_type: str, *, out: Reactions | None = None, **arrays: object) -> Reactions:
    """Solves a batch of dyads of one type ("RRR", "RRT", "RTR", "TRT", "RTT") given as
    arrays of their fields (see the module's help); one C call for the whole batch. With
    `out` (the Reactions of an earlier batch of the same shape) the results are written
    into its arrays, which are returned: a sweep of many batches allocates nothing."""
    kind = dyad_type.upper() if isinstance(dyad_type, str) else dyad_type
    if kind not in TYPES:
        raise ValueError(f"unknown dyad type {dyad_type!r}; expected one of {', '.join(TYPES)}")
    fields = _checked_fields(arrays)
    shape = _batch_shape(fields)
    columns, alive, read = _input_columns(fields, shape)
    results, written, spans = _output_columns(shape, out)
    if out is not None:
        _refuse_overlap(spans, read)
    count = math.prod(shape)
    default_core().solve_batch(kind, count, columns, results)
    del alive  # the inputs were read during the call
    if out is not None:
        return out
    del written["_table"]
    return Reactions(**written)


__all__ = ["FIELDS", "OUTPUTS", "Reactions", "default_core", "solve"]
