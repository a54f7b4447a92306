"""No hand-written copy of a spec bound: code uses the generated names.

The spec (protocol/spec/roverlink.toml) writes each limit once; the generator gives every one a
name on both sides (WATCHDOG_MAX_MS, SetAckermann.STEERING_MRAD_MAX, Hello.WATCHDOG_MS_MAX...).
This scan fails when a literal with a bound's value is used *as that bound* in hand-written code:

- Python (AST): a number compared with something, passed to min/max/a clamp, or assigned to / the
  default of a name, in a statement that mentions the bound's subject (`watchdog`, `steering`...);
  for the watchdog also in seconds (0.05, 2.0, 0.25), since the SDK speaks seconds.
- C++ (regex, comments and strings removed, under arduino/RoverLink/src and the examples'
  sketches, generated code excluded): the same uses on one line (a comparison, a clamp/min/max/
  constrain call, a `const` definition).

A number is only a copy where it stands for the bound: 1000 in `/ 1000` is a unit conversion, 50
ticks of a stall timer is not a watchdog. The subject words and the "used as a bound" rule keep
those out without a long allow-list; ALLOWED lists the few exceptions, each with its reason.
"""

from __future__ import annotations

import ast
import re
from dataclasses import dataclass
from pathlib import Path

from protocol.generated import constants
from protocol.generated.messages import Feedback, Hello, SetAckermann, SetConfig

ROOT = Path(__file__).resolve().parents[3]
PY_PACKAGES = ("protocol", "host_sdk", "emulator", "roverlink")
CPP_DIRS = ("arduino/RoverLink/src", "arduino/RoverLink/examples")
GENERATED = ("protocol/generated/", "arduino/RoverLink/src/generated/", "robot_profile.h")


@dataclass(frozen=True)
class Bound:
    name: str
    """The generated name to use instead."""
    values: tuple[float, ...]
    subject: str
    """Regex the statement (Python) or line (C++) must match for the number to be this bound."""
    python_only: tuple[float, ...] = ()
    """Other spellings a Python caller would write (the watchdog in seconds)."""


def _ms(name: str, value: int) -> Bound:
    return Bound(name, (value,), r"(?i)watchdog", (value / 1000,))


BOUNDS = (
    _ms("WATCHDOG_MIN_MS", constants.WATCHDOG_MIN_MS),
    _ms("WATCHDOG_MAX_MS", constants.WATCHDOG_MAX_MS),
    _ms("WATCHDOG_DEFAULT_MS", constants.WATCHDOG_DEFAULT_MS),
    _ms("Hello.WATCHDOG_MS_MAX", Hello.WATCHDOG_MS_MAX),
    Bound(
        "SetAckermann.STEERING_MRAD_MIN/MAX (Feedback's are the same)",
        (SetAckermann.STEERING_MRAD_MIN, SetAckermann.STEERING_MRAD_MAX),
        r"(?i)mrad|steer|angle",
    ),
    Bound("Feedback.STEERING_MRAD_MIN/MAX", (Feedback.STEERING_MRAD_MIN, Feedback.STEERING_MRAD_MAX), r"(?i)mrad"),
    Bound("MAX_PAYLOAD", (constants.MAX_PAYLOAD,), r"(?i)payload"),
    Bound("FEEDBACK_HZ_MAX", (constants.FEEDBACK_HZ_MAX,), r"(?i)feedback_hz|\bhz\b"),
    Bound("FEEDBACK_HZ_DEFAULT", (constants.FEEDBACK_HZ_DEFAULT,), r"(?i)feedback_hz"),
    Bound(
        "SetConfig.SERVO_MIN_US_MIN / SERVO_MAX_US_MAX",
        (SetConfig.SERVO_MIN_US_MIN, SetConfig.SERVO_MAX_US_MAX),
        r"(?i)pulse|servo",
    ),
    Bound(
        "SetConfig.ESC_MIN_US_MIN / ESC_MAX_US_MAX", (SetConfig.ESC_MIN_US_MIN, SetConfig.ESC_MAX_US_MAX), r"(?i)esc"
    ),
    Bound("SetConfig.MAX_WHEEL_SPEED_MM_S_MAX", (SetConfig.MAX_WHEEL_SPEED_MM_S_MAX,), r"(?i)speed|mm_s"),
    Bound("SetConfig.STEERING_*_CDEG_MAX", (SetConfig.STEERING_MAX_CDEG_MAX,), r"(?i)cdeg"),
    Bound(
        "SetConfig.WHEEL_DIAMETER_UM_MIN/MAX",
        (SetConfig.WHEEL_DIAMETER_UM_MIN, SetConfig.WHEEL_DIAMETER_UM_MAX),
        r"(?i)diameter",
    ),
    Bound("WHEEL_COUNT", (constants.WHEEL_COUNT,), r"(?i)wheel"),
)
"""The bounds the scan knows. 1000 (the permille full scale, and ms per s) is deliberately not one:
it is a unit, written in every conversion, and the effort bound is that unit's full scale."""

ALLOWED: dict[tuple[str, float], str] = {
    ("arduino/RoverLink/src/hal/avr/diff_drive_board.h", 2): "DiffDriveBoard is built from a left and a "
    "right motor: its own two wheels, whatever number of channels the protocol carries",
}
"""(path, value) -> why this file may hold that number as a bound."""


@dataclass(frozen=True, order=True)
class Finding:
    path: str
    line: int
    value: float
    bound: str
    text: str

    def __str__(self) -> str:
        return f"{self.path}:{self.line}: {self.value:g} is {self.bound}: {self.text.strip()}"


# -- Python ---------------------------------------------------------------------------------------
CLAMPS = re.compile(r"^(min|max|_?clamp\w*|constrain)$")


def _number(node: ast.AST) -> float | None:
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub):
        inner = _number(node.operand)
        return None if inner is None else -inner
    if isinstance(node, ast.Constant) and type(node.value) in (int, float):
        return float(node.value)
    return None


def _bound_uses(tree: ast.AST) -> list[tuple[ast.AST, ast.AST]]:
    """(number node, the statement-level node whose text gives its subject) for every number used
    as a bound: compared, clamped, assigned or a default."""
    out: list[tuple[ast.AST, ast.AST]] = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Compare):
            out += [(n, node) for n in (node.left, *node.comparators)]
        elif isinstance(node, ast.Call):
            func = node.func
            name = func.id if isinstance(func, ast.Name) else func.attr if isinstance(func, ast.Attribute) else ""
            if CLAMPS.match(name):
                out += [(a, node) for a in node.args]
            out += [(k.value, k) for k in node.keywords]
        elif isinstance(node, (ast.Assign, ast.AnnAssign)) and node.value is not None:
            out.append((node.value, node))
        elif isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            a = node.args
            positional = [*a.posonlyargs, *a.args]
            pairs = list(zip(positional[len(positional) - len(a.defaults) :], a.defaults, strict=True))
            pairs += [(arg, d) for arg, d in zip(a.kwonlyargs, a.kw_defaults, strict=True) if d is not None]
            out += [(d, arg) for arg, d in pairs]
    return out


def _subject(source: str, node: ast.AST, parents: dict[ast.AST, ast.AST]) -> str:
    """The text a number's meaning is read from: its whole expression (up through calls and
    keywords), or the simple statement holding it (an assignment, a return)."""
    top = node
    while isinstance(parents.get(top), ast.expr):
        top = parents[top]
    parent = parents.get(top)
    if isinstance(parent, ast.keyword):  # f(name=...): the keyword names what the number is
        return f"{parent.arg}={ast.get_source_segment(source, top)}"
    if isinstance(parent, (ast.Assign, ast.AnnAssign, ast.AugAssign, ast.Return, ast.Expr)):
        top = parent
    return ast.get_source_segment(source, top) or ""


def scan_python(path: Path, rel: str) -> list[Finding]:
    source = path.read_text(encoding="utf-8")
    tree = ast.parse(source)
    parents = {child: node for node in ast.walk(tree) for child in ast.iter_child_nodes(node)}
    found = []
    for number_node, context in _bound_uses(tree):
        value = _number(number_node)
        if value is None:
            continue
        text = context.arg if isinstance(context, ast.arg) else _subject(source, number_node, parents)
        for bound in BOUNDS:
            if value in bound.values + bound.python_only and re.search(bound.subject, text):
                line = getattr(number_node, "lineno", 0)
                found.append(Finding(rel, line, value, bound.name, source.splitlines()[line - 1]))
                break  # one finding per number, under the first bound it matches
    return found


# -- C++ ------------------------------------------------------------------------------------------
_COMMENTS = re.compile(r"//[^\n]*|/\*.*?\*/|\"(?:\\.|[^\"\\])*\"|'(?:\\.|[^'\\])'", re.S)
_NUMBER = r"-?\b\d+(?:\.\d+)?[uUlLfF]*\b"
_USES = (
    re.compile(rf"(?<![<>])(?:<=?|>=?)(?![<>=])\s*\(?\s*(?:static_cast<\w+>\()?\s*({_NUMBER})"),
    re.compile(rf"({_NUMBER})\s*(?<![<>])(?:<=?|>=?)(?![<>=])"),
    re.compile(r"\b(?:clamp\w*|constrain|min|max)\s*\(([^;]*)\)"),
    re.compile(rf"\bconst\s+[\w:]+\s+\w+\s*=\s*({_NUMBER})\s*;"),
)


def _blank(match: re.Match[str]) -> str:
    """Comments and strings become spaces, newlines kept (line numbers stay right)."""
    return re.sub(r"[^\n]", " ", match.group(0))


def scan_cpp(path: Path, rel: str) -> list[Finding]:
    code = _COMMENTS.sub(_blank, path.read_text(encoding="utf-8"))
    found = []
    for number, line_text in enumerate(code.splitlines(), 1):
        literals: list[str] = []
        for use in _USES:
            for m in use.finditer(line_text):
                literals += re.findall(_NUMBER, m.group(1))
        for lit in literals:
            value = float(re.sub(r"[uUlLfF]+$", "", lit))
            for bound in BOUNDS:
                if value in bound.values and re.search(bound.subject, line_text):
                    found.append(Finding(rel, number, value, bound.name, line_text))
                    break
    return found


# -- the tree -------------------------------------------------------------------------------------
def scan(root: Path = ROOT) -> list[Finding]:
    found: list[Finding] = []
    files = [(p, scan_python) for pkg in PY_PACKAGES for p in (root / pkg).rglob("*.py")]
    for d in CPP_DIRS:
        files += [(p, scan_cpp) for ext in ("*.h", "*.cpp", "*.ino") for p in (root / d).rglob(ext)]
    for path, scanner in files:
        rel = path.relative_to(root).as_posix()
        if not any(g in rel for g in GENERATED):
            found += scanner(path, rel)
    return sorted(f for f in set(found) if (f.path, f.value) not in ALLOWED)


def test_no_hand_written_copy_of_a_spec_bound() -> None:
    found = scan()
    stale = [key for key in ALLOWED if not (ROOT / key[0]).is_file()]
    assert not stale, f"ALLOWED names files that are gone: {stale}"
    assert not found, "use the generated name:\n" + "\n".join(map(str, found))


def test_the_scan_leaves_units_and_other_quantities_alone(tmp_path: Path) -> None:
    py = tmp_path / "a.py"
    py.write_text(
        "cdeg = center + round(steering_mrad * 18000 / (1000 * math.pi))\n"
        "STALL_TICKS = 50\nthread.join(timeout=2.0)\nif not 0 <= ms <= 60_000:\n    pass\n"
        "p = MotorParams(resistance_ohm=2.0, wheel_radius_m=r)\n"
    )
    cpp = tmp_path / "a.cpp"
    cpp.write_text(
        "const uint8_t STALL_TICKS = 50;  // not a watchdog\nx = y << 8;\nreturn div_round(cdeg * span, 18000);\n"
        'const char* s = "watchdog < 2000";\n'
    )
    assert scan_python(py, "a.py") == [] and scan_cpp(cpp, "a.cpp") == []


def test_a_copy_in_a_real_module_is_found(tmp_path: Path) -> None:
    """The whole-tree scan over a copy of a package with one bound pasted back in."""
    for pkg in PY_PACKAGES:
        (tmp_path / pkg).mkdir()
    target = tmp_path / "emulator" / "tick.py"
    original = (ROOT / "emulator/firmware/tick.py").read_text(encoding="utf-8")
    assert "Feedback.STEERING_MRAD_MIN" in original
    target.write_text(original.replace("Feedback.STEERING_MRAD_MIN", "-1571", 1))
    assert scan_python(ROOT / "emulator/firmware/tick.py", "tick.py") == []
    found = scan(tmp_path)
    assert [(f.path, f.line, f.value) for f in found] == [("emulator/tick.py", found[0].line, -1571.0)]
