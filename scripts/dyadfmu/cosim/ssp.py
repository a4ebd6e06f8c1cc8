"""An SSP 1.0 package (.ssp) of the stiff co-simulation of :mod:`dyadfmu.cosim.mechanism_drive`:
the drive FMU and one mechanism FMU with the connections and parameters of the harness's
stabilised coupling, and a master that runs such a package the harness's way.

The package
-----------
``SystemStructure.ssd`` at the root, the two FMUs under ``resources/``. The connections, in
the order a communication point evaluates them:

    drive.crank.angle        -> mechanism.crank.angle
    drive.crank.omega        -> mechanism.crank.omega
    mechanism.crank.torque0  -> drive.load.demand
    mechanism.crank.J        -> drive.load.inertia
    drive.crank.epsilon      -> mechanism.crank.epsilon

The mechanism's driving torque is torque0 + J eps. The drive gets the part at zero
acceleration as the torque the mechanism demands (load.demand, the sign of a driving
torque: no connection needs a transformation, which some importers do not apply) and the
mechanism's inertia at the crank, and solves (J_r + J) eps = T_motor - torque0: the loop
through the links' inertia closes inside the drive. torque0 and J do not depend on eps, so the last
connection only brings the mechanism's reactions to the solved acceleration.

``acceleration="zero"`` leaves that connection out: the mechanism's crank.epsilon stays at
its start value 0, so its crank.torque is the torque at zero acceleration and goes to the
drive in place of crank.torque0, and no output reaches an input it is declared to depend
on (the mechanism FMUs declare crank.torque0 dependent on crank.epsilon). The crank's
motion is the same; the mechanism's reactions are then those at zero acceleration.

The drive's parameters are the harness's (:func:`drive_parameters`: the machine of
:data:`dyadfmu.cosim.mechanism_drive.MACHINES`, the crank's mass 0 since the crank is the
mechanism FMU's); the mechanism keeps its defaults, as in the harness. A user's scene
(:func:`write_fmu`, ``--scene FILE.toml``) brings its own mechanism FMU, and the drive the
machine :mod:`dyadfmu.cosim.scene_drive` derives from that FMU, as ``dyadfmu cosim --scene``
runs it. The
DefaultExperiment spans the harness's run; the communication step, which SSP 1.0's
DefaultExperiment does not carry, is in an annotation of type :data:`COUPLING_ANNOTATION`.

The master
----------
:func:`read_package` reads a package back through fmpy's ``read_ssd`` (validated against
fmpy's copy of the SSD schema) and takes from the XML what ``read_ssd`` of fmpy 0.3 does
not: the connections' ``ssc:LinearTransformation`` (it looks for them in the ssd
namespace), the DefaultExperiment and the annotation. :func:`simulate` propagates the
connections in the order listed, applying their transformations, at each communication
point, then steps the mechanism and the drive: the scheme of
:func:`dyadfmu.cosim.mechanism_drive.run`.

API: :func:`write`, :func:`write_fmu`, :func:`read_package` (-> :class:`Package`),
:func:`validate`, :func:`simulate` (-> :class:`SspRun`), :func:`compare`,
:func:`compare_fmu`, :func:`drive_parameters`, :func:`connections`;
``python -m dyadfmu.cosim.ssp --help``.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import zipfile
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path

import numpy as np
from fmpy import read_model_description
from fmpy.ssp.ssd import read_ssd, validate_tree
from lxml import etree

from .. import paths
from ..fmi.slave import Slave
from . import master, mechanism_drive, scene_drive

__all__ = [
    "DRIVE",
    "MECHANISM",
    "MECHANISMS",
    "ACCELERATIONS",
    "COUPLING_ANNOTATION",
    "Link",
    "Package",
    "SspRun",
    "connections",
    "drive_parameters",
    "communication_step",
    "write",
    "write_fmu",
    "validate",
    "read_package",
    "simulate",
    "simulate_fmpy",
    "compare",
    "compare_fmu",
    "main",
]

NS = {
    "ssd": "http://ssp-standard.org/SSP1/SystemStructureDescription",
    "ssc": "http://ssp-standard.org/SSP1/SystemStructureCommon",
    "ssv": "http://ssp-standard.org/SSP1/SystemStructureParameterValues",
    "dyadfmu": "urn:dyadfmu:ssp:coupling",
}
#: The component names of the system.
DRIVE, MECHANISM = "drive", "mechanism"
#: The mechanism FMUs a package can hold: those of the harness's stiff co-simulation.
MECHANISMS = ("slider_crank", "four_bar")
#: ``connected``: the drive's crank.epsilon goes to the mechanism; ``zero``: it stays 0.
ACCELERATIONS = ("connected", "zero")
#: The annotation type that carries the communication step and the evaluation order.
COUPLING_ANNOTATION = "org.dyadfmu.coupling"
#: The harness's communication step [s] per mechanism (the report's coarser step).
STEPS = {"slider_crank": 1e-3, "four_bar": 1e-3}

_SSC_TYPES = {"Real": "Real", "Float64": "Real", "Integer": "Integer", "Int32": "Integer"}


@dataclass(frozen=True)
class Link:
    """A connection: (element, connector) to (element, connector), end = factor x start +
    offset."""

    start: tuple[str, str]
    end: tuple[str, str]
    factor: float = 1.0
    offset: float = 0.0


def connections(acceleration: str = "connected") -> list[Link]:
    """The system's connections in the order a communication point evaluates them."""
    if acceleration not in ACCELERATIONS:
        raise ValueError(f"acceleration must be one of {ACCELERATIONS}, got {acceleration!r}")
    connected = acceleration == "connected"
    torque = "crank.torque0" if connected else "crank.torque"
    links = [
        Link((DRIVE, "crank.angle"), (MECHANISM, "crank.angle")),
        Link((DRIVE, "crank.omega"), (MECHANISM, "crank.omega")),
        Link((MECHANISM, torque), (DRIVE, "load.demand")),
        Link((MECHANISM, "crank.J"), (DRIVE, "load.inertia")),
    ]
    if connected:
        links.append(Link((DRIVE, "crank.epsilon"), (MECHANISM, "crank.epsilon")))
    return links


def drive_parameters(name: str) -> dict[str, float]:
    """The drive FMU's parameters in the harness's stiff co-simulation of ``name``."""
    return mechanism_drive.drive_parameters(mechanism_drive.machine_of(name))


def communication_step(name: str) -> float:
    """The harness's communication step [s] for ``name``."""
    return STEPS[name]


# ---------------------------------------------------------------------------
# writing
# ---------------------------------------------------------------------------
def _q(prefix: str, tag: str) -> str:
    return f"{{{NS[prefix]}}}{tag}"


def _sub(parent: etree._Element, prefix: str, tag: str, **attrib: str) -> etree._Element:
    return etree.SubElement(parent, _q(prefix, tag), attrib)


def _unit(variable: object) -> str | None:
    declared = getattr(variable, "declaredType", None)
    return variable.unit or (declared.unit if declared is not None else None)


def _listed(v: object, inputs: set, parameters: dict) -> bool:
    """Outputs, the connected inputs and the bound parameters."""
    if v.type not in _SSC_TYPES:
        return False
    return (
        v.causality == "output"
        or (v.causality == "input" and v.name in inputs)
        or (v.causality == "parameter" and v.name in parameters)
    )


def _connectors(parent: etree._Element, md: object, inputs: set, parameters: dict) -> None:
    """The FMU's outputs, connected inputs and bound parameters, with their types and units
    (an input left out keeps its start value)."""
    connectors = _sub(parent, "ssd", "Connectors")
    for v in md.modelVariables:
        if not _listed(v, inputs, parameters):
            continue
        c = _sub(connectors, "ssd", "Connector", name=v.name, kind=v.causality)
        unit = _unit(v)
        _sub(c, "ssc", _SSC_TYPES[v.type], **({"unit": unit} if unit else {}))


def _parameter_set(name: str, values: dict, units: dict) -> etree._Element:
    pset = etree.Element(_q("ssv", "ParameterSet"), version="1.0", name=name, nsmap=NS)
    parameters = _sub(pset, "ssv", "Parameters")
    for key, value in values.items():
        p = _sub(parameters, "ssv", "Parameter", name=key)
        unit = units.get(key)
        _sub(p, "ssv", "Real", value=repr(float(value)), **({"unit": unit} if unit else {}))
    return pset


def _component(
    elements: etree._Element, name: str, source: str, md: object, parameters: dict, links: list
) -> None:
    c = _sub(elements, "ssd", "Component", name=name, source=source)
    c.set("type", "application/x-fmu-sharedlibrary")
    _connectors(c, md, {link.end[1] for link in links if link.end[0] == name}, parameters)
    if parameters:
        units = {v.name: _unit(v) for v in md.modelVariables}
        binding = _sub(_sub(c, "ssd", "ParameterBindings"), "ssd", "ParameterBinding")
        values = _sub(binding, "ssd", "ParameterValues")
        values.append(_parameter_set(f"{name} parameters", parameters, units))


def _connections(system: etree._Element, links: list[Link]) -> None:
    parent = _sub(system, "ssd", "Connections")
    for link in links:
        c = _sub(parent, "ssd", "Connection")
        c.set("startElement", link.start[0])
        c.set("startConnector", link.start[1])
        c.set("endElement", link.end[0])
        c.set("endConnector", link.end[1])
        if (link.factor, link.offset) != (1.0, 0.0):
            _sub(c, "ssc", "LinearTransformation", factor=repr(link.factor))
            if link.offset:
                c[-1].set("offset", repr(link.offset))


def _units(root: etree._Element, mds: list) -> None:
    units, seen = _sub(root, "ssd", "Units"), set()
    for md in mds:
        for u in md.unitDefinitions:
            if u.name in seen:
                continue
            seen.add(u.name)
            b = u.baseUnit
            exps = {k: str(getattr(b, k)) for k in ("kg", "m", "s", "A", "K", "mol", "cd", "rad")}
            base = {k: e for k, e in exps.items() if e != "0"}
            if (b.factor, b.offset) != (1.0, 0.0):
                base.update(factor=repr(b.factor), offset=repr(b.offset))
            _sub(_sub(units, "ssc", "Unit", name=u.name), "ssc", "BaseUnit", **base)


def _coupling(root: etree._Element, step: float, acceleration: str) -> None:
    annotation = _sub(_sub(root, "ssd", "Annotations"), "ssc", "Annotation")
    annotation.set("type", COUPLING_ANNOTATION)
    _sub(
        annotation,
        "dyadfmu",
        "Coupling",
        communicationStep=repr(float(step)),
        order="connections as listed, then doStep of the mechanism and the drive",
        acceleration=acceleration,
    )


def _ssd(
    m: mechanism_drive.Machine, step: float, sources: dict, mds: dict, acceleration: str
) -> etree._Element:
    """The SystemStructure.ssd of the drive and the mechanism FMU ``m.name`` turned by the
    machine ``m`` with communication step ``step`` [s]."""
    name = m.name
    root = etree.Element(
        _q("ssd", "SystemStructureDescription"), version="1.0", name=f"drive_{name}", nsmap=NS
    )
    system = _sub(root, "ssd", "System", name=f"{name}_machine")
    system.set("description", f"the drive FMU turning the crank of the {name} mechanism FMU")
    elements = _sub(system, "ssd", "Elements")
    links = connections(acceleration)
    parameters = mechanism_drive.drive_parameters(m)
    _component(elements, DRIVE, sources[DRIVE], mds[DRIVE], parameters, links)
    _component(elements, MECHANISM, sources[MECHANISM], mds[MECHANISM], {}, links)
    _connections(system, links)
    _units(root, list(mds.values()))
    _sub(root, "ssd", "DefaultExperiment", startTime="0.0", stopTime=repr(float(m.t_end)))
    _coupling(root, step, acceleration)
    return root


def _check_names(mds: dict, links: list[Link]) -> None:
    for link in links:
        for element, connector in (link.start, link.end):
            if connector not in {v.name for v in mds[element].modelVariables}:
                raise ValueError(f"{element} FMU has no variable {connector!r}")


def write(
    name: str,
    fmi_version: int = 2,
    out: Path | str = paths.ROOT / "out" / "ssp",
    acceleration: str = "connected",
    build: Path | None = None,
) -> Path:
    """Write <out>/drive_<name>_fmi<v>.ssp: the built drive and ``name`` FMUs of this FMI
    version, their connections and the harness's parameters; returns its path."""
    if name not in MECHANISMS:
        raise ValueError(f"no stiff co-simulation of {name!r}; expected one of {MECHANISMS}")
    fmu = paths.built_fmu(name, fmi_version, build, what=f"the {name} FMU")
    m = mechanism_drive.machine_of(name)
    return write_fmu(fmu, m, communication_step(name), fmi_version, out, acceleration, build)


def write_fmu(
    fmu: Path,
    m: mechanism_drive.Machine,
    step: float,
    fmi_version: int = 2,
    out: Path | str = paths.ROOT / "out" / "ssp",
    acceleration: str = "connected",
    build: Path | None = None,
) -> Path:
    """Write <out>/drive_<m.name>_fmi<v>.ssp: the mechanism FMU ``fmu`` (a scene's, of this
    FMI version) and the built drive FMU, their connections, the drive's parameters of the
    machine ``m`` and the communication step ``step`` [s]; returns its path."""
    fmus = {DRIVE: master.drive_fmu_path(fmi_version, build), MECHANISM: Path(fmu)}
    mds = {k: read_model_description(str(p)) for k, p in fmus.items()}
    _check_names(mds, connections(acceleration))
    sources = {k: f"resources/{p.name}" for k, p in fmus.items()}
    ssd = etree.tostring(
        _ssd(m, step, sources, mds, acceleration),
        xml_declaration=True,
        encoding="UTF-8",
        pretty_print=True,
    )
    target = Path(out) / f"drive_{m.name}_fmi{fmi_version}.ssp"
    target.parent.mkdir(parents=True, exist_ok=True)
    with zipfile.ZipFile(target, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("SystemStructure.ssd", ssd)
        for key, path in fmus.items():
            z.write(path, sources[key])
    return target


# ---------------------------------------------------------------------------
# reading back
# ---------------------------------------------------------------------------
@dataclass
class Package:
    """A package read back: components (name -> FMU source), connections in order,
    parameters (component -> name -> value), start and stop time, communication step."""

    name: str
    sources: dict[str, str]
    links: list[Link]
    parameters: dict[str, dict[str, float]]
    start_time: float
    stop_time: float
    step: float
    acceleration: str


def _root(path: Path | str) -> etree._Element:
    with zipfile.ZipFile(path) as z, z.open("SystemStructure.ssd") as f:
        return etree.parse(f).getroot()


def validate(path: Path | str) -> None:
    """Validate the .ssd against fmpy's SSD schema and each inline parameter set against its
    SSV schema (the SSD schema 1.0 admits them unchecked); raises on the first violation."""
    root = _root(path)
    validate_tree(root, "SystemStructureDescription.xsd")
    for pset in root.iterfind(".//ssd:ParameterValues/ssv:ParameterSet", NS):
        validate_tree(etree.fromstring(etree.tostring(pset)), "SystemStructureParameterValues.xsd")


def _transformations(root: etree._Element) -> list[tuple[float, float]]:
    """(factor, offset) of each connection, in document order."""
    out = []
    for c in root.iterfind("ssd:System/ssd:Connections/ssd:Connection", NS):
        t = c.find("ssc:LinearTransformation", NS)
        if t is None:
            out.append((1.0, 0.0))
        else:
            out.append((float(t.get("factor", "1.0")), float(t.get("offset", "0.0"))))
    return out


def _parameters(component: object) -> dict[str, float]:
    values = {}
    for binding in component.parameterBindings:
        prefix = binding.prefix or ""
        for pset in binding.parameterValues:
            for p in pset.parameters:
                values[prefix + p.name] = float(p.value)
    return values


def read_package(path: Path | str) -> Package:
    """The package at ``path`` read back (and validated) through fmpy's ``read_ssd``, with
    the transformations, DefaultExperiment and coupling annotation from the XML."""
    validate(path)
    ssd = read_ssd(str(path), validate=True)
    root = _root(path)
    components = [e for e in ssd.system.elements if getattr(e, "source", None)]
    links = [
        Link((c.startElement, c.startConnector), (c.endElement, c.endConnector), f, o)
        for c, (f, o) in zip(ssd.system.connections, _transformations(root), strict=True)
    ]
    experiment = root.find("ssd:DefaultExperiment", NS)
    if experiment is None:
        raise ValueError(f"{path}: no DefaultExperiment")
    settings = root.find(
        f"ssd:Annotations/ssc:Annotation[@type='{COUPLING_ANNOTATION}']/dyadfmu:Coupling", NS
    )
    if settings is None:
        settings = etree.Element("none", communicationStep="nan", acceleration="")
    return Package(
        ssd.name,
        {c.name: c.source for c in components},
        links,
        {c.name: _parameters(c) for c in components},
        float(experiment.get("startTime", "0.0")),
        float(experiment.get("stopTime")),
        float(settings.get("communicationStep")),
        settings.get("acceleration"),
    )


# ---------------------------------------------------------------------------
# the master
# ---------------------------------------------------------------------------
@dataclass
class SspRun:
    """A package's run at its communication points: t and every output of each component
    after the connections were evaluated there (``outputs[component][name]``, arrays)."""

    package: Package
    t: np.ndarray
    outputs: dict[str, dict[str, np.ndarray]] = field(default_factory=dict)

    def __getitem__(self, path: str) -> np.ndarray:
        """``run["drive.crank.omega"]``: one output over the run."""
        element, _, name = path.partition(".")
        return self.outputs[element][name]


def _slaves(package: Package, directory: Path, path: Path | str) -> dict[str, Slave]:
    with zipfile.ZipFile(path) as z:
        z.extractall(directory)
    slaves = {}
    try:
        for name, source in package.sources.items():
            slaves[name] = Slave(directory / source, instance_name=name)
            slaves[name].initialize(package.parameters.get(name), package.start_time)
    except Exception:
        for s in slaves.values():
            s.close()
        raise
    return slaves


def _real_outputs(s: Slave) -> tuple[str, ...]:
    return tuple(
        v.name
        for v in s.md.modelVariables
        if v.causality == "output" and _SSC_TYPES.get(v.type) == "Real"
    )


def _propagate(slaves: dict[str, Slave], links: list[Link]) -> None:
    for link in links:
        value = slaves[link.start[0]].get(link.start[1])
        slaves[link.end[0]].set(link.end[1], link.factor * value + link.offset)


def _run(package: Package, slaves: dict[str, Slave], n: int) -> list:
    names = {k: _real_outputs(s) for k, s in slaves.items()}
    order = [k for k in (MECHANISM, DRIVE) if k in slaves]
    rows = []
    for k in range(n + 1):
        t = package.start_time + k * package.step
        _propagate(slaves, package.links)
        rows.append({c: slaves[c].get(names[c]) for c in slaves})
        if k < n:
            for c in order:
                slaves[c].do_step(t, package.step)
    return rows


def simulate(path: Path | str, step: float | None = None) -> SspRun:
    """Run the package at ``path`` from its start to its stop time with its communication
    step (or ``step``): the connections in order, then doStep of each FMU."""
    package = read_package(path)
    if step is not None:
        package.step = float(step)
    if not package.step > 0.0:
        raise ValueError(f"{path}: no communication step in the package; pass step")
    span = package.stop_time - package.start_time
    n = int(round(span / package.step))
    if n < 1 or abs(n * package.step - span) > 1e-9 * span:
        raise ValueError(f"{span} s is not a whole number of steps of {package.step!r} s")
    with tempfile.TemporaryDirectory(prefix="dyadfmu_ssp_") as directory:
        slaves = _slaves(package, Path(directory), path)
        try:
            rows = _run(package, slaves, n)
        finally:
            for s in slaves.values():
                s.close()
        names = {k: _real_outputs(s) for k, s in slaves.items()}
    outputs = {c: dict(zip(names[c], np.array([r[c] for r in rows]).T, strict=True)) for c in names}
    t = package.start_time + package.step * np.arange(n + 1)
    return SspRun(package, t, outputs)


def simulate_fmpy(path: Path | str) -> np.ndarray:
    """Run an FMI 2 package with fmpy's ``simulate_ssp`` over its DefaultExperiment and
    communication step, its parameter bindings passed as fmpy's parameter set (which
    ``simulate_ssp`` does not read from the .ssd). fmpy steps every FMU with the inputs of
    the previous communication point and copies outputs to inputs without their
    transformations (this package has none); row k holds the outputs after the step from
    t_k."""
    from fmpy.ssp.simulation import simulate_ssp
    from fmpy.ssp.ssd import Parameter, ParameterSet

    package = read_package(path)
    bound = ParameterSet(name="bindings")
    for component, values in package.parameters.items():
        for key, value in values.items():
            bound.parameters.append(
                Parameter(name=f"{component}.{key}", type="Real", value=repr(value))
            )
    return simulate_ssp(
        str(path),
        start_time=package.start_time,
        stop_time=package.stop_time - 0.5 * package.step,
        step_size=package.step,
        parameter_set=bound,
    )


# ---------------------------------------------------------------------------
# against the harness
# ---------------------------------------------------------------------------
def _reaction_names(md: object) -> list[str]:
    """The mechanism FMU's force and moment outputs (unit N or N.m)."""
    return [
        v.name for v in md.modelVariables if v.causality == "output" and _unit(v) in ("N", "N.m")
    ]


def _harness_reactions(fmu: Path, run: object, names: list) -> np.ndarray:
    """The mechanism FMU's reactions at the harness's states (it has no state of its own, so
    these are the outputs the harness's instance held at each communication point)."""
    y = Slave(fmu, "harness_mechanism")
    y.initialize()
    try:
        out = []
        for state in zip(run.phi, run.omega, run.epsilon, strict=True):
            y.set(("crank.angle", "crank.omega", "crank.epsilon"), state)
            out.append(y.get(tuple(names)))
    finally:
        y.close()
    return np.array(out)


def _relative(a: np.ndarray, b: np.ndarray) -> float:
    scale = np.max(np.abs(b), axis=0)
    return float(np.max(np.abs(a - b) / np.where(scale > 0, scale, 1.0)))


def compare(path: Path | str, fmi_version: int, name: str) -> dict[str, float]:
    """The package's run against :func:`dyadfmu.cosim.mechanism_drive.run` of ``name`` at
    the same step: largest |phi| difference [rad], largest omega, epsilon and torque
    difference over their peaks, and the largest reaction difference over each reaction's
    peak (all at the harness's solved acceleration)."""
    fmu = paths.built_fmu(name, fmi_version)
    return compare_fmu(path, fmi_version, fmu, mechanism_drive.machine_of(name))


def compare_fmu(
    path: Path | str, fmi_version: int, fmu: Path, m: mechanism_drive.Machine
) -> dict[str, float]:
    """The package's run against :func:`dyadfmu.cosim.mechanism_drive.run_fmu` of the
    mechanism FMU ``fmu`` and the machine ``m`` at the same step (the differences of
    :func:`compare`)."""
    ours = simulate(path)
    theirs = mechanism_drive.run_fmu(fmu, m, ours.package.step, fmi_version)
    if len(theirs.t) != len(ours.t):
        raise ValueError("the package and the harness ran different communication points")
    names = _reaction_names(read_model_description(str(fmu)))
    reactions = np.array([ours[f"{MECHANISM}.{r}"] for r in names]).T
    return {
        "phi": float(np.max(np.abs(ours["drive.crank.angle"] - theirs.phi))),
        "omega": _relative(ours["drive.crank.omega"], theirs.omega),
        "epsilon": _relative(ours["drive.crank.epsilon"], theirs.epsilon),
        "torque": _relative(ours[f"{MECHANISM}.crank.torque"], theirs.torque),
        "reactions": _relative(reactions, _harness_reactions(fmu, theirs, names)),
        "points": len(ours.t),
    }


# ---------------------------------------------------------------------------
# the command line
# ---------------------------------------------------------------------------
PROG = "python -m dyadfmu.cosim.ssp"


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog=PROG,
        description="Write an SSP 1.0 package of the drive FMU and a mechanism FMU with the "
        "connections and parameters of the harness's stiff co-simulation, validate it "
        "against the SSD schema, and (with --compare) run it against the harness.",
    )
    which = p.add_mutually_exclusive_group()
    which.add_argument(
        "--mechanism",
        choices=MECHANISMS,
        default="slider_crank",
        help="the mechanism FMU (default slider_crank)",
    )
    which.add_argument(
        "--scene",
        type=Path,
        metavar="FILE.toml",
        help="instead: the mechanism FMU of your own scene (one crank, no other driver; "
        "built where it is stale), the drive's machine derived from it as 'dyadfmu cosim "
        "--scene' does (rotor inertia the mean of its crank.J over a revolution)",
    )
    p.add_argument(
        "--fmi",
        type=int,
        choices=(2, 3),
        default=2,
        help="FMI version of the FMUs in the package (default 2)",
    )
    p.add_argument(
        "--out",
        type=Path,
        default=paths.ROOT / "out" / "ssp",
        help="output folder (default out/ssp)",
    )
    p.add_argument(
        "--acceleration",
        choices=ACCELERATIONS,
        default="connected",
        help="connected: the drive's crank.epsilon goes to the mechanism, whose "
        "reactions are then at the solved acceleration; zero: it stays 0 and "
        "the mechanism's crank.torque goes to the drive (default connected)",
    )
    p.add_argument(
        "--compare",
        action="store_true",
        help="run the package and print its largest differences from the "
        "harness's stiff co-simulation",
    )
    scene_drive.add_machine_options(p)
    return p


def _scene_package(args: argparse.Namespace) -> tuple[Path, Callable[[Path], dict]]:
    """The package of --scene's FMU and machine, and its comparison with the harness."""

    def say(text: str) -> None:
        print(f"{PROG}: {text}", file=sys.stderr, flush=True)

    s = scene_drive.prepare(args.scene, args, args.fmi, args.out, say)
    path = write_fmu(s.fmu, s.machine, s.step, args.fmi, args.out, args.acceleration)
    return path, lambda package: compare_fmu(package, args.fmi, s.fmu, s.machine)


def main(argv: list[str] | None = None) -> int:
    """Write (and optionally compare) one package; prints its path."""
    command = _parser()
    args = command.parse_args(argv)
    problem = scene_drive.options_problem(args)
    if problem:
        command.error(problem)
    if args.scene is None:
        path = write(args.mechanism, args.fmi, args.out, args.acceleration)
        differences = partial(compare, fmi_version=args.fmi, name=args.mechanism)
    else:
        try:
            path, differences = _scene_package(args)
        except scene_drive.SceneRefused as refused:
            print(f"{PROG}: error: {refused}", file=sys.stderr)
            return 1
    validate(path)
    print(path)
    if args.compare:
        for key, value in differences(path).items():
            print(f"{key}: {value:.3g}" if isinstance(value, float) else f"{key}: {value}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
