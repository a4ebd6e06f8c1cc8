"""C names: a small C lexer, the identifiers C and its standard headers reserve, and the
names the project's headers declare. The scene generator refuses a scene whose names
would collide with any of them in the generated code (scenefile/names.py and
scenefile/c_names.py).

The lexer follows translation phases 1 to 3 as far as names go: trigraphs are replaced
(gcc -std=c99 honours them), backslash-newlines joined, then comments, string and
character literals, preprocessing directives, identifiers, numbers and punctuators
are told apart. It is meant for the generated code and the project's headers, and for
tests that look at generated code; it is not a preprocessor.

Python 3.11 standard library only.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

#: The keywords of C99, C11, C17 and C23, and the macros that spell keywords (stdbool.h,
#: stdalign.h, stdnoreturn.h, complex.h, iso646.h).
C_KEYWORDS = frozenset(
    """
auto break case char const continue default do double else enum extern float for goto if
inline int long register restrict return short signed sizeof static struct switch typedef
union unsigned void volatile while _Bool _Complex _Imaginary _Alignas _Alignof _Atomic
_Generic _Noreturn _Static_assert _Thread_local alignas alignof bool constexpr false
nullptr static_assert thread_local true typeof typeof_unqual _BitInt _Decimal32
_Decimal64 _Decimal128 noreturn complex imaginary asm
and and_eq bitand bitor compl not not_eq or or_eq xor xor_eq
""".split()
)

#: Names of the standard headers the generated code includes (directly or through the
#: project's headers), as the C standard (C99, C11) defines them, and the common macros
#: every C program must leave alone. A header missing here is an error of the
#: generator (see headers_names), so that this list cannot silently go stale.
_MATH_FUNCTIONS = """
acos asin atan atan2 cos sin tan acosh asinh atanh cosh sinh tanh exp exp2 expm1 frexp
ilogb ldexp log log10 log1p log2 logb modf scalbn scalbln cbrt fabs hypot pow sqrt erf
erfc lgamma tgamma ceil floor nearbyint rint lrint llrint round lround llround trunc fmod
remainder remquo copysign nan nextafter nexttoward fdim fmax fmin fma
""".split()
STANDARD_HEADERS = {
    "math.h": frozenset(
        _MATH_FUNCTIONS
        + [f + s for f in _MATH_FUNCTIONS for s in ("f", "l")]
        + """
        float_t double_t HUGE_VAL HUGE_VALF HUGE_VALL INFINITY NAN FP_INFINITE FP_NAN
        FP_NORMAL FP_SUBNORMAL FP_ZERO FP_FAST_FMA FP_FAST_FMAF FP_FAST_FMAL FP_ILOGB0
        FP_ILOGBNAN MATH_ERRNO MATH_ERREXCEPT math_errhandling fpclassify isfinite isinf
        isnan isnormal signbit isgreater isgreaterequal isless islessequal islessgreater
        isunordered M_PI M_E j0 j1 jn y0 y1 yn gamma signgam""".split()
    ),
    "stdio.h": frozenset(
        """
        size_t FILE fpos_t NULL _IOFBF _IOLBF _IONBF BUFSIZ EOF FOPEN_MAX FILENAME_MAX
        L_tmpnam SEEK_CUR SEEK_END SEEK_SET TMP_MAX stderr stdin stdout remove rename tmpfile
        tmpnam fclose fflush fopen freopen setbuf setvbuf fprintf fscanf printf scanf
        snprintf sprintf sscanf vfprintf vfscanf vprintf vscanf vsnprintf vsprintf vsscanf
        fgetc fgets fputc fputs getc getchar gets putc putchar puts ungetc fread fwrite
        fgetpos fseek fsetpos ftell rewind clearerr feof ferror perror""".split()
    ),
    "string.h": frozenset(
        """
        size_t NULL memcpy memmove strcpy strncpy strcat strncat memcmp strcmp strcoll
        strncmp strxfrm memchr strchr strcspn strpbrk strrchr strspn strstr strtok memset
        strerror strlen strdup strndup""".split()
    ),
    "stddef.h": frozenset("ptrdiff_t size_t wchar_t max_align_t NULL offsetof".split()),
    "stdarg.h": frozenset("va_list va_start va_arg va_end va_copy".split()),
    "float.h": frozenset(
        """
        FLT_ROUNDS FLT_EVAL_METHOD FLT_RADIX FLT_MANT_DIG DBL_MANT_DIG LDBL_MANT_DIG
        DECIMAL_DIG FLT_DIG DBL_DIG LDBL_DIG FLT_MIN_EXP DBL_MIN_EXP LDBL_MIN_EXP
        FLT_MIN_10_EXP DBL_MIN_10_EXP LDBL_MIN_10_EXP FLT_MAX_EXP DBL_MAX_EXP LDBL_MAX_EXP
        FLT_MAX_10_EXP DBL_MAX_10_EXP LDBL_MAX_10_EXP FLT_MAX DBL_MAX LDBL_MAX FLT_EPSILON
        DBL_EPSILON LDBL_EPSILON FLT_MIN DBL_MIN LDBL_MIN""".split()
    ),
}
#: Names every C program leaves alone whatever it includes: errno (a macro of errno.h
#: that other headers may pull in), assert, the limits of the common types.
COMMON_MACROS = frozenset(
    """
errno assert NULL EOF INFINITY NAN EDOM ERANGE EILSEQ CHAR_BIT INT_MAX INT_MIN UINT_MAX
LONG_MAX LONG_MIN SIZE_MAX true false bool I main
""".split()
)


@dataclass(frozen=True)
class Token:
    """A token of C source text, with its line."""

    kind: str  # comment, string, char, directive, header, identifier, number, punct
    text: str
    line: int
    member: bool = False  # an identifier right after '.' or '->'


_TRIGRAPHS = {
    "=": "#",
    "(": "[",
    "/": "\\",
    ")": "]",
    "'": "^",
    "<": "{",
    "!": "|",
    ">": "}",
    "-": "~",
}
_TOKEN = re.compile(
    r"""
    (?P<comment>/\*.*?\*/|//[^\n]*)
  | (?P<string>(?:u8|[uUL])?"(?:\\.|[^"\\\n])*")
  | (?P<char>(?:[uUL])?'(?:\\.|[^'\\\n])*')
  | (?P<identifier>[A-Za-z_][A-Za-z0-9_]*)
  | (?P<number>\.?[0-9](?:[eEpP][+-]|[A-Za-z0-9_.])*)
  | (?P<punct>->|\+\+|--|<<=|>>=|<<|>>|<=|>=|==|!=|&&|\|\||[-+*/%&|^!~<>=?:;,.(){}\[\]#])
  | (?P<space>\s+)
  | (?P<other>.)
""",
    re.S | re.X,
)


def translate(code: str, trigraphs: bool = True) -> str:
    """Translation phases 1 and 2: trigraphs replaced, backslash-newlines joined (each
    join leaves its newline at the end of the joined line, so that line numbers stay)."""
    if trigraphs:
        code = re.sub(r"\?\?([=(/)'<!>-])", lambda m: _TRIGRAPHS[m.group(1)], code)
    lines = code.split("\n")
    out, pending = [], 0
    current = ""
    for line in lines:
        if line.endswith("\\"):
            current += line[:-1]
            pending += 1
            continue
        out.append(current + line + "\n" * pending)
        current, pending = "", 0
    if current or pending:
        out.append(current + "\n" * pending)
    return "\n".join(out)


def tokens(code: str, trigraphs: bool = True) -> list[Token]:
    """The tokens of C source text (whitespace dropped); raises ValueError on an
    unterminated comment or literal, or a character that starts no token."""
    text = translate(code, trigraphs)
    out: list[Token] = []
    line, at_line_start, directive_next, previous = 1, True, False, None
    header_line, designator = None, 0  # designator: 1 offsetof, 2 "(", 3 "," seen
    for m in _TOKEN.finditer(text):
        kind, value = m.lastgroup, m.group()
        if kind == "other":
            what = "literal" if value in "\"'" else f"character {value!r}"
            raise ValueError(f"line {line}: unterminated or stray {what}")
        if kind == "punct" and value == "/" and text.startswith("*", m.end()):
            raise ValueError(f"line {line}: unterminated comment")
        if kind == "space":
            if "\n" in value:
                at_line_start = True
            line += value.count("\n")
            continue
        if kind == "identifier" and directive_next:
            kind = "directive"
            header_line = line if value == "include" else None
        elif header_line == line:
            kind = "header"  # the header name of an #include
        directive_next = kind == "punct" and value == "#" and at_line_start
        # a member: after '.' or '->', or the member designator of offsetof(type, member)
        member = kind == "identifier" and (previous in (".", "->") or designator == 3)
        designator = (
            1
            if value == "offsetof"
            else designator + 1
            if designator and (designator, value) in ((1, "("), (2, ","))
            else 2
            if designator == 2 and kind == "identifier"
            else 0
        )
        out.append(Token(kind, value, line, member))
        if kind != "comment":
            previous = value
            at_line_start = False
        line += value.count("\n")
    return out


def identifiers(code: str) -> list[Token]:
    """The identifier tokens of C source text (not in comments, literals or directive
    names)."""
    return [t for t in tokens(code) if t.kind == "identifier"]


class _FileScope:
    """The scan of a header for the names it declares at file scope."""

    def __init__(self) -> None:
        self.names: set[str] = set()
        self.parens = 0
        self.braces: list[bool] = []  # per open brace: is it an enum's body
        self.last_keyword: str | None = None
        self.previous: str | None = None
        self.directive_line: int | None = None

    def in_directive(self, t: Token) -> bool:
        """Take a token of a preprocessing directive (a #define's name is declared);
        whether the token was one."""
        if t.kind == "directive":
            self.directive_line = t.line
            if t.text == "define":
                self.previous = "define"
                return True
        if self.directive_line is not None and t.line != self.directive_line:
            self.directive_line = None
        if self.directive_line is None:
            return False
        if self.previous == "define" and t.kind == "identifier":
            self.names.add(t.text)
        self.previous = t.text
        return True

    def punct(self, text: str) -> None:
        """Track the nesting of parentheses and braces."""
        if text == "(":
            self.parens += 1
        elif text == ")":
            self.parens -= 1
        elif text == "{":
            self.braces.append(self.last_keyword == "enum")
        elif text == "}":
            self.braces.pop()
        elif text == ";":
            self.last_keyword = None

    def identifier(self, text: str) -> None:
        """A name at file scope, or an enumerator, is declared."""
        if text in ("enum", "struct", "union"):
            self.last_keyword = text
        elif text in C_KEYWORDS:
            pass
        elif self.parens == 0 and not self.braces:
            self.names.add(text)
        elif self.braces and self.braces[-1] and self.parens == 0 and self.previous in ("{", ","):
            self.names.add(text)  # an enumerator


def declared_names(code: str) -> set[str]:
    """The names a C header declares at file scope: macros, types, struct and enum tags,
    enumerators, functions and objects (not members, parameters or locals)."""
    scope = _FileScope()
    for t in tokens(code):
        if scope.in_directive(t):
            continue
        if t.kind == "punct":
            scope.punct(t.text)
        elif t.kind == "identifier":
            scope.identifier(t.text)
        scope.previous = t.text
    return scope.names


INCLUDE = re.compile(r'^\s*#\s*include\s*([<"])([^>"]+)[>"]', re.M)


def includes(code: str) -> list[tuple[bool, str]]:
    """(system?, name) of every #include of C source text."""
    return [(m.group(1) == "<", m.group(2)) for m in INCLUDE.finditer(code)]


def headers_names(
    code: str, search: list[Path], known: dict[str, str] | None = None, seen: set | None = None
) -> set[str]:
    """Every name the headers `code` includes declare, following the project's headers
    (looked up in `search`, or given as text in `known`) and taking a standard header's
    names from STANDARD_HEADERS. Raises LookupError for a header found in neither."""
    known = known or {}
    seen = set() if seen is None else seen
    names: set[str] = set()
    for system, name in includes(code):
        if name in seen:
            continue
        seen.add(name)
        if system:
            if name not in STANDARD_HEADERS:
                raise LookupError(
                    f"<{name}> is included by generated code, but "
                    "cnames.STANDARD_HEADERS does not list its names"
                )
            names |= STANDARD_HEADERS[name]
            continue
        if name in known:
            text = known[name]
        else:
            for folder in search:
                if (Path(folder) / name).is_file():
                    text = (Path(folder) / name).read_text(encoding="utf-8")
                    break
            else:
                raise LookupError(
                    f'"{name}" is included by generated code, but is in none '
                    f"of {', '.join(map(str, search))}"
                )
        names |= declared_names(text)
        names |= headers_names(text, search, known, seen)
    return names
