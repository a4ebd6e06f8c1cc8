"""Read and check a scene, then derive what it needs: the stages of scenefile joined.

The sections are parsed in file order of dependence (the scene, its effects, the crank,
the links, the dyads, the loads, the tunable parameters); every problem is recorded,
and the inputs and outputs are derived only from a scene without problems. Which
inputs the scene keeps is known only once it is known what its code computes: the
candidates the generated C never reads are dropped, and the outputs' dependencies
follow from the inputs that are left."""

from __future__ import annotations

import copy
import math
from collections.abc import Callable
from pathlib import Path

from dyadgen.emit.scene_c import inputs_read
from dyadgen.forward import required_outputs
from dyadgen.model import Crank, Param, Scene
from dyadgen.needs import derive_inputs, derive_outputs
from dyadgen.scenefile import experiment, mechanism, sections
from dyadgen.scenefile import loads as point_loads
from dyadgen.scenefile.locator import Locator
from dyadgen.scenefile.names import CNames, c_name_clashes, identifier_problem
from dyadgen.scenefile.problems import Problems, SceneError


def _named_objects(identifier: str, found: mechanism.Mechanism, drivers: list[Crank]) -> list:
    """(kind, name, label, where) of every name of the scene, in file order."""
    objects = []
    if not identifier_problem(identifier):
        objects.append(
            (
                "identifier",
                identifier,
                f"[scene]: identifier '{identifier}'",
                ("scene", 0, "identifier"),
            )
        )
    for crank in drivers:
        i = crank.index
        if crank.is_cylinder():
            label = f"cylinder '{crank.actuator}'"
            objects.append(("crank", crank.actuator, label, ("cylinder", i, "name")))
            link_label = f"link '{crank.name}'"
            objects.append(("crank", crank.name, link_label, ("cylinder", i, "link")))
        else:
            where = (crank.kind, i, "name")
            objects.append(("crank", crank.name, f"{crank.kind} '{crank.name}'", where))
    objects += [
        ("dyad", d.name, f"dyad '{d.name}'", ("dyad", d.index, "name"))
        for d in found.dyads
        if d.name
    ]
    objects += [
        ("link", g, f"link '{g}'", ("link", i, "name")) for g, (row, i) in found.tables.items()
    ]
    return objects


def prune_inputs(scene: Scene) -> None:
    """Drop the candidate inputs the generated code never reads: a link's angular velocity
    where nothing of it lies off its pair D (its centripetal terms vanish), and the like."""
    used = inputs_read(scene)
    scene.inputs = [i for i in scene.inputs if i.member in used]


def _derive(p: Problems, scene: Scene, scene_t: dict, data: dict) -> None:
    derive_inputs(scene)
    candidates = {i.name for i in scene.inputs}
    wanted = sections.outputs(p, scene_t)
    if wanted is None:
        return
    if scene.forward() and "all" not in wanted:
        # the equation of motion reads M(q) and h
        wanted = wanted + [n for n in required_outputs(scene) if n not in wanted]
    for problem in derive_outputs(scene, wanted):
        p.add(f"[scene]: {problem}", "scene", 0, "outputs")
    if p.items:
        return
    # only now is it known what the code computes, and so which inputs it reads;
    # the outputs' dependencies follow from those inputs
    prune_inputs(scene)
    derive_outputs(scene, wanted)
    sections.starts(p, scene, data.get("start", {}), candidates)


def read_scene(path: Path, c_names: Callable[[], CNames] | None = None) -> Scene:
    """Read and validate a scene; raises SceneError listing every problem.
    `c_names`: the C names of generated code, to refuse names whose C names clash
    (None only for the C names probe, from which the clashes are learnt)."""
    path = Path(path)
    text, data = sections.read_text(path)
    p = Problems(path, Locator(text))
    scene_t, identifier, description = sections.scene_section(p, data)
    effects = sections.effects(p, data)
    inertia, gravity = effects["inertia"], effects["gravity"]
    needs_mass = inertia or gravity
    gravity_params = sections.gravity(p, data, gravity)
    threshold = sections.threshold(p, scene_t)
    kinematics = sections.kinematics(p, scene_t, any(d in data for d in sections.DRIVERS))
    internal = kinematics == "internal"
    dynamics = sections.dynamics(p, scene_t, internal, inertia)
    drivers = sections.drivers(p, data, inertia, needs_mass, internal)
    refused: dict[str, int] = {}
    tables = mechanism.link_tables(p, data, drivers, refused)
    found = mechanism.Mechanism(p, drivers, tables, internal, refused)
    found.parse(data)
    found.link_numbers(inertia, needs_mass)
    if c_names is not None:
        objects = _named_objects(identifier, found, drivers)
        c_name_clashes(p, objects, c_names())
    sections.loads(p, data, found.links, found.known())
    names = {o[1] for o in _named_objects(identifier, found, drivers)}
    placed = point_loads.point_loads(p, data, drivers, found.links, names | found.known())
    scene = Scene(
        path=path,
        identifier=identifier,
        description=description,
        inertia=inertia,
        gravity=gravity,
        crank=drivers[0] if len(drivers) == 1 else None,
        drivers=drivers,
        dyads=found.dyads,
        links=found.links,
        gravity_params=gravity_params,
        threshold=threshold,
        kinematics=kinematics,
        dynamics=dynamics,
        point_loads=placed,
    )
    scene.motors = sections.motors(p, data, drivers, scene.forward())
    scene.experiment = experiment.experiment(p, data, scene)
    sections.tunable(p, scene_t, scene, found.tables_of_names(data.get("dyad", [])))
    if not p.items:
        _derive(p, scene, scene_t, data)
    if p.items:
        raise SceneError(p.items)
    return scene


def _cylinder_as_crank(scene: Scene, driver: Crank) -> None:
    """A cylinder's link as a crank whose motion is an input (the kinematics outside
    would give it), its dyads on the pin B where they sit on it without a point."""
    pin = (driver.params["pin.x"], driver.params["pin.y"])
    for d in scene.dyads:
        for att in (d.k, d.p):
            if att.kind == "crank" and att.link == driver.name and att.at is None:
                att.at = pin
    length = math.hypot(pin[0].value, pin[1].value)
    driver.params = {
        k: v for k, v in driver.params.items() if k in ("com.x", "com.y", "mass", "inertia")
    }
    driver.params["length"] = Param(f"{driver.name}.length", length, "m", "|O B|")
    driver.kind, driver.actuator = "crank", ""
    # a carried pivot moves with its carrier, whose angle, rate and acceleration are inputs
    # already: its motion follows from them as a dyad's pair on a link does, no input more
    driver.pivot_on = driver.base_on = None


def inputs_with_external_kinematics(scene: Scene) -> list[str]:
    """The inputs a mechanism scene's FMU would take if every link's motion were an input
    (kinematics = "external", every output of that kind): what the kinematics inside save
    its user from computing."""
    other = copy.deepcopy(scene)
    for driver in other.drivers:
        if driver.is_cylinder():
            _cylinder_as_crank(other, driver)
    other.kinematics, other.computed, other.loaders = "external", {}, {}
    for d in other.dyads:
        d.internal = False
    derive_inputs(other)
    derive_outputs(other, ["all"])
    prune_inputs(other)
    return [i.name for i in other.inputs]
