"""The generated C++ checks of each message: values_defined() (enums, flag bits, ASCII: what unpack()
refuses) and check_ranges() (the spec ranges: the first field outside its range). Integers compare
as integers; a float compares by its order key (src/wire/layout.h), so no floating-point code is
needed."""

from __future__ import annotations

import re
import struct

from protocol.generator.emit.cpp_types import CTYPE, ctype, float_lit, int_lit
from protocol.generator.model import PRIMITIVES, Enum, Field, Message


def value_checks(m: Message) -> list[tuple[Field, str, str]]:
    """(field, C++ test of one element `v` that is true for an undefined value, comment) per checked field."""
    out = []
    for f in m.fields:
        test = undefined_test(f)
        if test is not None:
            out.append((f, *test))
    return out


def undefined_test(f: Field) -> tuple[str, str] | None:
    """(C++ test of one element `v` that is true for a value the field's type does not define: an
    enum value, a flag bit, a non-ASCII char; comment), or None for a field of no such type."""
    if f.enum is not None and f.enum.flags:
        width = PRIMITIVES[f.prim][0]
        undefined = ~f.enum.mask & ((1 << (8 * width)) - 1)
        return f"(v & 0x{undefined:X}u) != 0", f"{f.enum.name} bits 0x{f.enum.mask:X}"
    if f.enum is not None:
        return f"!is_valid_{f.enum.name}(static_cast<{CTYPE[f.prim]}>(v))", f.enum.name
    if f.prim == "char":
        return "static_cast<uint8_t>(v) > 0x7F", "ASCII"
    return None


def answers_values(m: Message) -> bool:
    """A reliable request: its receiver answers a value the spec does not define with NACK(OUT_OF_RANGE,
    the field), so its direction's dispatcher leaves the values to check_ranges()."""
    return m.direction == "host_to_mcu" and m.delivery == "reliable"


def _range_test(f: Field) -> tuple[str, str] | None:
    """(C++ test of one element `v` that is true when it is OUT of range, comment), or None. The
    values a type does not define are out of range too (enum, flag bit, ASCII), so check_ranges()
    alone vets a message whose values nothing has checked."""
    undefined = undefined_test(f)
    if undefined is not None or f.max_len is not None:
        return undefined
    if f.is_float:  # always: a float field without a spec range still refuses NaN and infinity
        # Both zeros compare equal in the spec (and in Python): widen a bound at zero to take both.
        lo_bits = 0x80000000 if f.lo == 0 else _f32_bits(f.lo)
        hi_bits = 0x00000000 if f.hi == 0 else _f32_bits(f.hi)
        lo_key, hi_key = _key(lo_bits, "f32"), _key(hi_bits, "f32")
        test = f"!layout::f32_within(v, 0x{lo_key:08X}UL, 0x{hi_key:08X}UL)"
        return test, f"{float_lit(f.lo)}..{float_lit(f.hi)}, as order keys"
    _, _, _, tlo, thi = PRIMITIVES[f.prim]
    lo = int(f.min) if f.min is not None else int(tlo or 0)
    hi = int(f.max) if f.max is not None else int(thi or 0)
    # An unsigned bound is written unsigned, so the compare is unsigned on every target.
    suffix = "u" if f.prim in ("u8", "u16") else ""  # int_lit() writes u32 as UL already
    tests = []
    if lo != tlo:
        tests.append(f"v < {int_lit(lo, f.prim)}{suffix}")
    if hi != thi:
        tests.append(f"v > {int_lit(hi, f.prim)}{suffix}")
    if not tests:
        return None
    return " || ".join(tests), f"{lo}..{hi}"


def range_checks(m: Message) -> list[tuple[int, Field, str, str]]:
    """(field index, field, out-of-range test of `v`, comment) of every ranged field, spec order."""
    out = []
    for i, f in enumerate(m.fields):
        r = _range_test(f)
        if r is not None:
            out.append((i, f, *r))
    return out


_ELEMENT = re.compile(r"\bv\b")


def _each(f: Field, body: str, indent: str = "    ") -> str:
    """`body` (a statement about `v`) for the field's element, or for each element of an array."""
    if f.count is None and f.max_len is None:
        return indent + _ELEMENT.sub(f"m.{f.name}", body) + "\n"
    count = str(f.count) if f.count is not None else f"m.{f.name}_len"
    return (
        f"{indent}for (uint8_t i = 0; i < {count}; ++i) {{\n"
        f"{indent}    const {ctype(f)} v = m.{f.name}[i];\n{indent}    {body}\n{indent}}}\n"
    )


def check_functions(m: Message) -> str:
    """The message's values_defined() and check_ranges(), when it has something to check."""
    n = m.class_name
    out = []
    values = value_checks(m)
    if values:
        out.append(f"bool values_defined(const {n}& m) {{\n")
        for f, test, note in values:
            out.append(f"    // {f.name}: {note}\n")
            out.append(_each(f, f"if ({test}) return false;"))
        out.append("    return true;\n}\n\n")
    ranges = range_checks(m)
    if ranges:
        out.append(f"uint8_t check_ranges(const {n}& m) {{\n")
        for run in _runs(ranges):
            i, f, test, note = run[0]
            if len(run) < _RUN_MIN:
                for i, f, test, note in run:
                    out.append(f"    // {f.name}: {note}\n")
                    out.append(_each(f, f"if ({test}) return {i};"))
                continue
            # Adjacent fields with the same check: one loop over their bytes (one copy of the test).
            names = ", ".join(g[1].name for g in run)
            out.append(f"    // {names}: {note}\n")
            out.append(f"    for (uint8_t i = 0; i < {len(run)}; ++i) {{\n")
            out.append(f"        {ctype(f)} v;\n")
            out.append(
                f"        memcpy(&v, reinterpret_cast<const uint8_t*>(&m) + offsetof({n}, {f.name}) + i * sizeof v, "
                "sizeof v);\n"
            )
            out.append(f"        if ({test}) return static_cast<uint8_t>({i} + i);\n    }}\n")
        out.append("    return ALL_FIELDS_VALID;\n}\n\n")
    return "".join(out)


_RUN_MIN = 2  # adjacent fields with one check that become a loop (fewer: one test each is smaller)


def _runs(ranges: list[tuple[int, Field, str, str]]) -> list[list[tuple[int, Field, str, str]]]:
    """The range checks in runs of adjacent scalar fields of one type with the same test."""

    def scalar(f: Field) -> bool:
        return f.count is None and f.max_len is None

    runs: list[list[tuple[int, Field, str, str]]] = []
    for c in ranges:
        prev = runs[-1][-1] if runs else None
        if (
            prev is not None
            and prev[0] + 1 == c[0]
            and scalar(prev[1])
            and scalar(c[1])
            and prev[1].prim == c[1].prim
            and prev[2] == c[2]
        ):
            runs[-1].append(c)
        else:
            runs.append([c])
    return runs


def enum_test(e: Enum) -> str:
    """The body of is_valid_<Enum>(value): a range when the values are contiguous, else a switch."""
    values = sorted(v.value for v in e.values)
    lo, hi = values[0], values[-1]
    if values == list(range(lo, hi + 1)):
        return f"return value <= {hi};" if lo == 0 else f"return value >= {lo} && value <= {hi};"
    cases = " ".join(f"case {v}:" for v in values)
    return f"switch (value) {{ {cases} return true; default: return false; }}"


def _f32_bits(value: float) -> int:
    """IEEE-754 single-precision bits of `value`, rounded to nearest as a C float literal is."""
    try:
        return int.from_bytes(struct.pack("<f", value), "little")
    except OverflowError:
        return 0xFF800000 if value < 0 else 0x7F800000


def _key(value: int, prim: str) -> int:
    """The order key of an element (wire/layout.h): unsigned order = the numbers' order."""
    width = PRIMITIVES[prim][0]
    bits = value & ((1 << (8 * width)) - 1)
    if prim == "f32":
        return bits ^ 0xFFFFFFFF if bits & 0x80000000 else bits | 0x80000000
    if prim.startswith("i"):
        return bits ^ (1 << (8 * width - 1))
    return bits
