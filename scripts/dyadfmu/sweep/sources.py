"""The FMUs a study runs. A study that names an .fmu runs it as it is. A study that
names a scene runs that scene's mechanism FMU built with the study's parameters tunable:
the scene is copied to the study's output folder with those parameters added to its
``tunable`` list, under the identifier ``<identifier>_sweep_<hash of the copy>``, and
built by the project's CMake (:mod:`dyadfmu.sweep.scenebuild`: the checkout's
build-scene/fmus/, or the study's output folder for an installed package) unless that
FMU is there already. The drive FMU is the build's."""

from __future__ import annotations

import hashlib
import json
import math
import os
import re
import subprocess
import sys
import tempfile
import tomllib
import zipfile
from pathlib import Path

from fmpy import read_model_description
from fmpy.model_description import ModelDescription

from .. import paths
from ..fmi.slave import described
from .scenebuild import BuildError, build_folder, generator, scene_fmu, stale
from .studyfile import Counterweight, Driven, MultiStroke, Stroke, Study, StudyError, line_of

__all__ = [
    "toml_text",
    "sweep_scene",
    "mechanism_fmu",
    "drive_fmu",
    "model_description",
    "planned_model_description",
    "SourceError",
]


#: The longest identifier a scene may have (MAX_NAME of the generator, scenefile/names.py).
MAX_IDENTIFIER = 40


class SourceError(RuntimeError):
    """An FMU the study needs could not be built or found."""


def _value(v: object) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if not math.isfinite(v):
            raise ValueError(f"not a finite number: {v!r}")
        return repr(v)
    if isinstance(v, str):
        # a TOML basic string: JSON's escapes are TOML's; characters beyond the BMP stay
        # as they are (JSON would write surrogate pairs, which TOML refuses)
        return json.dumps(v, ensure_ascii=False)
    if isinstance(v, list):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{json.dumps(k)} = {_value(x)}" for k, x in v.items()) + " }"
    raise TypeError(f"cannot write {type(v).__name__} to TOML")


def _is_table_array(v: object) -> bool:
    return isinstance(v, list) and bool(v) and all(isinstance(x, dict) for x in v)


def _table(lines: list, header: str, data: dict) -> None:
    nested = {k: v for k, v in data.items() if isinstance(v, dict) or _is_table_array(v)}
    lines.extend(f"{json.dumps(k)} = {_value(v)}" for k, v in data.items() if k not in nested)
    for k, v in nested.items():
        name = f"{header}.{json.dumps(k)}" if header else json.dumps(k)
        for item in v if isinstance(v, list) else [v]:
            lines.append("")
            lines.append(f"[[{name}]]" if isinstance(v, list) else f"[{name}]")
            _table(lines, name, item)


def toml_text(data: dict) -> str:
    """TOML text of parsed TOML data (tables, arrays of tables, strings, numbers, booleans
    and arrays): every key quoted, every string escaped."""
    lines: list = []
    _table(lines, "", data)
    return "\n".join(lines).lstrip("\n") + "\n"


def _varied(study: Study) -> list:
    names = []
    for p in study.parameters:
        names += list(p.needs()) if isinstance(p, Counterweight) else [p.name]
    names += [n for n, _ in study.fixed]
    return [n for n in dict.fromkeys(names) if not n.startswith("drive.")]


def check_scene(scene: Path) -> None:
    """SourceError with the scene checker's messages (FILE:LINE each) where the scene
    file is not a valid scene."""
    done = subprocess.run(
        [sys.executable, str(generator()), str(scene), "--check"],
        capture_output=True,
        text=True,
    )
    if done.returncode != 0:
        raise SourceError(f"{scene}: not a valid scene:\n{done.stderr.strip()[-4000:]}")


def _copy_of(scene_file: Path, study: Study) -> dict:
    """The scene's data with the study's parameters added to its tunable list."""
    data = tomllib.loads(scene_file.read_text(encoding="utf-8"))
    scene = data.get("scene")
    identifier = scene.get("identifier") if isinstance(scene, dict) else None
    if not isinstance(identifier, str) or not re.fullmatch(
        r"[A-Za-z_][A-Za-z0-9_]{0,63}", identifier
    ):
        raise ValueError("[scene] identifier must be a C identifier of at most 64 characters")
    tunable = scene.get("tunable", [])
    if not isinstance(tunable, list) or not all(isinstance(n, str) for n in tunable):
        raise ValueError("[scene] tunable must be a list of parameter names")
    geometry, angle = _cylinder_names(data, study)
    wanted = _varied(study) + geometry
    scene["tunable"] = tunable + [n for n in dict.fromkeys(wanted) if n not in tunable]
    outputs = scene.get("outputs")
    if isinstance(outputs, list) and "all" not in outputs:
        # every dyad's amplification: the round-off bound a study checks at each sample
        more = _amplifications(data) + angle
        scene["outputs"] = outputs + [n for n in dict.fromkeys(more) if n not in outputs]
    toml_text(data)  # every value can be written
    return data


def _turned_cylinders(study: Study) -> list:
    """The names of the cylinders the study's run turns over their links' angles (None
    for the scene's only driver, as a [run] over an angle names none)."""
    run = study.run
    if isinstance(run, Stroke) and run.over == "angle":
        return [None]
    if isinstance(run, MultiStroke):
        return [e.name for e in run.drivers if e.over == "angle"]
    return []


def _cylinder_names(data: dict, study: Study) -> tuple[list, list]:
    """(tunable names, outputs) a run over cylinders' links' angles needs: the geometry
    the run computes each cylinder's length from (the link's pivot, the pins, the branch)
    and the angles it checks, the link's and its pins' carrier's; nothing for another run
    or a scene without such a cylinder (the run is refused against the scene's model
    description)."""
    tables = data.get("cylinder")
    tables = [tables] if isinstance(tables, dict) else tables if isinstance(tables, list) else []
    tables = [t for t in tables if isinstance(t, dict) and isinstance(t.get("link"), str)]
    by_name = {t.get("name", "cylinder"): t for t in tables}
    links = {t["link"] for t in tables}
    tunable, outputs = [], []
    for wanted in _turned_cylinders(study):
        table = tables[0] if wanted is None and len(tables) == 1 else by_name.get(wanted)
        if table is None or not isinstance(table.get("name", "cylinder"), str):
            continue
        name, link = table.get("name", "cylinder"), table["link"]
        tunable += [f"{link}.at", f"{name}.base", f"{name}.pin", f"{name}.branch"]
        outputs.append(f"{link}.angle")
        carrier = table.get("at", {}).get("link") if isinstance(table.get("at"), dict) else None
        outputs += [f"{carrier}.angle"] if carrier in links else []
    return tunable, outputs


def _amplifications(data: dict) -> list:
    """The amplification outputs of a scene's dyads (``DYAD.amplification``; a lone dyad
    without a name has ``amplification``)."""
    dyads = data.get("dyad")
    dyads = [d for d in dyads if isinstance(d, dict)] if isinstance(dyads, list) else []
    names = [d.get("name") for d in dyads]
    if len(names) == 1 and names[0] is None:
        return ["amplification"]
    return [f"{n}.amplification" for n in names if isinstance(n, str)]


def sweep_scene(study: Study, out: Path) -> Path:
    """The study's copy of its scene, with the varied parameters tunable (written only
    when it changed)."""
    try:
        data = _copy_of(study.scene, study)
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError, ValueError, TypeError) as e:
        check_scene(study.scene)  # its messages name the line
        raise SourceError(f"{study.scene}: {e}") from None
    scene = data["scene"]
    identifier = scene["identifier"]
    # named by its content: two studies of one scene never share a build they differ in
    digest = hashlib.sha256(toml_text(data).encode()).hexdigest()[:10]
    # within the 40 characters of an identifier
    scene["identifier"] = f"{identifier[: MAX_IDENTIFIER - 17]}_sweep_{digest}"
    text = "# the study's scene with its parameters tunable (dyadfmu sweep)\n" + toml_text(data)
    path = out / f"{scene['identifier']}.toml"
    if not path.is_file() or path.read_text(encoding="utf-8") != text:
        out.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding="utf-8")
    return path


def _build_scene(scene: Path, identifier: str, fmi: int, out: Path) -> Path:
    """The copy's FMU (its scene was generated already: planned_model_description)."""
    try:
        return scene_fmu(scene, identifier, fmi, out)
    except BuildError as e:
        raise SourceError(str(e)) from None


def _generator_refusal(study: Study, stderr: str) -> SourceError:
    """The error of a study copy the generator refused: the user's scene's own line where
    it is the scene's fault, the study's line where a name it sets is no parameter."""
    check_scene(study.scene)
    _refuse_unknown_name(study, stderr)
    return SourceError(f"{study.scene}: the study's copy of it was refused:\n{stderr[-2000:]}")


def planned_model_description(study: Study, out: Path) -> tuple[ModelDescription, str] | None:
    """(model description, FMU file name) of the mechanism FMU a scene study will build,
    generated from the study's copy of its scene without building it (scene.py --out, in
    well under a second), so that the study's names are checked before the build; None
    for a study of an .fmu."""
    if study.fmu is not None:
        return None
    scene = sweep_scene(study, out)
    identifier = tomllib.loads(scene.read_text(encoding="utf-8"))["scene"]["identifier"]
    built = build_folder(out) / "fmus" / f"{identifier}_fmi{study.fmi}.fmu"
    if not stale(built, scene, paths.project_dir()):  # the one it will run: no generator
        return described(built), built.name
    with tempfile.TemporaryDirectory(prefix="dyadfmu-sweep-") as generated:
        done = subprocess.run(
            [sys.executable, str(generator()), str(scene), "--out", generated],
            capture_output=True,
            text=True,
        )
        if done.returncode != 0:
            raise _generator_refusal(study, done.stderr)
        xml = Path(generated) / f"fmi{study.fmi}" / "modelDescription.xml"
        md = read_model_description(str(xml))
    return md, f"{identifier}_fmi{study.fmi}.fmu"


def mechanism_fmu(study: Study, out: Path) -> Path:
    """The mechanism FMU of the study (built from its scene where it names one)."""
    if study.fmu is not None:
        return study.fmu
    scene = sweep_scene(study, out)
    identifier = tomllib.loads(scene.read_text(encoding="utf-8"))["scene"]["identifier"]
    try:
        return _build_scene(scene, identifier, study.fmi, out)
    except SourceError as e:
        _refuse_unknown_name(study, str(e))
        raise


def _refuse_unknown_name(study: Study, message: str) -> None:
    """StudyError at the study's line where the scene copy failed because a name the study
    sets is not a parameter of the scene (the copy lists it as tunable)."""
    found = re.search(
        r"tunable '([^']+)' is no parameter of this scene \(parameters: ([^)]*)", message
    )
    if found is None:
        return
    name, known = found.groups()
    where = ("fixed", None, name)
    for k, p in enumerate(study.parameters):
        if name == p.name or (isinstance(p, Counterweight) and name in p.needs()):
            where = ("parameter", k, "counterweight" if isinstance(p, Counterweight) else "name")
    line = line_of(study.text, *where)
    raise StudyError(
        f"{study.path}:{line}: {name} is not a parameter of the scene {study.scene.name}; "
        f"its parameters: {known}"
    )


def drive_fmu(study: Study, build: Path | None) -> Path | None:
    """The drive FMU of a driven study, None for a kinetostatic one."""
    if not isinstance(study.run, Driven):
        return None
    return paths.built_fmu("drive", study.fmi, build)


def model_description(fmu: Path, trial: bool = True) -> ModelDescription:
    """The model description of an FMU a study runs, checked: a co-simulation FMU of
    FMI 2 or 3 with a binary for this platform (SourceError naming the file otherwise),
    whose binary loads (``trial``: tried in a process of its own; the project's own build
    of a study's scene needs no trial)."""
    try:
        md = described(fmu)
        with zipfile.ZipFile(fmu) as archive:
            members = set(archive.namelist())
    except Exception as e:  # a broken archive or XML: zipfile, lxml and fmpy raise their own
        raise SourceError(f"{fmu}: not an FMU that can be read ({type(e).__name__}: {e})") from None
    version = md.fmiVersion.split(".")[0] if isinstance(md.fmiVersion, str) else ""
    if version not in ("2", "3") or md.coSimulation is None:
        raise SourceError(f"{fmu}: not a co-simulation FMU of FMI 2 or 3")
    binary = f"binaries/{paths.PLATFORM[int(version)]}/{md.coSimulation.modelIdentifier}.so"
    if binary not in members:
        raise SourceError(f"{fmu}: no binary for this platform ({binary})")
    if trial:
        _check_instantiates(fmu)
    return md


#: Loads an FMU's binary, makes an instance and frees it: run in a process of its own.
_TRIAL = (
    "import sys\n"
    "from dyadfmu.fmi.slave import Slave\n"
    "Slave(sys.argv[1], instance_name='trial').close()\n"
)


def _check_instantiates(fmu: Path) -> None:
    """SourceError unless the FMU's binary loads and makes an instance, tried in a
    separate process first: a damaged binary can crash the process that loads it. That
    process unpacks the FMU in a folder of this one's, removed whatever became of it (a
    crashed process removes nothing)."""
    with tempfile.TemporaryDirectory(prefix="dyadfmu_trial_") as scratch:
        env = dict(os.environ, PYTHONPATH=str(Path(__file__).resolve().parents[2]), TMPDIR=scratch)
        try:
            done = subprocess.run(
                [sys.executable, "-c", _TRIAL, str(fmu)],
                capture_output=True,
                text=True,
                env=env,
                timeout=120,
            )
        except subprocess.TimeoutExpired:
            raise SourceError(f"{fmu}: its binary did not load within 120 s") from None
    if done.returncode != 0:
        last = (done.stderr.strip().splitlines() or [f"exit status {done.returncode}"])[-1]
        if done.returncode < 0:
            last = f"the process loading it died (signal {-done.returncode})"
        raise SourceError(f"{fmu}: its binary does not load or instantiate: {last}")
