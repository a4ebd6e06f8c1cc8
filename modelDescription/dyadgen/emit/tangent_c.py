"""The directional derivative of a scene's generated C: forward-mode differentiation of
the generated code itself.

The statements of the scene's `evaluate` (and of its `kinematics`) are rewritten one by
one on dual numbers (dyadfmu/dual.h), a value with its rate along the seed, so that the
derivative is the code that computes the outputs, differentiated: it cannot drift from
it. A scalar or vector local becomes a dual local; a struct local (a dyad's loads, its
result, the kinematics) becomes a pair, the value and `d_` its rate; an input of the FMU
carries the seed's rate and a parameter none (it is not a known of a directional
derivative). The core's closed forms are replaced by their exact tangents
(dyad_react_tangent_<type>, dyad_kinematics_tangent_<type>), so that no step size enters
anywhere.

The code it reads is the generator's own: a statement it does not know raises
TangentError, so that a change to the generator cannot silently produce a wrong
derivative.
"""

from __future__ import annotations

import functools
import re
from dataclasses import dataclass
from pathlib import Path as FilePath
from string import Template

from dyadgen import cnames
from dyadgen.emit import kinematics_c
from dyadgen.model import Dyad, Scene

REAL, VEC, POINT, STRUCT, INT = "real", "vec", "point", "struct", "int"

#: C types of declarations, by what the differentiation makes of them
_DECLARED = {
    "double": REAL,
    "dyad_real": REAL,
    "dyad_vec2": VEC,
    "dyad_point_motion": POINT,
    "int": INT,
    "dyad_loaded": STRUCT,
    "dyad_result": STRUCT,
    "dyad_kin_input": STRUCT,
    "dyad_cylinder_input": STRUCT,
    "dyad_cylinder_result": STRUCT,
}
_DUAL_TYPE = {REAL: "dyad_dual", VEC: "dyad_dual_vec2", POINT: "dyad_dual_point_motion"}
#: struct members that are vectors, or a point's motion; every other leaf is a scalar
_VEC_FIELDS = frozenset(
    "dir position velocity acceleration r_mk r_np r_mn f i j i_k j_k i_p j_p guide "
    "turn_m turn_n com_m com_n".split()
)
_POINT_FIELDS = frozenset("point d e com".split())
_INT_FIELDS = frozenset(["branch"])
#: the members of a cylinder's input and result (dyadfmu/cylinder.h) that are vectors or
#: a point's motion, by their last one or two names: their names mean other things in
#: the dyads' structs
_CYLINDER_FIELDS = {
    "link.force": VEC,
    "link.com": VEC,
    "barrel.com": REAL,
    "rod.com": REAL,
    "a": POINT,
    "o": POINT,
    "b": POINT,
    "barrel_com": POINT,
    "rod_com": POINT,
    "link_com": POINT,
    "pin_b": VEC,
    "gravity": VEC,
    "link_dir": VEC,
    "axis": VEC,
    "r_a": VEC,
    "r_b": VEC,
    "r_o": VEC,
}
#: the dual counterpart of each function on dual arguments, with its result's type
_DUAL_FUNCTIONS = {
    "dyad_vec2_make": ("dyad_kdv_make", VEC),
    "dyad_norm1": ("dyad_kdv_norm1", REAL),
    "dyad_scale": ("dyad_kdv_scale", VEC),
    "dyad_add": ("dyad_kdv_add", VEC),
    "dyad_sub": ("dyad_kdv_sub", VEC),
    "dyad_neg": ("dyad_kdv_neg", VEC),
    "dyad_perp": ("dyad_kdv_perp", VEC),
    "dyad_cross": ("dyad_kdv_cross", REAL),
    "dyad_dot": ("dyad_kdv_dot", REAL),
    "dyad_combine": ("dyad_kdv_combine", VEC),
    "dyad_turn": ("dyad_kdv_cmul", VEC),
    "dyad_fabs": ("dyad_kd_abs", REAL),
    "dyad_atan2": ("dyad_kd_atan2", REAL),
    "dyad_point_on_link": ("dyad_point_on_link_dual", POINT),
}
#: functions of parameters only (constant along every seed), with their result's type
_CONSTANT_FUNCTIONS = {
    "DYAD_R": REAL,
    "cos": REAL,
    "sin": REAL,
    "dyad_dir_from_angle": VEC,
    "fixed_point": POINT,
    "dyad_kin_input_default": STRUCT,
    "dyad_cylinder_input_default": STRUCT,
}
#: the macros of constants the generated code names (dyadfmu/types.h)
_CONSTANT_NAMES = frozenset(["DYAD_REAL_MIN", "DYAD_DEFAULT_SINGULAR_THRESHOLD"])
_SIZE_FUNCTIONS = {
    "dyad_force_size": "dyad_force_size_rate",
    "dyad_moment_size": "dyad_moment_size_rate",
}
_BINARY = {"+": "dyad_dual_add", "-": "dyad_kd_sub", "*": "dyad_dual_mul", "/": "dyad_dual_div"}
_LIFT = {REAL: "dyad_dual_const", VEC: "dyad_kdv_const", POINT: "dual_point_const"}
_READ = {REAL: "dyad_dual_make", VEC: "dyad_kdv_in", POINT: "dual_point"}
_PUT = {REAL: "dyad_kd_put", VEC: "dyad_kdv_put"}


class TangentError(ValueError):
    """Generated code the differentiation does not know."""


# ---------------------------------------------------------------------------
# Expressions
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class Num:
    """A number literal."""

    text: str


@dataclass(frozen=True)
class Path:
    """A name with its members: `kin.engine.n.dir` is ("kin", ((".", "engine"), ...))."""

    root: str
    steps: tuple = ()

    def text(self, root: str | None = None) -> str:
        """The C text, on another root if given."""
        return (root or self.root) + "".join(sep + name for sep, name in self.steps)


@dataclass(frozen=True)
class Call:
    """A function call."""

    name: str
    args: tuple


@dataclass(frozen=True)
class Unary:
    """-x or &x."""

    op: str
    operand: object


@dataclass(frozen=True)
class Binary:
    """x op y: arithmetic or a comparison."""

    op: str
    left: object
    right: object


@dataclass(frozen=True)
class Ternary:
    """test ? yes : no."""

    test: object
    yes: object
    no: object


class _Parser:
    """Recursive descent over the tokens of one expression."""

    def __init__(self, text: str) -> None:
        self.text = text
        self.toks = [t.text for t in cnames.tokens(text) if t.kind != "comment"]
        self.at = 0

    def peek(self) -> str | None:
        return self.toks[self.at] if self.at < len(self.toks) else None

    def take(self, expected: str | None = None) -> str:
        tok = self.peek()
        if tok is None or (expected is not None and tok != expected):
            raise TangentError(f"expected {expected or 'more'} in: {self.text}")
        self.at += 1
        return tok

    def whole(self) -> object:
        node = self.expr()
        if self.peek() is not None:
            raise TangentError(f"unexpected {self.peek()!r} in: {self.text}")
        return node

    def expr(self) -> object:
        test = self.compare()
        if self.peek() != "?":
            return test
        self.take("?")
        yes = self.expr()
        self.take(":")
        return Ternary(test, yes, self.expr())

    def compare(self) -> object:
        left = self.additive()
        if self.peek() in ("<", ">", "<=", ">=", "==", "!="):
            return Binary(self.take(), left, self.additive())
        return left

    def additive(self) -> object:
        node = self.term()
        while self.peek() in ("+", "-"):
            node = Binary(self.take(), node, self.term())
        return node

    def term(self) -> object:
        node = self.unary()
        while self.peek() in ("*", "/"):
            node = Binary(self.take(), node, self.unary())
        return node

    def unary(self) -> object:
        if self.peek() in ("-", "&"):
            return Unary(self.take(), self.unary())
        return self.primary()

    def primary(self) -> object:
        tok = self.take()
        if tok == "(":
            node = self.expr()
            self.take(")")
            return node
        if re.match(r"\.?[0-9]", tok):
            return Num(tok)
        if not re.match(r"[A-Za-z_]", tok):
            raise TangentError(f"unexpected {tok!r} in: {self.text}")
        if self.peek() == "(":
            return Call(tok, self.arguments())
        steps = []
        while self.peek() in (".", "->"):
            steps.append((self.take(), self.take()))
        return Path(tok, tuple(steps))

    def arguments(self) -> tuple:
        self.take("(")
        args = []
        while self.peek() != ")":
            args.append(self.expr())
            if self.peek() == ",":
                self.take(",")
        self.take(")")
        return tuple(args)


def parse(text: str) -> object:
    """The expression tree of C text of the generator's expressions."""
    return _Parser(text).whole()


def plain(node: object) -> str:
    """The node as plain C again (for the parts of a statement that have no rate)."""
    if isinstance(node, Num):
        return node.text
    if isinstance(node, Path):
        return node.text()
    if isinstance(node, Call):
        return f"{node.name}({', '.join(plain(a) for a in node.args)})"
    if isinstance(node, Unary):
        return f"{node.op}{_grouped(node.operand)}"
    if isinstance(node, Binary):
        return f"{_grouped(node.left)} {node.op} {_grouped(node.right)}"
    return f"{_grouped(node.test)} ? {_grouped(node.yes)} : {_grouped(node.no)}"


def _grouped(node: object) -> str:
    return f"({plain(node)})" if isinstance(node, (Binary, Ternary)) else plain(node)


# ---------------------------------------------------------------------------
# Expressions on dual numbers
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class Dual:
    """An expression on dual numbers: C text and type; a constant one is plain C."""

    text: str
    type: str
    constant: bool = False

    def lifted(self) -> str:
        """The C text of its dual value (a constant with rate zero)."""
        if not self.constant:
            return self.text
        if self.type not in _LIFT:
            raise TangentError(f"no dual of the constant {self.text}")
        return f"{_LIFT[self.type]}({self.text})"


#: the kinematics block's members that hold a carried cylinder's pins A and O (points'
#: motion), by their names' ending
_MOUNT_SUFFIXES = ("_mount_a", "_mount_o")


def _field_type(steps: tuple) -> str:
    last = steps[-1][1]
    two = ".".join(name for _, name in steps[-2:])
    for key in (two, last):
        if key in _CYLINDER_FIELDS:
            return _CYLINDER_FIELDS[key]
    if last.endswith(_MOUNT_SUFFIXES):
        return POINT
    if last in _INT_FIELDS:
        return INT
    return VEC if last in _VEC_FIELDS else POINT if last in _POINT_FIELDS else REAL


class Names:
    """What the differentiation knows of the names of one function: the FMU inputs (by
    input-block member: carry the seed's rate), the dual locals and the struct locals
    (their rate `d_<name>`, a pointer's `d_<name>` too)."""

    def __init__(
        self, inputs: dict[str, str], duals: dict | None = None, structs: tuple | set = ()
    ) -> None:
        self.inputs = inputs
        self.duals: dict[str, str] = dict(duals or {})
        self.structs: set[str] = set(structs)

    def read(self, path: Path) -> Dual:
        """A name with its members as a dual expression."""
        if path.root in _CONSTANT_NAMES and not path.steps:
            return Dual(path.root, REAL, constant=True)
        if path.root == "in":
            return self._input(path)
        if path.root in self.duals:
            return self._dual_member(path)
        if path.root in self.structs and path.steps:
            kind = _field_type(path.steps)
            return Dual(f"{_READ[kind]}({path.text()}, {rate_of(path)})", kind)
        raise TangentError(f"no rate for {path.text()}")

    def _input(self, path: Path) -> Dual:
        member = path.steps[0][1]
        if len(path.steps) != 1:
            raise TangentError(f"no rate for {path.text()}")
        if member not in self.inputs:
            return Dual(path.text(), REAL, constant=True)
        kind = self.inputs[member]
        return Dual(f"{_READ[kind]}(in->{member}, seed->{member})", kind)

    def _dual_member(self, path: Path) -> Dual:
        kind = self.duals[path.root]
        if not path.steps:
            return Dual(path.root, kind)
        if kind == VEC and path.steps in (((".", "x"),), ((".", "y"),)):
            return Dual(f"dyad_kdv_{path.steps[0][1]}({path.root})", REAL)
        if kind == POINT and len(path.steps) == 1:
            name = path.steps[0][1]
            return Dual(f"dyad_kdv_in({path.root}.v.{name}, {path.root}.d.{name})", VEC)
        raise TangentError(f"no rate for {path.text()}")


def rate_of(path: Path) -> str:
    """The C text of the rate of a struct member: the same member of d_<root>."""
    return path.text("d_" + path.root)


def dual(node: object, names: Names) -> Dual:
    """The expression on dual numbers."""
    if isinstance(node, Num):
        return Dual(node.text, REAL, constant=True)
    if isinstance(node, Path):
        return names.read(node)
    if isinstance(node, Call):
        return _dual_call(node, names)
    if isinstance(node, Unary):
        return _dual_unary(node, names)
    if isinstance(node, Binary):
        return _dual_binary(node, names)
    parts = [dual(n, names) for n in (node.test, node.yes, node.no)]
    if all(p.constant for p in parts):
        return Dual(plain(node), parts[1].type, constant=True)
    raise TangentError(f"no rate for the choice {plain(node)}")


def _dual_unary(node: Unary, names: Names) -> Dual:
    if node.op == "&":
        return dual(node.operand, names)  # a point passed by address goes by value
    inner = dual(node.operand, names)
    if inner.constant:
        return Dual(plain(node), inner.type, constant=True)
    neg = {REAL: "dyad_kd_neg", VEC: "dyad_kdv_neg"}[inner.type]
    return Dual(f"{neg}({inner.text})", inner.type)


def _dual_binary(node: Binary, names: Names) -> Dual:
    left, right = dual(node.left, names), dual(node.right, names)
    if left.constant and right.constant:
        return Dual(plain(node), REAL, constant=True)
    if node.op not in _BINARY or left.type != REAL or right.type != REAL:
        raise TangentError(f"no rate for {plain(node)}")
    return Dual(f"{_BINARY[node.op]}({left.lifted()}, {right.lifted()})", REAL)


def _dual_call(node: Call, names: Names) -> Dual:
    if node.name in _SIZE_FUNCTIONS:
        (arg,) = node.args
        if not (isinstance(arg, Unary) and isinstance(arg.operand, Path)):
            raise TangentError(f"no rate for {plain(node)}")
        result = arg.operand
        rate = f"{_SIZE_FUNCTIONS[node.name]}(&{result.text()}, &{rate_of(result)})"
        return Dual(f"dyad_dual_make({plain(node)}, {rate})", REAL)
    args = [dual(a, names) for a in node.args]
    if node.name in _CONSTANT_FUNCTIONS:
        if not all(a.constant for a in args):
            raise TangentError(f"no rate for {plain(node)}: its arguments vary")
        return Dual(plain(node), _CONSTANT_FUNCTIONS[node.name], constant=True)
    if node.name not in _DUAL_FUNCTIONS:
        raise TangentError(f"no rate for the function {node.name}")
    name, kind = _DUAL_FUNCTIONS[node.name]
    if all(a.constant for a in args):
        return Dual(plain(node), kind, constant=True)
    return Dual(f"{name}({', '.join(a.lifted() for a in args)})", kind)


# ---------------------------------------------------------------------------
# Statements
# ---------------------------------------------------------------------------
_DECLARATION = re.compile(
    r"^(?P<const>const )?(?P<type>[A-Za-z_][A-Za-z0-9_]*)(?P<pointer>\*)? (?P<name>[A-Za-z_]"
    r"[A-Za-z0-9_]*)(?: = (?P<value>.*))?;$"
)
_ASSIGNMENT = re.compile(r"^(?P<target>[A-Za-z_][A-Za-z0-9_.>-]*) (?P<op>\+?=) (?P<value>.*);$")
_CORE_CALL = re.compile(
    r"^if \((?P<call>dyad_(?:react|kinematics))_(?P<type>[a-z]{3})\(&(?P<a>[^,]+), &(?P<b>[^)]+)\)"
    r" != DYAD_STATUS_OK\) \{$"
)
_CYLINDER_CALL = re.compile(
    r"^if \(dyad_cylinder\(&(?P<a>[^,]+), &(?P<b>[^)]+)\) != DYAD_STATUS_OK\) \{$"
)
_DRIVER_CALL = re.compile(
    r"^const dyad_kin_result\* bad = kinematics\(in, (?P<rates>(?:[^,&]+, )+)"
    r"&(?P<kin>[a-z_][a-z0-9_]*), &failed\);$"
)
#: statements whose values the derivative needs as they are
_VERBATIM = re.compile(
    r"^(?:[{}]|return(?: [^;]*)?;|\(void\)[A-Za-z0-9_]+;|\*failed = \d+;|if \(bad != NULL\) \{|"
    r"(?:fail|fail_kinematics|fail_cylinder)\(.*\);|out->status = \d+;|int failed = 0;)$"
)


def statements(lines: list[str]) -> list[str]:
    """The statements and braces of generated lines, one per item, comments dropped."""
    text = re.sub(r"/\*.*?\*/", "", "\n".join(lines), flags=re.S)
    out = []
    for line in text.split("\n"):
        line = line.strip()
        if line.startswith("{ ") and len(line) > 2:
            out += ["{", line[2:].strip()]
        elif line.endswith("; }"):
            out += [line[:-2].strip(), "}"]
        elif line:
            out.append(line)
    return out


class Differentiation:
    """The dual version of the statements of one function."""

    def __init__(self, ident: str, names: Names) -> None:
        self.ident = ident
        self.names = names

    def lines(self, plain_lines: list[str]) -> list[str]:
        """The dual statements, indented by their blocks."""
        out, depth = [], 0
        for statement in statements(plain_lines):
            depth -= statement.startswith("}")
            out += ["    " * depth + s for s in self.statement(statement)]
            depth += statement.endswith("{")
        return out

    def statement(self, text: str) -> list[str]:
        """The dual version of one statement (or brace)."""
        if _VERBATIM.match(text):
            return [text]
        if text == "check(out, evaluation);":
            return ["check_tangent(out, rate, evaluation);"]
        for pattern, write in (
            (_CORE_CALL, self._core_call),
            (_CYLINDER_CALL, self._cylinder_call),
            (_DRIVER_CALL, self._driver_call),
            (_DECLARATION, self._declaration),
            (_ASSIGNMENT, self._assignment),
        ):
            m = pattern.match(text)
            if m:
                return write(m)
        raise TangentError(f"no derivative for the statement: {text}")

    def _core_call(self, m: re.Match) -> list[str]:
        a, b = parse(m["a"]), parse(m["b"])
        args = f"&{plain(a)}, &{rate_of(a)}, &{plain(b)}, &{rate_of(b)}"
        return [f"if ({m['call']}_tangent_{m['type']}({args}) != DYAD_STATUS_OK) {{"]

    def _cylinder_call(self, m: re.Match) -> list[str]:
        a, b = parse(m["a"]), parse(m["b"])
        args = f"&{plain(a)}, &{rate_of(a)}, &{plain(b)}, &{rate_of(b)}"
        return [f"if (dyad_cylinder_tangent({args}) != DYAD_STATUS_OK) {{"]

    def _driver_call(self, m: re.Match) -> list[str]:
        rates = [
            dual(parse(arg), self.names).lifted()
            for arg in m["rates"].removesuffix(", ").split(", ")
        ]
        kin = m["kin"]
        return [
            f"const dyad_kin_result* bad = kinematics_tangent(in, seed, {', '.join(rates)}, "
            f"&{kin}, &d_{kin}, &failed);"
        ]

    def _declaration(self, m: re.Match) -> list[str]:
        kind = _DECLARED.get(m["type"])
        if kind is None and m["type"] == f"{self.ident}_kinematics":
            kind = STRUCT
        if kind is None or m["pointer"]:
            raise TangentError(f"no derivative for the declaration of {m['name']}")
        if kind == STRUCT:
            if m["value"] is not None:
                raise TangentError(f"no derivative for the initialised struct {m['name']}")
            self.names.structs.add(m["name"])
            return [f"{m['type']} {m['name']}, d_{m['name']};"]
        if kind == INT:
            return [f"{m['const'] or ''}int {m['name']} = {m['value']};"]
        self.names.duals[m["name"]] = kind
        if m["value"] is None:
            return [f"{_DUAL_TYPE[kind]} {m['name']};"]
        value = dual(parse(m["value"]), self.names).lifted()
        return [f"{m['const'] or ''}{_DUAL_TYPE[kind]} {m['name']} = {value};"]

    def _assignment(self, m: re.Match) -> list[str]:
        target = parse(m["target"])
        if not isinstance(target, Path):
            raise TangentError(f"no derivative for the assignment to {m['target']}")
        if target.root in self.names.structs and not target.steps:
            return self._struct_assignment(target.root, m["value"])
        value = dual(parse(m["value"]), self.names)
        if target.root == "out":
            # the output block holds doubles whatever the core's dyad_real
            member = target.steps[0][1]
            return [
                f"{{ const {_DUAL_TYPE[value.type]} o = {value.lifted()}; "
                f"out->{member} = o.v; rate->{member} = o.d; }}"
            ]
        if target.root in self.names.duals:
            return [self._dual_assignment(target, m["op"], value)]
        if target.root in self.names.structs:
            return [self._member_assignment(target, value)]
        raise TangentError(f"no derivative for the assignment to {m['target']}")

    def _struct_assignment(self, name: str, value: str) -> list[str]:
        node = parse(value)
        if not (isinstance(node, Call) and node.name in _CONSTANT_FUNCTIONS and not node.args):
            raise TangentError(f"no derivative for the assignment to {name}")
        return [f"{name} = {plain(node)};", f"memset(&d_{name}, 0, sizeof d_{name});"]

    def _dual_assignment(self, target: Path, op: str, value: Dual) -> str:
        kind = self.names.duals[target.root]
        if kind == POINT and len(target.steps) == 1:
            field = target.steps[0][1]
            return (
                f"dyad_kdv_put({value.lifted()}, &{target.root}.v.{field}, "
                f"&{target.root}.d.{field});"
            )
        if target.steps or value.type != kind:
            raise TangentError(f"no derivative for the assignment to {target.text()}")
        if op == "+=":
            add = {REAL: "dyad_dual_add", VEC: "dyad_kdv_add"}[kind]
            return f"{target.root} = {add}({target.root}, {value.lifted()});"
        return f"{target.root} = {value.lifted()};"

    def _member_assignment(self, target: Path, value: Dual) -> str:
        kind = _field_type(target.steps)
        if kind == INT and value.constant:
            return f"{target.text()} = {value.text};"  # a choice, not differentiated
        if kind != value.type:
            raise TangentError(f"no derivative for the assignment to {target.text()}")
        if kind == POINT:
            return (
                f"{{ const dyad_dual_point_motion p = {value.lifted()}; "
                f"{target.text()} = p.v; {rate_of(target)} = p.d; }}"
            )
        return f"{_PUT[kind]}({value.lifted()}, &{target.text()}, &{rate_of(target)});"


# ---------------------------------------------------------------------------
# The scene's derivative
# ---------------------------------------------------------------------------
_TEMPLATES = FilePath(__file__).resolve().parent / "templates"
_POINT_HELPERS = {
    "dual_point": """/* A point's motion with its rate. */
static dyad_dual_point_motion dual_point(dyad_point_motion value, dyad_point_motion rate)
{
    dyad_dual_point_motion p;
    p.v = value;
    p.d = rate;
    return p;
}
""",
    "dual_point_const": """/* A point's motion that the seed does not move. */
static dyad_dual_point_motion dual_point_const(dyad_point_motion value)
{
    return dual_point(value, fixed_point(dyad_vec2_make(0.0, 0.0)));
}
""",
}


@functools.cache
def _template(name: str) -> Template:
    return Template((_TEMPLATES / name).read_text(encoding="utf-8"))


def _indented(lines: list[str]) -> str:
    return "\n".join("    " + line for line in lines)


def _inputs(scene: Scene) -> dict[str, str]:
    """The input block's members that carry a rate: the FMU's inputs."""
    return {i.member: VEC if i.angle else REAL for i in scene.inputs}


def _kinematics_tangent(scene: Scene, dyads: list[Dyad], evaluate_text: str) -> str:
    rates = [kinematics_c.rate_names(scene, d) for d in scene.drivers]
    duals = {name: REAL for pair in rates for name in pair}
    names = Names(_inputs(scene), duals=duals, structs={"kin"})
    body = Differentiation(scene.identifier, names).lines(
        kinematics_c.kinematics_body(scene, dyads)
    )
    used = evaluate_text + "\n".join(body)
    wanted = [h for h in _POINT_HELPERS if f"{h}(" in used]
    if "dual_point_const" in wanted and "dual_point" not in wanted:
        wanted.insert(0, "dual_point")
    indent = " " * len("static const dyad_kin_result* kinematics_tangent(")
    arguments = [f"dyad_dual {name}" for pair in rates for name in pair]
    if len(rates) == 1:  # two to a line, as they always were
        arguments = [", ".join(arguments)]
    return _template("scene_kinematics_tangent.c.in").substitute(
        ident=scene.identifier,
        rates=f",\n{indent}".join(arguments),
        point_helpers="\n".join(_POINT_HELPERS[h] for h in wanted),
        body=_indented(body),
    )


def scene_tangent(
    scene: Scene, dyads: list[Dyad], evaluate_lines: list[str], runs_kinematics: bool
) -> tuple[str, str]:
    """The parts of the scene's `<identifier>_derivative` from the lines of its
    `<identifier>_evaluate`: the code before it (`kinematics_tangent` and its helpers
    where the kinematics are internal, else "") and its body; dyads: those whose
    kinematics it runs."""
    body = Differentiation(scene.identifier, Names(_inputs(scene))).lines(evaluate_lines)
    if not runs_kinematics:
        return "", _indented(body)
    return _kinematics_tangent(scene, dyads, "\n".join(body)), _indented(body)
