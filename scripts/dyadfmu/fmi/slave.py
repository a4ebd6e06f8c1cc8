"""The one fmpy wrapper of dyadfmu: an FMU (FMI 2 or 3) instance loaded, set, stepped and
read by variable names through fmpy's FMU2Slave/FMU3Slave.

Used by the co-simulation master, the study's timing of fmpy and the tests. Every failing
call raises :class:`SlaveError` (an fmpy ``FMICallException`` that also names the FMU and
carries its last log message); the FMU's log messages are captured, not printed.
"""

from __future__ import annotations

import atexit
import shutil
import tempfile
import zipfile
from collections.abc import Callable, Sequence
from ctypes import CFUNCTYPE, c_char_p, c_int, c_void_p, cast
from pathlib import Path

from fmpy import calloc, free, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import (
    FMU2Slave,
    fmi2CallbackAllocateMemoryTYPE,
    fmi2CallbackFreeMemoryTYPE,
    fmi2CallbackFunctions,
    fmi2CallbackLoggerTYPE,
)
from fmpy.fmi3 import FMU3Slave, fmi3FMUState
from fmpy.model_description import ModelDescription

__all__ = ["SlaveError", "Slave", "unpacked"]

_STATUS_NAMES = {1: "warning", 2: "discard", 3: "error", 4: "fatal"}
#: Variable types read with the integer getter (FMI 2, FMI 3).
_INTEGER_TYPES = ("Integer", "Int32")


class SlaveError(FMICallException):
    """An FMU call that failed (status discard, error or fatal): ``label`` (which FMU),
    ``function``, ``status`` and the FMU's last log ``message``."""

    def __init__(self, label: str, function: str, status: int, message: str = "") -> None:
        text = f"{label}: {function} returned {_STATUS_NAMES.get(status, status)}"
        if message:
            text += f" ({message})"
        Exception.__init__(self, text)
        self.label, self.function, self.status, self.message = label, function, status, message


_UNPACKED: dict = {}
_DESCRIBED: dict = {}


def _file_version(path: Path | str) -> tuple:
    """An FMU file's identity: its path, its modification time and its size."""
    path = Path(path).resolve()
    stat = path.stat()
    return str(path), stat.st_mtime_ns, stat.st_size


def described(path: Path | str) -> ModelDescription:
    """An FMU's model description, read once per file version (a study reads it where it
    checks its names, where it loads the binary and where it runs)."""
    key = _file_version(path)
    if key not in _DESCRIBED:
        _DESCRIBED[key] = read_model_description(key[0])
    return _DESCRIBED[key]


def unpacked(path: Path | str) -> tuple:
    """(model description, directory) of an FMU, unpacked once per file version."""
    key = _file_version(path)
    if key not in _UNPACKED:
        directory = tempfile.mkdtemp(prefix="dyadfmu_fmu_")
        try:
            with zipfile.ZipFile(key[0]) as archive:
                archive.extractall(directory)
            _UNPACKED[key] = (described(key[0]), directory)
        except BaseException:  # not an FMU, say: no directory left behind
            shutil.rmtree(directory, ignore_errors=True)
            raise
    return _UNPACKED[key]


def _cleanup() -> None:  # pragma: no cover - at interpreter exit
    for _, directory in _UNPACKED.values():
        shutil.rmtree(directory, ignore_errors=True)


atexit.register(_cleanup)


class Slave:
    """One instance of a co-simulation FMU (FMI 2 or 3), addressed by variable names.

    ``md`` is its model description, ``vr`` maps names to value references, ``fmu`` is
    fmpy's instance for calls beyond load, set, step and get."""

    def __init__(
        self, path: Path | str, instance_name: str = "instance", label: str | None = None
    ) -> None:
        self.path = Path(path)
        self.label = label or self.path.stem
        self.md, directory = unpacked(self.path)
        self.version = int(self.md.fmiVersion.split(".")[0])
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        self.types = {v.name: v.type for v in self.md.modelVariables}
        self.names = frozenset(self.vr)
        self.messages: list[str] = []
        self._vrs: dict = {}
        cls = FMU2Slave if self.version == 2 else FMU3Slave
        self.fmu = cls(
            guid=self.md.guid,
            unzipDirectory=directory,
            modelIdentifier=self.md.coSimulation.modelIdentifier,
            instanceName=instance_name,
        )
        self._instantiated = False
        self._call("instantiate", self._instantiate)
        self._instantiated = True
        if self.version == 2:
            self._set, self._get = self.fmu.setReal, self.fmu.getReal
            self._get_int = self.fmu.getInteger
            self._set_item, self._get_item = self.fmu.setInteger, self.fmu.getInteger
        else:
            self._set, self._get = self.fmu.setFloat64, self.fmu.getFloat64
            self._get_int = self.fmu.getInt32
            self._set_item, self._get_item = self.fmu.setInt64, self.fmu.getInt64

    # ---- logging -----------------------------------------------------------
    def _log(self, status: int, category: object, message: object) -> None:
        text = message.decode("utf-8", "replace") if isinstance(message, bytes) else str(message)
        self.messages.append(text)
        del self.messages[:-20]

    def _instantiate(self) -> None:
        if self.version == 2:
            # The dyadfmu FMUs call the FMI 2 logger as (env, name, status, category,
            # "%s", text): a callback that takes the text as a sixth argument reads
            # the message without fmpy's logger proxy, whose single global target
            # would dangle once this slave is gone.
            def logger(
                component: object,
                instance_name: object,
                status: int,
                category: object,
                fmt: bytes,
                text: bytes | None,
            ) -> None:
                self._log(status, category, text if text is not None else fmt)

            self._logger = CFUNCTYPE(None, c_void_p, c_char_p, c_int, c_char_p, c_char_p, c_char_p)(
                logger
            )
            callbacks = fmi2CallbackFunctions()
            callbacks.logger = cast(self._logger, fmi2CallbackLoggerTYPE)
            callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
            callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
            self._callbacks = callbacks  # kept alive with the instance
            self.fmu.instantiate(callbacks=callbacks, loggingOn=False)
        else:

            def log_message(
                environment: object, status: int, category: object, message: object
            ) -> None:
                self._log(status, category, message)

            self.fmu.instantiate(loggingOn=False, logMessage=log_message)

    def _call(self, function: str, f: Callable, *args: object) -> object:
        try:
            return f(*args)
        except FMICallException as e:
            raise SlaveError(
                self.label, function, e.status, self.messages[-1] if self.messages else ""
            ) from None

    def _refs(self, names: tuple) -> list:
        refs = self._vrs.get(names)
        if refs is None:
            refs = self._vrs[names] = [self.vr[n] for n in names]
        return refs

    # ---- load, set, step, get -----------------------------------------------
    def initialize(self, parameters: dict | None = None, start_time: float = 0.0) -> None:
        """Set the parameters, then enter and leave initialisation mode at start_time."""
        if parameters:
            names = tuple(parameters)
            self.set(names, [float(parameters[n]) for n in names])
        if self.version == 2:
            self._call("setupExperiment", self.fmu.setupExperiment, None, start_time)
            self._call("enterInitializationMode", self.fmu.enterInitializationMode)
        else:
            self._call(
                "enterInitializationMode", self.fmu.enterInitializationMode, None, start_time
            )
        self._call("exitInitializationMode", self.fmu.exitInitializationMode)

    def set(self, names: tuple | str, values: Sequence[float] | float) -> None:
        """Set variables: a tuple of names and their values, or one name and a value. Reals,
        and Enumerations (``on_singular``) by their items' values."""
        if isinstance(names, str):
            names, values = (names,), (values,)
        if not any(self._is_item(n) for n in names):
            self._call("set", self._set, self._refs(names), [float(v) for v in values])
            return
        pairs = list(zip(names, values, strict=True))
        items = [(n, int(v)) for n, v in pairs if self._is_item(n)]
        reals = [(n, float(v)) for n, v in pairs if not self._is_item(n)]
        for setter, chosen in ((self._set_item, items), (self._set, reals)):
            if chosen:
                refs = self._refs(tuple(n for n, _ in chosen))
                self._call("set", setter, refs, [v for _, v in chosen])

    def _is_item(self, name: str) -> bool:
        return self.types.get(name) == "Enumeration"

    def get(self, names: tuple | str) -> list | float | int:
        """Real variables by a tuple of names (a list), or one variable by name (a number;
        an integer for integer variables such as ``status`` and Enumerations)."""
        if isinstance(names, str):
            if self.types.get(names) in _INTEGER_TYPES:
                return int(self._call("get", self._get_int, self._refs((names,)))[0])
            if self._is_item(names):
                return int(self._call("get", self._get_item, self._refs((names,)))[0])
            return self._call("get", self._get, self._refs((names,)))[0]
        return self._call("get", self._get, self._refs(names))

    def get_status(self) -> int:
        """The FMU's ``status`` output."""
        return int(self._call("get", self._get_int, self._refs(("status",)))[0])

    def do_step(self, t: float, h: float) -> None:
        """One communication step from t of length h."""
        self._call("doStep", self.fmu.doStep, t, h)

    def directional_derivative(self, unknowns: tuple, knowns: tuple, seed: Sequence) -> list:
        """d(unknowns)/d(knowns) . seed at the current state."""
        return self._call(
            "getDirectionalDerivative",
            self.fmu.getDirectionalDerivative,
            self._refs(unknowns),
            self._refs(knowns),
            [float(s) for s in seed],
        )

    def set_rates(self, names: tuple | str, rates: Sequence[float] | float) -> None:
        """The first time derivatives of Real inputs, which a plant follows over its steps
        until set again (FMI 2 only: fmi2SetRealInputDerivatives)."""
        if isinstance(names, str):
            names, rates = (names,), (rates,)
        if self.version != 2:
            raise SlaveError(self.label, "setRealInputDerivatives", 3, "FMI 3 has no such call")
        refs = self._refs(tuple(names))
        values = [float(r) for r in rates]
        self._call(
            "setRealInputDerivatives",
            self.fmu.setRealInputDerivatives,
            refs,
            [1] * len(refs),
            values,
        )

    def output_rates(self, names: tuple) -> list:
        """The first time derivatives of Real outputs at the current point
        (fmi2GetRealOutputDerivatives, fmi3GetOutputDerivatives)."""
        refs = self._refs(tuple(names))
        if self.version == 2:
            get = self.fmu.getRealOutputDerivatives
        else:
            get = self.fmu.getOutputDerivatives
        return self._call("getOutputDerivatives", get, refs, [1] * len(refs))

    def state_calls(self) -> tuple:
        """fmpy's get, set, free, serialize and deserialize of the FMU state, the same
        five for FMI 2 and 3 (FMI 3's deserialize made to return the new state)."""
        f = self.fmu
        if self.version == 2:
            return (
                f.getFMUstate,
                f.setFMUstate,
                f.freeFMUstate,
                f.serializeFMUstate,
                f.deSerializeFMUstate,
            )

        def deserialize(data: bytes) -> fmi3FMUState:
            state = fmi3FMUState()
            f.deserializeFMUState(data, state)
            return state

        return f.getFMUState, f.setFMUState, f.freeFMUState, f.serializeFMUState, deserialize

    def reset(self) -> None:
        """Back to the state after instantiation (start values, not initialised)."""
        self._call("reset", self.fmu.reset)

    def close(self) -> None:
        """Terminate (where still legal) and free the instance; closing twice is harmless."""
        if not self._instantiated:
            return
        self._instantiated = False
        try:
            self.fmu.terminate()
        except Exception:
            pass  # terminate may be illegal after an error
        self.fmu.freeInstance()
