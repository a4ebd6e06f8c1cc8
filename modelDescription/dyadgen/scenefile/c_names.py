"""The C names of generated code, learnt from the generated code of the C names probe
(interface/c_names_probe.toml), a scene with every feature of the generated code: the
names that code and the headers it includes use, and the C names each kind of scene
name (identifier, crank, dyad, link) leads to."""

from __future__ import annotations

import re

from dyadgen import cnames
from dyadgen.emit.c_table import model_c
from dyadgen.emit.scene_c import scene_c, scene_header, scene_tangent_c
from dyadgen.kinds import SceneKind
from dyadgen.locations import C_NAMES_PROBES, HEADER_DIRS
from dyadgen.scenefile.names import CNames
from dyadgen.scenefile.read import read_scene

_PROBE_NAME = re.compile(r"zq[a-z]{2}", re.IGNORECASE)
#: the files whose names of links, dyads and the crank are locals, not block members
_CODE_FILES = ("scene.c", "scene_tangent.c")
_C_NAMES: list = []


def c_names() -> CNames:
    """The C names of generated code (computed once per process from the probe scene)."""
    if not _C_NAMES:
        _C_NAMES.append(_learn_c_names())
    return _C_NAMES[0]


def _learn_c_names() -> CNames:
    reserved = set(cnames.C_KEYWORDS) | cnames.COMMON_MACROS
    patterns: dict[str, set] = {kind: set() for kind in ("identifier", "crank", "dyad", "link")}
    for path in C_NAMES_PROBES:
        _learn_from(path, reserved, patterns)
    reserved = {n for n in reserved if not _PROBE_NAME.search(n)}
    return CNames(frozenset(reserved), {k: frozenset(v) for k, v in patterns.items()})


def _learn_from(path: object, reserved: set, patterns: dict) -> None:
    """The names and patterns of one probe's generated code, added to the sets."""
    probe = read_scene(path, c_names=None)
    table = SceneKind(probe).table_of_scene(probe)
    header = f"{probe.identifier}_scene.h"
    files = {
        "scene.c": scene_c(probe),
        "scene_tangent.c": scene_tangent_c(probe),
        "scene.h": scene_header(table),
        "model.c": model_c(table),
    }
    # a cylinder's name and its link's are the driver's, as a crank's
    kind_of = {probe.identifier: "identifier"}
    for driver in probe.drivers:
        kind_of[driver.name] = "crank"
        if driver.actuator:
            kind_of[driver.actuator] = "crank"
    kind_of.update({d.name: "dyad" for d in probe.dyads})
    kind_of.update({g: "link" for g in probe.links})
    reserved |= cnames.headers_names(
        "\n".join(files.values()), list(HEADER_DIRS), {header: files["scene.h"]}
    )
    for file, code in files.items():
        for t in cnames.identifiers(code):
            found = _PROBE_NAME.search(t.text)
            if found is None:
                # the header's own names came with headers_names (its struct members,
                # which no local can hide, do not count)
                if not t.member and file != "scene.h":
                    reserved.add(t.text)
                continue
            kind = kind_of[found.group().lower()]
            # a link's, dyad's or crank's name in the header or the variable table is a
            # member of the input or output block; in the code, after '.' or '->'
            member = t.member or (kind != "identifier" and file not in _CODE_FILES)
            patterns[kind].add(
                (
                    "member" if member else "code",
                    t.text[: found.start()],
                    t.text[found.end() :],
                    found.group().isupper(),
                )
            )
