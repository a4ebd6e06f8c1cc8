"""One run of a study per design, of one of three kinds:

- :class:`KinetostaticRun`: the mechanism FMU turned through one revolution at constant
  crank speed (the loads from the study's load case at each angle);
- :class:`StrokeRun`: a ram or a cylinder moved once over its stroke, or a cylinder's
  link turned over a range of angles, rest to rest (:mod:`dyadfmu.sweep.stroke`), under
  constant loads; a design whose cylinder cannot turn its link over the range (its toggle
  within it, or its pin on the other branch) is a failed run before any sample;
- :class:`MultiStrokeRun`: every driver of a mechanism with several moved at once, each
  over its own range (an angle or a stroke), in one duration, under constant loads;
- :class:`DrivenRun`: the drive FMU (motor and rotor) and the mechanism FMU co-simulated
  with the stabilised coupling of :mod:`dyadfmu.cosim.mechanism_drive`: at each
  communication point the mechanism FMU gives its torque at zero crank acceleration
  and, as its directional derivative, the inertia it adds at the crank; the drive solves
  the acceleration with both.

A run object holds only data (paths, settings), so that it travels to Dask workers as
it is; each worker process loads each FMU once (:func:`slave`) and resets it between
runs. A run that fails returns its status (``singular``, ``cannot_assemble``,
``diverged``, ``refused``: the FMU refused a parameter value) with the FMU's message and
NaN figures, or ``undefined_figure`` with the figures that have a value; it never raises.
Every sample counts: one whose mechanism FMU ``status`` is not 0 fails the run with that
status, whatever its outputs.

Where the mechanism FMU has amplification outputs (the mechanism's ``amplification``,
else each dyad's ``DYAD.amplification``), a run also reads them at every sample: the
worst eps x amplification over the run bounds the relative round-off of its reactions
(README: "Status, conditioning, singular positions"), given as the digits it leaves,
-log10(eps x amplification). A run with fewer than the study's ``min_digits`` is
``inaccurate``: its figures are kept, it is not ok.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from fmpy.model_description import ModelDescription

from ..fmi.slave import Slave, SlaveError
from . import stroke
from .checks import Driver, base_values, driver_of, drivers_of
from .figures import UndefinedFigure, figure_value, series_names
from .rows import RowsEntry, columns_entry, rows_entry
from .studyfile import (
    MIN_DIGITS,
    Driven,
    Kinetostatic,
    MultiStroke,
    Stroke,
    Study,
    recorded_from,
)

__all__ = [
    "Outcome",
    "KinetostaticRun",
    "StrokeRun",
    "Axis",
    "MultiStrokeRun",
    "DrivenRun",
    "run_of",
    "run_rows",
    "slave",
    "STATUS_NAMES",
    "amplification_outputs",
    "digits_of",
]

#: The mechanism FMU's ``status`` output.
STATUS_NAMES = {0: "ok", 1: "singular", 2: "invalid_input", 3: "out_of_range", 4: "cannot_assemble"}

_SLAVES: dict = {}


def slave(path: str, role: str) -> Slave:
    """This process's instance of the FMU at ``path`` (loaded on first use)."""
    key = (path, role)
    if key not in _SLAVES:
        _SLAVES[key] = Slave(path, instance_name=role, label=role)
    return _SLAVES[key]


def _fresh(path: str, role: str, parameters: dict) -> Slave:
    """The process's instance, reset and initialised with ``parameters``."""
    s = slave(path, role)
    s.reset()
    s.messages.clear()  # a failure's message is this run's, not an earlier one's
    s.initialize(parameters)
    return s


@dataclass(frozen=True)
class Outcome:
    """A run's figures (by the study's figure order), its status, the FMU's message and
    the digits its reactions keep (None where the FMU has no amplification output or the
    run failed)."""

    figures: tuple
    status: str
    message: str = ""
    digits: float | None = None


#: The unit round-off of a double, the FMUs' scalar.
EPS = float(np.finfo(float).eps)


def digits_of(amplification: float) -> float:
    """The decimal digits a result with this amplification keeps: -log10(eps x a); NaN for
    a NaN amplification (no bound), -inf for an infinite one."""
    if math.isnan(amplification) or amplification <= 0:
        return math.nan if math.isnan(amplification) else -math.log10(EPS)
    return -math.log10(EPS * amplification) if math.isfinite(amplification) else -math.inf


def amplification_outputs(md: ModelDescription) -> tuple:
    """The mechanism FMU's amplification outputs: the mechanism's ``amplification`` where
    it has one, else every dyad's ``DYAD.amplification``; () where it has none."""
    reals = [
        v.name
        for v in md.modelVariables
        if v.causality == "output" and v.type in ("Real", "Float64")
    ]
    if "amplification" in reals:
        return ("amplification",)
    return tuple(n for n in reals if n.endswith(".amplification"))


class _Failed(Exception):
    def __init__(self, status: str, message: str):
        super().__init__(message)
        self.status, self.message = status, message


def _assignments(study_parameters: tuple, values: tuple, base: dict) -> dict:
    out: dict = {}
    for p, v in zip(study_parameters, values, strict=True):
        out.update(p.assign(float(v), base))
    return out


@dataclass(frozen=True)
class _Common:
    mechanism: str  # the mechanism FMU's path
    driver: str  # the driver's name in the mechanism FMU (a crank, a ram or a cylinder)
    parameters: tuple
    base: tuple  # ((name, start value), ...) the counterweights read
    fixed: tuple
    loads: tuple
    figures: tuple
    amplifications: tuple = ()  # the FMU's amplification outputs (amplification_outputs)
    min_digits: float = MIN_DIGITS
    motion: tuple = ()  # the driver's motion inputs (Driver.motion); a crank's by default
    effort: str = ""  # the driver's torque or force output; a crank's torque by default

    def motion_inputs(self) -> tuple:
        """The driver's coordinate, rate and acceleration inputs (those the FMU has)."""
        return self.motion or tuple(f"{self.driver}.{q}" for q in ("angle", "omega", "epsilon"))

    def checked(self) -> tuple:
        """Outputs a sample reads beyond the figures' series, to solve it and check it:
        the amplifications and the driver's torque or force (an output: reading it
        solves the sample, so that its status is that of the whole mechanism even where
        the figures read inputs only)."""
        return (*self.amplifications, self.effort or f"{self.driver}.torque")

    def read(self) -> tuple:
        """The mechanism FMU's variables a sample reads: the figures' series, then the
        checked outputs."""
        series = series_names(self.figures)
        return series + tuple(n for n in dict.fromkeys(self.checked()) if n not in series)

    def mechanism_parameters(self, values: tuple) -> dict:
        """The mechanism FMU's parameters of a design (drive.* left out)."""
        assigned = dict(self.fixed)
        assigned.update(_assignments(self.parameters, values, dict(self.base)))
        return {n: v for n, v in assigned.items() if not n.startswith("drive.")}

    def inputs(self) -> tuple:
        """The mechanism FMU's inputs a point sets: the driver's motion, then the loads."""
        return self.motion_inputs() + tuple(load.name for load in self.loads)

    def guarded(self, run: Callable[[], Outcome]) -> Outcome:
        """run(), or the Outcome of its failure (NaN figures and the status)."""
        nothing = (math.nan,) * len(self.figures)
        try:
            return run()
        except _Failed as e:
            return Outcome(nothing, e.status, e.message)
        except SlaveError as e:
            return Outcome(nothing, "refused" if e.status >= 3 else "discarded", str(e))
        except ArithmeticError as e:  # a design's parameters out of a float's range
            return Outcome(nothing, "refused", f"the design's parameters: {e}")

    def chunk(self, rows: list) -> list:
        """[(index, Outcome)] of the designs [(index, values)], one run after another."""
        return [(index, self(tuple(values))) for index, values in rows]

    def accuracy(self, series: dict) -> tuple[float | None, str]:
        """(digits, message) of the worst sample of a run's series: the message says why
        the run is inaccurate, "" where it keeps ``min_digits`` (or the FMU has no
        amplification output: digits None)."""
        if not self.amplifications:
            return None, ""
        worst = np.max([np.max(series[n]) for n in self.amplifications])
        digits = digits_of(float(worst))
        if digits >= self.min_digits:  # not for NaN: a sample without a bound is no pass
            return digits, ""
        which = max(self.amplifications, key=lambda n: float(np.max(series[n])))
        k = int(np.argmax(series[which]))
        return digits, (
            f"{which} {worst:.3g} at sample {k}: eps x amplification = {EPS * worst:.2g}, "
            f"{digits:.1f} digits, fewer than min_digits {self.min_digits:g}"
        )

    def outcome(self, series: dict, phi: np.ndarray | None) -> Outcome:
        """The figures over the recorded series, and the digits they keep."""
        values, undefined = [], []
        for f in self.figures:
            try:
                values.append(figure_value(f, series, phi))
            except UndefinedFigure as e:
                values.append(math.nan)
                undefined.append(f"{f.name}: {e}")
        digits, inaccurate = self.accuracy(series)
        if inaccurate:
            return Outcome(tuple(values), "inaccurate", inaccurate, digits)
        if undefined:
            return Outcome(tuple(values), "undefined_figure", "; ".join(undefined), digits)
        if not all(map(math.isfinite, values)):
            return Outcome(tuple(values), "diverged", "a figure is not finite", digits)
        return Outcome(tuple(values), "ok", "", digits)


def _failed_point(mech: Slave, where: str) -> _Failed:
    code = mech.get_status() if "status" in mech.names else 0
    message = f"{mech.messages[-1]} ({where})" if mech.messages else f"outputs not finite {where}"
    return _Failed(STATUS_NAMES.get(code, f"status {code}") if code else "diverged", message)


def _check_point(mech: Slave, values: list, where: str) -> None:
    """_Failed where a sample's values are not finite or the FMU's status is not 0 (a
    sample it reports singular counts as failed even where its outputs are numbers)."""
    if not np.all(np.isfinite(values)):
        raise _failed_point(mech, where)
    code = mech.get_status() if "status" in mech.names else 0
    if code != 0:
        said = f"{mech.messages[-1]} " if mech.messages else ""
        raise _Failed(STATUS_NAMES.get(code, f"status {code}"), f"{said}(status {code} {where})")


@dataclass(frozen=True)
class KinetostaticRun(_Common):
    """One revolution at constant crank speed ``speed`` (rad/s), ``points`` angles."""

    speed: float = 0.0
    points: int = 360
    use_rows: bool = True  # evaluate a chunk in one call where the binary can

    def __call__(self, values: tuple) -> Outcome:
        """The figures of the design ``values``, through FMI calls."""
        return self.guarded(lambda: self._run(values))

    @functools.cached_property
    def _point_inputs(self) -> np.ndarray:
        """The inputs at every angle: the crank's motion and the loads (points x inputs)."""
        rows = []
        for k in range(self.points):
            phi = 2 * math.pi * k / self.points
            rows.append((phi, self.speed, 0.0) + tuple(ld.at(phi) for ld in self.loads))
        return np.array(rows)

    def samples(self, params: dict) -> np.ndarray:
        """The inputs of every sample of the design whose mechanism parameters are
        ``params`` (samples x inputs); _Failed where the design cannot be run."""
        return self._point_inputs

    def where(self, k: int, x: np.ndarray) -> str:
        """Sample ``k`` (inputs ``x``) as a message names it."""
        return f"at crank angle {x[0]:.6g} rad"

    def result(self, series: dict, x: np.ndarray) -> Outcome:
        """The outcome of a design's series, its samples' inputs ``x``."""
        return self.outcome(series, None)

    def chunk(self, rows: list) -> list:
        """[(index, Outcome)] of the designs [(index, values)]: every sample of every
        design in one call of the binary's rows entry; a design that fails there runs
        again through FMI, whose calls name the failure."""
        entry = rows_entry(self.mechanism) if self.use_rows else None
        if entry is None:
            return super().chunk(rows)
        try:
            params = [self.mechanism_parameters(tuple(v)) for _, v in rows]
        except ArithmeticError:  # the FMI path gives each design its own row
            return super().chunk(rows)
        p_names = tuple(params[0]) if params else ()
        if any(tuple(p) != p_names for p in params):
            return super().chunk(rows)
        out, runnable = {}, []
        for j, (index, _) in enumerate(rows):
            try:
                runnable.append((j, self.samples(params[j])))
            except _Failed as e:  # the design cannot run: its outcome says why
                out[index] = Outcome((math.nan,) * len(self.figures), e.status, e.message)
        try:
            out.update(self._evaluated(entry, rows, params, p_names, runnable))
        except RuntimeError:  # refused as a whole (an FMU whose GUID is not its binary's)
            return super().chunk(rows)
        return [(index, out[index]) for index, _ in rows]

    def _evaluated(
        self, entry: RowsEntry, rows: list, params: list, p_names: tuple, runnable: list
    ) -> dict:
        """{index: Outcome} of the runnable designs [(j, their samples' inputs)] of
        ``rows``, all their samples in one call of the rows entry."""
        if not runnable:
            return {}
        names, n = self.read(), self.points
        p = np.repeat(np.array([[params[j][k] for k in p_names] for j, _ in runnable]), n, axis=0)
        x = np.concatenate([xj for _, xj in runnable])
        y, status = _by_columns(self.mechanism, p_names, p, self.inputs(), x, names) or (
            entry.evaluate(p_names, p, self.inputs(), x, names)
        )
        out = {}
        for m, (j, xj) in enumerate(runnable):
            index, values = rows[j]
            block, ok = y[m * n : (m + 1) * n], not status[m * n : (m + 1) * n].any()
            if ok and np.all(np.isfinite(block)):
                out[index] = self.result(dict(zip(names, block.T, strict=True)), xj)
            else:
                out[index] = self(tuple(values))
        return out

    def _run(self, values: tuple) -> Outcome:
        params = self.mechanism_parameters(values)
        x = self.samples(params)
        mech = _fresh(self.mechanism, "mechanism", params)
        names, inputs = self.read(), self.inputs()
        rows = np.empty((self.points, len(names)))
        for k in range(self.points):
            mech.set(inputs, tuple(x[k]))
            rows[k] = mech.get(names)
            _check_point(mech, rows[k], self.where(k, x[k]))
        return self.result(dict(zip(names, rows.T, strict=True)), x)


def _by_columns(
    mechanism: str, p_names: tuple, p: np.ndarray, x_names: tuple, x: np.ndarray, y_names: tuple
) -> tuple[np.ndarray, np.ndarray] | None:
    """(outputs per row, status per row) of the rows of parameters ``p`` and inputs ``x``
    through the binary's columns entry, the same values as its rows entry gives; None
    where it has none or refuses the call (a model with states)."""
    entry = columns_entry(mechanism)
    if entry is None or set(p_names) & set(x_names):
        return None
    columns = {n: p[:, k] for k, n in enumerate(p_names)}
    columns.update({n: x[:, k] for k, n in enumerate(x_names)})
    done = entry.evaluate(columns, y_names, len(x))
    if done is None:
        return None
    y = np.empty((len(x), len(y_names)))
    for k, name in enumerate(y_names):
        y[:, k] = done[0][name]
    return y, done[1]


@dataclass(frozen=True)
class StrokeRun(KinetostaticRun):
    """A ram or a cylinder moved once over its stroke (``over`` "stroke": its coordinate
    from ``low`` to ``high``, m) or a cylinder's link turned (``over`` "angle": from
    ``low`` to ``high``, rad), rest to rest in ``duration`` s along the cycloidal rise of
    :mod:`dyadfmu.sweep.stroke`, at ``points`` instants. An angle run takes the cylinder's
    geometry (``geometry``: the names of O, A, B and the branch, Driver.geometry) from
    each design's parameters, refuses a design whose run passes the toggle or lies on the
    other branch before it runs, and checks at every sample that the FMU puts ``link`` at
    the run's angle."""

    over: str = "stroke"
    low: float = 0.0
    high: float = 1.0
    duration: float = 1.0
    link: str = ""
    geometry: tuple = ()

    @functools.cached_property
    def _profile(self) -> tuple:
        return stroke.cycloid(self.low, self.high, self.duration, self.points)

    def _loads(self) -> np.ndarray:
        """The loads at every instant: constant (points x loads)."""
        return _constant_loads(self.loads, self.points)

    def checked(self) -> tuple:
        """The amplifications, the driver's force and, for an angle run, the link's angle."""
        return (*super().checked(), *((f"{self.link}.angle",) if self.over == "angle" else ()))

    def cylinder(self, params: dict) -> stroke.Cylinder:
        """The cylinder's geometry of a design (its parameters, else the FMU's start values)."""
        return _cylinder(self.driver, self.link, None, self.geometry, params, dict(self.base))

    def samples(self, params: dict) -> np.ndarray:
        """The driver's motion at every instant (its coordinate and, where the FMU takes
        them, its rates), then the loads; _Failed where the link cannot be turned over
        the run on the cylinder's branch."""
        q = self._profile
        if self.over == "angle":
            q = _turned(self.cylinder(params), self.low, self.high, q)
        motion = np.column_stack(q[: len(self.motion_inputs())])
        return np.hstack([motion, self._loads()])

    def where(self, k: int, x: np.ndarray) -> str:
        """Sample ``k`` as a message names it: the driver's coordinate (and the angle)."""
        at = f"at sample {k}: {self.motion_inputs()[0]} {x[0]:.6g}"
        return at if self.over != "angle" else f"{at}, {self.link}.angle {self._profile[0][k]:.6g}"

    def result(self, series: dict, x: np.ndarray) -> Outcome:
        """The outcome; for an angle run ``wrong_angle`` where the FMU's link is not at the
        run's angle (by more than 1e-6 rad) at some sample: the message names the first."""
        if self.over == "angle":
            got = series[f"{self.link}.angle"]
            k = _off_run(got, self._profile[0])
            if k is not None:
                return Outcome(
                    (math.nan,) * len(self.figures),
                    "wrong_angle",
                    f"the FMU puts {self.link} at {got[k]:.9g} rad, not the run's "
                    f"{self._profile[0][k]:.9g} rad (sample {k})",
                )
        return self.outcome(series, None)


def _constant_loads(loads: tuple, points: int) -> np.ndarray:
    """A run over time's loads at every instant: constant (points x loads)."""
    return np.tile(np.array([ld.value[0] for ld in loads], dtype=float), (points, 1))


def _cylinder(
    name: str, link: str, carrier: str | None, geometry: tuple, params: dict, base: dict
) -> stroke.Cylinder:
    """Cylinder ``name``'s geometry of a design: the names ``geometry`` (O, A, B, the
    branch: Driver.geometry) read from its parameters, else the FMU's start values."""
    ox, oy, ax, ay, px, py, branch = (params.get(n, base.get(n)) for n in geometry)
    return stroke.Cylinder(name, link, (ox, oy), (ax, ay), (px, py), branch, carrier)


def _turned(cylinder: stroke.Cylinder, low: float, high: float, q: tuple) -> tuple:
    """(s, s', s'') of a cylinder whose link runs the angles ``q`` (angle, rate,
    acceleration) from ``low`` to ``high``; _Failed where it cannot."""
    try:
        cylinder.check(low, high)
    except stroke.Unreachable as e:
        raise _Failed(e.status, str(e)) from None
    with np.errstate(all="ignore"):
        return cylinder.lengths(*q)


def _off_run(got: np.ndarray, wanted: np.ndarray) -> int | None:
    """The first sample where an angle the FMU gives is more than 1e-6 rad from the
    run's (modulo 2 pi); None where none is."""
    off = np.abs(np.remainder(got - wanted + math.pi, 2 * math.pi) - math.pi)
    return None if np.all(off <= 1e-6) else int(np.argmax(~(off <= 1e-6)))


@dataclass(frozen=True)
class Axis:
    """One driver of a :class:`MultiStrokeRun`: ``name``, moved from ``start`` to ``end``
    over ``over`` ("angle": a crank's angle or a cylinder's link's, rad; "stroke": a
    ram's position or a cylinder's length, m), its ``motion`` inputs and ``effort``
    output (Driver.motion, Driver.effort); a cylinder turned over its link's angle has
    its ``link``, the ``carrier`` of its pins O and A ("" for the frame; the angle is
    then relative to the carrier's) and its ``geometry`` (Driver.geometry)."""

    name: str
    over: str
    start: float
    end: float
    motion: tuple
    effort: str
    link: str = ""
    carrier: str = ""
    geometry: tuple = ()

    def angles(self) -> tuple:
        """The FMU's angles a turned cylinder's link is checked by: its own and its
        carrier's (the run's angle is their difference); () for another driver."""
        if not self.geometry:
            return ()
        return (f"{self.link}.angle",) + ((f"{self.carrier}.angle",) if self.carrier else ())


@dataclass(frozen=True)
class MultiStrokeRun(KinetostaticRun):
    """Every driver of the mechanism moved at once, each over its own range (``axes``,
    :class:`Axis`), all rest to rest in ``duration`` s along the cycloidal rise of
    :mod:`dyadfmu.sweep.stroke`, at ``points`` instants. A cylinder turned over its link's
    angle takes its lengths from each design's geometry (relative to its pins' carrier),
    as :class:`StrokeRun` does for one; its design fails before any sample where the run
    passes its toggle or lies on its other branch, and ``wrong_angle`` where the FMU puts
    the link elsewhere than the run's angle."""

    duration: float = 1.0
    axes: tuple = ()

    @functools.cached_property
    def _profiles(self) -> tuple:
        """(q, q', q'') of every axis's cycloid."""
        return tuple(stroke.cycloid(a.start, a.end, self.duration, self.points) for a in self.axes)

    def motion_inputs(self) -> tuple:
        """Every driver's coordinate, rate and acceleration inputs, driver after driver."""
        return tuple(n for a in self.axes for n in a.motion)

    def checked(self) -> tuple:
        """The amplifications, every driver's effort and the turned links' angles."""
        angles = tuple(n for a in self.axes for n in a.angles())
        return (*self.amplifications, *(a.effort for a in self.axes), *angles)

    def samples(self, params: dict) -> np.ndarray:
        """Every driver's motion at every instant, then the loads; _Failed where a
        cylinder cannot turn its link over its range."""
        columns, base = [], dict(self.base)
        for a, q in zip(self.axes, self._profiles, strict=True):
            if a.geometry:
                cylinder = _cylinder(a.name, a.link, a.carrier or None, a.geometry, params, base)
                q = _turned(cylinder, min(a.start, a.end), max(a.start, a.end), q)
            columns += list(q[: len(a.motion)])
        return np.hstack([np.column_stack(columns), _constant_loads(self.loads, self.points)])

    def where(self, k: int, x: np.ndarray) -> str:
        """Sample ``k`` as a message names it: every driver's coordinate."""
        at, column = [], 0
        for a in self.axes:
            at.append(f"{a.motion[0]} {x[column]:.6g}")
            column += len(a.motion)
        return f"at sample {k}: {', '.join(at)}"

    def result(self, series: dict, x: np.ndarray) -> Outcome:
        """The outcome; ``wrong_angle`` where the FMU puts a turned link elsewhere than the
        run's angle (by more than 1e-6 rad) at some sample: the message names the first."""
        for a, q in zip(self.axes, self._profiles, strict=True):
            if not a.geometry:
                continue
            got = series[f"{a.link}.angle"]
            got = got - series[f"{a.carrier}.angle"] if a.carrier else got
            k = _off_run(got, q[0])
            if k is not None:
                return Outcome(
                    (math.nan,) * len(self.figures),
                    "wrong_angle",
                    f"the FMU puts {a.link} at {got[k]:.9g} rad"
                    f"{f' from {a.carrier}' if a.carrier else ''}, not the run's "
                    f"{q[0][k]:.9g} rad (sample {k})",
                )
        return self.outcome(series, None)


@dataclass(frozen=True)
class DrivenRun(_Common):
    """The drive and the mechanism co-simulated; see the module's docstring."""

    drive: str = ""  # the drive FMU's path
    drive_fixed: tuple = ()
    step: float = 1e-3
    duration: float = 1.0
    settle: float = 0.0
    start_speed: float = 0.0
    start_angle: float = 0.0

    def __call__(self, values: tuple) -> Outcome:
        """The figures of the design ``values``."""
        return self.guarded(lambda: self._run(values))

    def _drive_parameters(self, values: tuple) -> dict:
        p = {f"drive.{n}": v for n, v in self.drive_fixed}
        p.update(_assignments(self.parameters, values, dict(self.base)))
        p = {n[6:]: v for n, v in p.items() if n.startswith("drive.")}
        # the crank, its mass and its weight, are the mechanism FMU's
        p.update(
            {"crank.mass": 0.0, "start.angle": self.start_angle, "start.speed": self.start_speed}
        )
        return p

    def _point(self, d: Slave, y: Slave, t: float, inputs: tuple) -> float:
        phi, omega = d.get(("crank.angle", "crank.omega"))
        loads = tuple(ld.at(phi) for ld in self.loads)
        y.set(inputs, (phi, omega, 0.0) + loads)
        torque0 = y.get(f"{self.driver}.torque")
        _check_point(y, [torque0], f"at t = {t:g} s")
        try:
            (j,) = y.directional_derivative((f"{self.driver}.torque",), (inputs[2],), [1.0])
        except SlaveError as e:  # the FMU's status output says why
            raise _failed_point(y, f"at t = {t:g} s: {e}") from None
        if not math.isfinite(j):
            raise _failed_point(y, f"at t = {t:g} s")
        d.set(("load.torque", "load.inertia"), (-torque0, j))
        eps = d.get("crank.epsilon")
        if not all(map(math.isfinite, (phi, omega, eps))):
            raise _Failed("diverged", f"the crank's motion is not finite at t = {t:g} s")
        y.set((inputs[2],), (eps,))
        return phi

    def _run(self, values: tuple) -> Outcome:
        d = _fresh(self.drive, "drive", self._drive_parameters(values))
        y = _fresh(self.mechanism, "mechanism", self.mechanism_parameters(values))
        inputs, names = self.inputs(), self.read()
        own = tuple(n for n in names if not n.startswith("drive."))
        of_drive = tuple(n[6:] for n in names if n.startswith("drive."))
        n = int(round(self.duration / self.step))
        first = recorded_from(self.settle, self.step)
        phis, rows = [], []
        for k in range(n + 1):
            phi = self._point(d, y, k * self.step, inputs)
            if k >= first:
                phis.append(phi)
                recorded = y.get(own)  # at the crank's acceleration: solved again
                _check_point(y, recorded, f"at t = {k * self.step:g} s")
                rows.append(tuple(recorded) + tuple(d.get(of_drive)))
            if k < n:
                y.do_step(k * self.step, self.step)
                d.do_step(k * self.step, self.step)
        table = np.array(rows).reshape(len(rows), len(names))
        order = own + tuple(f"drive.{q}" for q in of_drive)
        series = {name: table[:, order.index(name)] for name in names}
        return self.outcome(series, np.unwrap(np.array(phis)))


def _stroke_run(common: dict, run: Stroke, driver: Driver) -> StrokeRun:
    return StrokeRun(
        **common,
        points=run.points,
        over=run.over,
        low=run.low,
        high=run.high,
        duration=run.duration,
        link=driver.link or "",
        geometry=driver.geometry if run.over == "angle" else (),
    )


def _multi_stroke_run(common: dict, run: MultiStroke, md: ModelDescription) -> MultiStrokeRun:
    by_name = {d.name: d for d in drivers_of(md)}
    axes = []
    for entry in run.drivers:
        d = by_name[entry.name]  # check_names refuses a name that is no driver first
        turned = d.kind == "cylinder" and entry.over == "angle"
        axes.append(
            Axis(
                entry.name,
                entry.over,
                entry.start,
                entry.end,
                d.motion,
                d.effort,
                link=(d.link or "") if turned else "",
                carrier=(d.carriers[0] or "") if turned else "",
                geometry=d.geometry if turned else (),
            )  # fmt: skip
        )
    return MultiStrokeRun(**common, points=run.points, duration=run.duration, axes=tuple(axes))


def run_of(
    study: Study, mechanism: str, drive: str | None, md: ModelDescription
) -> KinetostaticRun | StrokeRun | MultiStrokeRun | DrivenRun:
    """The run of a study on the mechanism FMU at path ``mechanism`` (model description
    ``md``) and, for a driven study, the drive FMU at ``drive``. ValueError where the FMU
    has no driver (check_names refuses such a study first)."""
    driver = driver_of(md)
    if driver is None:
        raise ValueError("the mechanism FMU has no crank, ram or cylinder to drive")
    common = dict(
        mechanism=mechanism,
        driver=driver.name,
        parameters=study.parameters,
        base=tuple(base_values(study, md).items()),
        fixed=study.fixed,
        loads=study.loads,
        figures=study.figures,
        amplifications=amplification_outputs(md),
        min_digits=study.min_digits,
        motion=driver.motion,
        effort=driver.effort,
    )
    if isinstance(study.run, MultiStroke):
        return _multi_stroke_run(common, study.run, md)
    if isinstance(study.run, Stroke):
        return _stroke_run(common, study.run, driver)
    if isinstance(study.run, Kinetostatic):
        return KinetostaticRun(**common, speed=study.run.speed, points=study.run.points)
    r: Driven = study.run
    return DrivenRun(
        **common,
        drive=str(drive),
        drive_fixed=r.drive,
        step=r.step,
        duration=r.duration,
        settle=r.settle,
        start_speed=r.start_speed,
        start_angle=r.start_angle,
    )


def run_rows(run: KinetostaticRun | StrokeRun | MultiStrokeRun | DrivenRun, rows: list) -> list:
    """[(design index, Outcome)] of the designs [(index, values)], in order."""
    return run.chunk(rows)
