"""[experiment]: the run a simulator makes of the FMU when told nothing else, written as
the model description's DefaultExperiment (stop time and communication step). Without
the table the scene's kind chooses: a row a degree over one revolution at 60 rpm for a
crank's mechanism, a row a millisecond for a plant, a row every 10 ms otherwise."""

from __future__ import annotations

from dyadgen.model import Experiment, Scene
from dyadgen.scenefile.problems import Problems, number, unknown_keys

KEYS = {"stop", "step"}
#: The most rows a default run may record (stop / step).
MAX_ROWS = 1_000_000
#: The longest default run (s).
MAX_STOP = 1.0e9
#: one revolution at 60 rpm, a row a degree
CRANK_RUN = Experiment(1.0, 1.0 / 360.0)
#: a plant's motion, a row a millisecond
PLANT_RUN = Experiment(1.0, 1.0e-3)
#: a ram's, a cylinder's or a generic dyad's inputs, a row every 10 ms
HELD_RUN = Experiment(1.0, 1.0e-2)


def derived(scene: Scene) -> Experiment:
    """The default run of a scene without [experiment] (see the module's text)."""
    if scene.forward():
        return PLANT_RUN
    if any(d.kind == "crank" for d in scene.drivers):
        return CRANK_RUN
    return HELD_RUN


def experiment(p: Problems, data: dict, scene: Scene) -> Experiment:
    """[experiment] stop and step (s), each optional, over the derived run."""
    base = derived(scene)
    table = data.get("experiment")
    if table is None:
        return base
    if not isinstance(table, dict):
        p.add("[experiment] must be a table with stop and step (s)", "experiment", 0)
        return base
    unknown_keys(p, table, KEYS, "[experiment]", "experiment", 0)
    stop = number(p, table, "stop", "[experiment]", "experiment", 0, positive=True, required=False)
    step = number(p, table, "step", "[experiment]", "experiment", 0, positive=True, required=False)
    stop = base.stop if stop is None else stop
    step = min(base.step, stop) if step is None else step
    return _checked(p, Experiment(stop, step), base)


def _checked(p: Problems, run: Experiment, base: Experiment) -> Experiment:
    where = ("experiment", 0)
    if run.stop > MAX_STOP:
        p.add(
            f"[experiment]: stop must be at most {MAX_STOP:g} s, not {run.stop!r}", *where, "stop"
        )
        return base
    if run.step > run.stop:
        p.add(
            f"[experiment]: step ({run.step!r} s) must not exceed stop ({run.stop!r} s)",
            *where,
            "step",
        )
        return base
    if run.stop / run.step > MAX_ROWS:
        p.add(
            f"[experiment]: stop / step is {run.stop / run.step:.4g} rows, more than "
            f"{MAX_ROWS:,}: take a longer step",
            *where,
            "step",
        )
        return base
    return run
