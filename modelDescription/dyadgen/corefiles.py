"""The core's C files (src/) that a scene's generated code links: those of its dyad
types and, for a mechanism, their kinematics; with the derivative, their tangents too
(each *_tangent.c), which a program that only evaluates leaves out."""

from __future__ import annotations

from dyadgen.model import Scene


def scene_types(scene: Scene) -> list[str]:
    """The scene's dyad types in lower case, each once, sorted."""
    return sorted({d.type.lower() for d in scene.dyads})


def dyad_core_sources(dyad_type: str, derivatives: bool = True) -> list[str]:
    """The core's files of one whole dyad of `dyad_type` (lower case): its solver and,
    with the derivative, its tangent."""
    files = ["dyad_common.c", f"dyad_{dyad_type}.c"]
    if derivatives:
        files += ["dyad_tangent.c", f"dyad_{dyad_type}_tangent.c"]
    return files


def scene_core_sources(scene: Scene, derivatives: bool) -> list[str]:
    """The core's .c files the scene's code (<identifier>_scene.c and, with
    `derivatives`, <identifier>_scene_tangent.c) calls into, in link order."""
    types = scene_types(scene)
    files = ["dyad_common.c"] + [f"dyad_{t}.c" for t in types]
    cylinder = any(d.is_cylinder() for d in scene.drivers)
    if scene.internal():
        files += ["dyad_kinematics.c"] + [f"dyad_kin_{t}.c" for t in types]
    if cylinder:
        files.append("dyad_cylinder.c")
    if derivatives:
        files += ["dyad_tangent.c"] + [f"dyad_{t}_tangent.c" for t in types]
        if scene.internal():
            files += ["dyad_kinematics_tangent.c"] + [f"dyad_kin_{t}_tangent.c" for t in types]
        if cylinder:
            files.append("dyad_cylinder_tangent.c")
    return files
