"""A whole mechanism over NumPy arrays: ``dyadfmu.evaluate(mechanism, inputs, outputs)``
runs a mechanism FMU's model over every sample of a batch in calls of its binary
(``dyadfmu_evaluate_columns``; a plant's through ``dyadfmu_evaluate_rows``; no per-sample
Python), computing only what the outputs asked need (a mechanism FMU leaves its
effective inertia out unless it is asked).

The mechanism: a shipped scene's name (its built FMU), a scene file ``.toml`` (its FMU
built where missing or older than the file) or an ``.fmu``. Inputs and parameters by the
FMU's variable names, in its units (an angle in rad); each an array or a number, all
broadcast together (NumPy's rules) to the batch's shape; an input left out keeps its
start value. Every value must be a finite real number; a name that is not an input
(parameter) of the FMU, values that do not broadcast or are not finite are refused with
the name, before anything runs. Each sample is the FMU's own answer to those inputs, bit
for bit what its FMI calls give; a sample without an answer (the mechanism does not
assemble there, a dyad at a dead centre) has NaN outputs and its status says so."""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import paths
from .batch import _bounds, _refuse_overlap, _shown, _writable

__all__ = ["Evaluation", "evaluate"]

#: Samples per call of the binary: bounds the contiguous copy of the inputs.
CHUNK = 65_536
#: The FMI status of a sample with an answer.
OK = 0


@dataclass(frozen=True)
class Evaluation:
    """The outputs asked, by name (arrays of the batch's shape, in ``units``), and each
    sample's FMI status (0 ok; else the FMU had no answer there and the outputs are NaN)."""

    values: dict
    units: dict
    status: np.ndarray

    def __getitem__(self, name: str) -> np.ndarray:
        return self.values[name]

    @property
    def ok(self) -> np.ndarray:
        """Where the FMU answered."""
        return self.status == OK


def _fmu(mechanism: str | Path, fmi: int) -> Path:
    """The FMU of a shipped scene's name, a scene file (built where stale) or an .fmu."""
    text = str(mechanism)
    if text.endswith(".fmu"):
        if not Path(text).is_file():
            raise ValueError(f"{text}: no such FMU")
        return Path(text)
    if text.endswith(".toml"):
        from .report import drivers_drawing, own_scene

        scene = Path(text).resolve()
        if not scene.is_file():
            raise ValueError(f"{text}: no such scene file")
        identifier = drivers_drawing.read_scene(scene).identifier
        return own_scene.scene_fmu(scene, identifier, fmi, Path.cwd(), lambda _: None)
    return _shipped(text, fmi)


@functools.lru_cache(maxsize=64)
def _shipped(name: str, fmi: int) -> Path:
    """The built FMU of a shipped scene, found once per process (its binary is loaded
    once too: a rebuild reaches a new process)."""
    if not (paths.SCENES_DIR / f"{name}.toml").is_file():
        raise ValueError(
            f"unknown mechanism {name!r}: a shipped scene's name, a scene file .toml or an .fmu"
        )
    return paths.built_fmu(name, fmi)


@functools.lru_cache(maxsize=64)
def _reals(md: object) -> tuple[dict, dict, dict]:
    """(unit by name of every Real variable, the inputs', the parameters'), read once per
    model description."""
    reals = [v for v in md.modelVariables if v.type in ("Real", "Float64")]
    units = {v.name: v.unit or "" for v in reals}
    of = {kind: {v.name: units[v.name] for v in reals if v.causality == kind} for kind in
          ("input", "parameter")}  # fmt: skip
    return units, of["input"], of["parameter"]


def _named(given: dict, allowed: dict, what: str, fmu: Path) -> dict[str, np.ndarray]:
    """The arrays ``given``, each name one of ``allowed`` (name -> unit), as float64."""
    unknown = sorted(set(given) - set(allowed))
    if unknown:
        shown = ", ".join(sorted(allowed)) or "none"
        raise ValueError(f"{', '.join(unknown)}: not {what} of {fmu.name} (its {what}: {shown})")
    arrays = {}
    for name, value in given.items():
        try:
            arrays[name] = np.asarray(value, dtype=np.float64)
        except (TypeError, ValueError, OverflowError):
            raise ValueError(f"{name} must be real numbers, not {_shown(value)}") from None
    checked = _finite_owners(arrays)
    for name, array in arrays.items():
        if name in checked:
            continue
        finite = np.isfinite(array)
        bad = () if finite.all() else np.flatnonzero(~finite)
        if len(bad):
            at = f"[{', '.join(map(str, np.unravel_index(bad[0], array.shape)))}]"
            raise ValueError(
                f"{name}{at if array.ndim else ''} is {array.flat[bad[0]]}: every value "
                "must be finite"
            )
    return arrays


def _owner(array: np.ndarray) -> np.ndarray:
    """The array whose memory ``array`` views (itself where it owns its memory)."""
    while isinstance(array.base, np.ndarray):
        array = array.base
    return array


def _finite_owners(arrays: dict[str, np.ndarray]) -> set[str]:
    """The names of the arrays that view one contiguous float64 array, no larger than they
    are together, whose every value is finite: the columns of a table of samples, checked
    in one pass over the table instead of a strided pass each (a table of 1,000,000 rows
    and 5 columns: about 2 against 9 ns a sample). Where that array holds a value that is
    not finite, the caller checks each column, and names the first one that does."""
    views: dict[int, tuple[np.ndarray, list[str]]] = {}
    for name, array in arrays.items():
        owner = _owner(array)
        if owner is array or owner.dtype != np.float64 or not owner.flags.c_contiguous:
            continue
        (low, high), (first, last) = _bounds(array), _bounds(owner)
        inside = first <= low and high <= last  # not so where a view was made to reach out
        steps = [low - first, *array.strides]  # whole values: no double made of two halves
        if inside and all(step % owner.itemsize == 0 for step in steps):
            views.setdefault(id(owner), (owner, []))[1].append(name)
    checked: set[str] = set()
    for owner, names in views.values():
        if owner.size <= sum(arrays[n].size for n in names) and np.isfinite(owner).all():
            checked.update(names)
    return checked


def _shape(arrays: dict[str, np.ndarray]) -> tuple[int, ...]:
    try:
        return tuple(np.broadcast_shapes(*(a.shape for a in arrays.values())))
    except ValueError:
        listed = ", ".join(f"{n} {a.shape}" for n, a in arrays.items())
        raise ValueError(f"the inputs do not broadcast to one batch shape: {listed}") from None


def _columns(arrays: dict, names: tuple, shape: tuple, start: int, stop: int) -> np.ndarray:
    """Samples start to stop of the named arrays as contiguous rows."""
    out = np.empty((stop - start, len(names)))
    for k, name in enumerate(names):
        out[:, k] = np.broadcast_to(arrays[name], shape).reshape(-1)[start:stop]
    return out


def evaluate(
    mechanism: str | Path,
    inputs: dict | None = None,
    outputs: list | tuple = (),
    parameters: dict | None = None,
    fmi: int = 2,
    out: Evaluation | None = None,
) -> Evaluation:
    """The ``outputs`` (names of the FMU's Real variables) of ``mechanism`` at every sample
    of ``inputs`` (name -> array or number) with ``parameters`` (tunable parameters,
    name -> array or number); see the module's text. With ``out`` (the Evaluation of an
    earlier call of the same shape and outputs) the results are written into its arrays,
    which are returned: a sweep of many batches allocates nothing."""
    from .sweep.rows import columns_entry, rows_entry

    fmu = _fmu(mechanism, fmi)
    entry = rows_entry(fmu)  # loaded once per FMU
    if entry is None:
        raise ValueError(f"{fmu.name} has no dyadfmu_evaluate_rows: not an FMU of this project")
    units, given, tunable = _reals(entry.md)
    x = _named(dict(inputs or {}), given, "inputs", fmu)
    p = _named(dict(parameters or {}), tunable, "tunable parameters", fmu)
    wanted = tuple(dict.fromkeys(outputs))
    missing = [n for n in wanted if n not in units]
    if missing or not wanted:
        raise ValueError(
            f"outputs: {', '.join(missing) or 'none asked'}: name Real variables of {fmu.name}"
        )
    shape = _shape({**x, **p})
    units = {n: units[n] for n in wanted}
    into = _into(out, wanted, shape, [*x.values(), *p.values()], units)
    by_columns = columns_entry(fmu)
    done = _by_columns(by_columns, {**x, **p}, wanted, shape, into) if by_columns else None
    return done if done is not None else _run(entry, x, p, wanted, shape, into)


def _into(
    out: Evaluation | None, wanted: tuple, shape: tuple, read: list, units: dict
) -> Evaluation:
    """The Evaluation the results go into: `out`'s arrays, each checked for its type,
    shape and layout and that it shares no memory with another or with an input, or new
    ones (the outputs one row each of a block)."""
    if out is None:
        block = np.empty((len(wanted), math.prod(shape)))
        values = {n: block[k].reshape(shape) for k, n in enumerate(wanted)}
        return Evaluation(values, units, np.empty(shape, dtype=np.intc))
    if not isinstance(out, Evaluation):
        raise TypeError(
            f"out must be the Evaluation of an earlier dyadfmu.evaluate, not "
            f"{type(out).__name__} {_shown(out)}"
        )
    missing = [n for n in wanted if not isinstance(out.values, dict) or n not in out.values]
    if missing:
        raise ValueError(f"out has no array for {', '.join(missing)}: pass the Evaluation "
                         "of a call that asked the same outputs")  # fmt: skip
    arrays = {f"out[{n!r}]": _writable(f"out[{n!r}]", out.values[n], np.float64, shape)
              for n in wanted}  # fmt: skip
    arrays["out.status"] = _writable("out.status", out.status, np.intc, shape)
    spans = {label: _bounds(a) for label, a in arrays.items()}
    _refuse_overlap(spans, [_bounds(a) for a in read], "{}", "an input or parameter")
    return Evaluation({n: out.values[n] for n in wanted}, units, out.status)


def _flat(array: np.ndarray, shape: tuple) -> np.ndarray:
    """The array's values over the batch, one dimension: as it is where it holds one value
    or has the batch's shape (a view where it can be), else broadcast."""
    if array.size == 1 or array.shape == shape:
        return array.reshape(-1)
    return np.broadcast_to(array, shape).reshape(-1)


def _by_columns(entry: object, x: dict, wanted: tuple, shape: tuple, into: Evaluation):
    """Every sample in chunks of CHUNK through the columns entry (a value held for every
    sample passed once), each chunk written in place into `into`'s arrays (checked by
    _into); None where the binary refuses it (a model with states)."""
    count = math.prod(shape)
    flat = {n: _flat(a, shape) for n, a in x.items()}
    columns = [into[n].reshape(-1) for n in wanted]  # views: C-contiguous
    status = into.status.reshape(-1)
    for start in range(0, max(count, 1), CHUNK):
        stop = min(start + CHUNK, count)
        part = {n: a if a.size == 1 else a[start:stop] for n, a in flat.items()}
        ys = [c[start:stop] for c in columns]
        if entry.write(part, wanted, stop - start, ys, status[start:stop]) is None:
            return None
    return into


def _run(entry: object, x: dict, p: dict, wanted: tuple, shape: tuple, into: Evaluation):
    """Every sample in chunks of CHUNK, into `into`'s arrays."""
    count = math.prod(shape)
    columns = [into[n].reshape(-1) for n in wanted]
    status = into.status.reshape(-1)
    x_names, p_names = tuple(x), tuple(p)
    for start in range(0, count, CHUNK):
        stop = min(start + CHUNK, count)
        y, status[start:stop] = entry.evaluate(
            p_names, _columns(p, p_names, shape, start, stop),
            x_names, _columns(x, x_names, shape, start, stop), wanted,
        )  # fmt: skip
        for k, column in enumerate(columns):
            column[start:stop] = y[:, k]
    return into
