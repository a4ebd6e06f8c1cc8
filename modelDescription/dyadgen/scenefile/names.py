"""The names of a scene: what may name the FMU (its identifier) and its crank, dyads and
links, and the C names those names lead to in the generated code, none of which may
clash with a name of C, its standard headers, the core, the FMU layer or the
generated code itself, nor with another one."""

from __future__ import annotations

import re
from dataclasses import dataclass

from dyadgen import cnames
from dyadgen.locations import relative_to_checkout
from dyadgen.scenefile.problems import Problems, shown

#: The scene's identifier (it names the FMU, its files and C types) and the names of the
#: crank, the dyads and the links (they name variables and C names); matched whole.
IDENT = re.compile(r"[A-Za-z][A-Za-z0-9_]*")
NAME = re.compile(r"[a-z][a-z0-9_]*")
#: The longest identifier or name. The generated C appends at most 16 characters to a
#: name (the member 'DYAD_guide_k_at_x') and 16 to the identifier ('DYADFMU_SCENE_..._H'),
#: which keeps every generated C name within the 63 characters that C99 guarantees to
#: be significant, and every file name (<identifier>_fmi3.fmu) far below 255 bytes.
MAX_NAME = 40
#: Names with a meaning in a scene: they cannot name a crank, dyad or link.
RESERVED = {
    "frame",
    "external",
    "gravity",
    "on_singular",
    "singular_threshold",
    "status",
    "time",
}
#: Prefixes of the core's, the FMU layer's and the FMI standard's C names: no name may
#: start with one (nor be the prefix without its underscore, 'dyad' or 'fmu').
RESERVED_PREFIXES = ("dyad_", "fmu_", "fmi2", "fmi3")
_PREFIX_RULE = (
    "no name is "
    + " or ".join(p[:-1] for p in RESERVED_PREFIXES if p.endswith("_"))
    + " or starts with "
    + ", ".join(RESERVED_PREFIXES[:-1])
    + f" or {RESERVED_PREFIXES[-1]}"
)


def name_problem(name: object) -> str | None:
    """Why `name` cannot name a crank, dyad or link (the message goes on "name ..."), or
    None. The C names it leads to are checked once every name is known (c_name_clashes)."""
    if not isinstance(name, str):
        return f"must be a string, not {shown(name)}"
    if not NAME.fullmatch(name):
        return (
            f"{shown(name)} must be a lower-case identifier: a letter a-z, then letters "
            "a-z, digits 0-9 and '_'"
        )
    if len(name) > MAX_NAME:
        return f"'{name[:20]}...' has {len(name)} characters; a name has at most {MAX_NAME}"
    if name in RESERVED:
        return f"'{name}' is a word of the scene format (reserved: {', '.join(sorted(RESERVED))})"
    if name in cnames.C_KEYWORDS:
        return f"'{name}' is a C keyword"
    for prefix in RESERVED_PREFIXES:
        if (name + "_").startswith(prefix):
            return (
                f"'{name}' starts with '{prefix}', which is reserved for the C names of "
                f"the core, the FMU layer and FMI ({_PREFIX_RULE})"
            )
    return None


#: Names Windows keeps for devices, in any case and whatever extension follows: a file
#: 'nul.dll' is the device NUL, so an FMU so named has no Windows binary. The
#: superscript forms (COM¹) are no identifiers (IDENT is ASCII), and COM0 and LPT0
#: are reserved on current versions of Windows.
WINDOWS_DEVICE_RULE = ("CON", "PRN", "AUX", "NUL", "COM0 to COM9", "LPT0 to LPT9")
WINDOWS_DEVICES = frozenset(
    ["con", "prn", "aux", "nul"] + [f"{port}{n}" for port in ("com", "lpt") for n in range(10)]
)


def identifier_problem(identifier: object) -> str | None:
    """Why `identifier` cannot name the FMU, or None."""
    if not isinstance(identifier, str):
        return f"must be a string (a C identifier that names the FMU), not {shown(identifier)}"
    if not IDENT.fullmatch(identifier):
        return (
            f"{shown(identifier)} must be a C identifier (it names the FMU): a letter, "
            "then letters, digits and '_'"
        )
    if len(identifier) > MAX_NAME:
        return (
            f"'{identifier[:20]}...' has {len(identifier)} characters; an identifier has "
            f"at most {MAX_NAME}"
        )
    if identifier in cnames.C_KEYWORDS:
        return f"'{identifier}' is a C keyword"
    if identifier.lower() in WINDOWS_DEVICES:
        return (
            f"'{identifier}' is a reserved device name on Windows (in any case: "
            f"{', '.join(WINDOWS_DEVICE_RULE)}): its library {identifier}.dll could not "
            "be created or loaded there; choose another identifier"
        )
    return None


#: Prefixes an identifier may not start with (in any case): the C names it leads to
#: (<identifier>_input, ...) would be the core's, the FMU layer's or FMI's ('dyad_check'
#: gives dyad_check_input, a function of the core), and dyadfmu_ is the project's own.
IDENTIFIER_PREFIXES = RESERVED_PREFIXES + ("dyadfmu_",)


def reserved_identifier_problem(identifier: str, builtins: dict) -> str | None:
    """Why a valid C identifier cannot name the FMU of a scene that is not built in: the
    identifier of an FMU the build always makes (`builtins`, identifier -> its file), or
    a reserved prefix; None where it can."""
    if identifier in builtins:
        where = relative_to_checkout(builtins[identifier])
        return (
            f"'{identifier}' names a built-in FMU (from {where}): a "
            f"build with both would make the targets {identifier}_fmi2 and "
            f"{identifier}_fmi3 twice; choose another identifier"
        )
    for prefix in IDENTIFIER_PREFIXES:
        if (identifier.lower() + "_").startswith(prefix.lower()):
            return (
                f"'{identifier}' starts with '{prefix}', which is reserved for the C names "
                f"of the core, the FMU layer and FMI (no identifier starts with "
                f"{', '.join(IDENTIFIER_PREFIXES)} or is one of them without its '_')"
            )
    return None


@dataclass(frozen=True)
class CNames:
    """What the generated C makes of a scene's names, learnt from the generated code of
    the probe scene: `reserved`, every identifier that code and the headers it includes
    use (C's keywords, the standard headers' names, the core's and the FMU layer's,
    the generated code's own: in, out, load, cos, ...); `patterns`, per kind of name
    (identifier, crank, dyad, link), the C names derived from a name as (scope, prefix,
    suffix, upper case): scope "code" for the names of the generated code's functions
    and files, "member" for the members of the scene's input and output blocks."""

    reserved: frozenset
    patterns: dict

    def derived(self, kind: str, name: str) -> list[tuple[str, str]]:
        """(scope, C name) of every C name derived from `name`, a name of `kind`; in each
        scope the name itself first, so that a clash of the name as it is is the one told."""
        return sorted(
            (
                (scope, prefix + (name.upper() if upper else name) + suffix)
                for scope, prefix, suffix, upper in self.patterns[kind]
            ),
            key=lambda c: (c[0], c[1] != name, c[1]),
        )


def c_name_clashes(p: Problems, objects: list, names: CNames) -> None:
    """Every clash of the C names the scene's names lead to: a name the generated code,
    the core or C already uses (a dyad 'in', 'load' or 'cos'), or one C name derived
    from two names (a dyad 'rod_f' beside the resultant force rod_f of a link 'rod').
    `objects`: (kind, name, label, (section, index, key)) in file order."""
    taken: dict[tuple[str, str], str] = {}
    for kind, name, label, where in objects:
        # an identifier itself too: 'EOF' or 'main' would name the FMU, its library and
        # files after a name of C (a dyad's name is a C name as it is: see the patterns)
        if kind == "identifier" and name in names.reserved:
            p.add(
                f"{label}: its name is already a name of C, its standard headers, the core "
                f"or the generated code ('{name}'); choose another name",
                *where,
            )
            continue
        for scope, cname in names.derived(kind, name):
            if scope == "code" and cname in names.reserved:
                what = "its name" if cname == name else f"the C name '{cname}' it leads to"
                p.add(
                    f"{label}: {what} is already a name of C, its standard headers, the "
                    f"core or the generated code ('{cname}'); choose another name",
                    *where,
                )
                break
            other = taken.setdefault((scope, cname), label)
            if other != label:
                p.add(
                    f"{label}: the generated C code would use the name '{cname}' both for "
                    f"{other} and for {label}; rename one of them",
                    *where,
                )
                break
