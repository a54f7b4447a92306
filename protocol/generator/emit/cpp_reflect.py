"""Emit tests/firmware/native/generated/roverlink_reflect.h: a test-only text interface (print fields, set
fields by name) that lets the Python tests drive the C++ codec field by field."""

from __future__ import annotations

from protocol.generator.emit.common import banner
from protocol.generator.emit.cpp_types import ctype
from protocol.generator.model import Field, Message, Spec

_HEAD = (
    "// Test-only: text view of every message for tests/firmware/native/rl_codec.cpp. Not part of the library.\n"
    "#ifndef ROVERLINK_REFLECT_H\n#define ROVERLINK_REFLECT_H\n\n"
    '#include <stdio.h>\n#include <stdlib.h>\n#include <string.h>\n\n#include "generated/roverlink_protocol.h"\n\n'
    "namespace roverlink {\nnamespace reflect {\n\n"
)
# The text forms of f32 (hex of its bits) and of byte/char arrays (hex), both ways.
_HELPERS = (
    "inline void print_f32(FILE* f, float v) {\n    uint32_t bits;\n    memcpy(&bits, &v, 4);\n"
    '    fprintf(f, "0x%08lX", static_cast<unsigned long>(bits));\n}\n'
    "inline float parse_f32(const char* s) {\n    uint32_t bits = static_cast<uint32_t>(strtoul(s, NULL, 16));\n"
    "    float v;\n    memcpy(&v, &bits, 4);\n    return v;\n}\n"
    "inline void print_hex(FILE* f, const uint8_t* p, uint8_t n) {\n"
    '    for (uint8_t i = 0; i < n; ++i) fprintf(f, "%02x", p[i]);\n}\n'
    "inline uint8_t parse_hex(const char* s, uint8_t* out, uint8_t cap) {\n    uint8_t n = 0;\n"
    "    while (s[0] && s[1] && n < cap) {\n        char b[3] = {s[0], s[1], 0};\n"
    "        out[n++] = static_cast<uint8_t>(strtoul(b, NULL, 16));\n        s += 2;\n    }\n    return n;\n}\n\n"
)
_TAIL = "}  // namespace reflect\n}  // namespace roverlink\n\n#endif  // ROVERLINK_REFLECT_H\n"


def reflect(spec: Spec) -> str:
    """print_fields()/set_field() per message, for the native cross-check tool.

    Text form of a field value: integers in decimal (enums and flags as their number), f32 as the
    hex of its IEEE-754 bits (exact), arrays comma-separated, byte/char arrays as hex.
    """
    out = [banner(spec, "//"), _HEAD, _HELPERS]
    for m in spec.messages:
        out.append(_print_fields(m))
        out.append(_set_field(m))
    for fs in spec.structs:
        out.append(f'// A {fs.struct}\'s fields only (no name), e.g. " {fs.fields[0].name}=0 ...".\n')
        out.append(f"inline void print_fields(FILE* f, const proto::{fs.struct}& s) {{\n")
        for fld in fs.fields:
            out.append(f'    fprintf(f, " {fld.name}=%lu", static_cast<unsigned long>(s.{fld.name}));\n')
        out.append("}\n\n")
    out.append(_by_id_and_name(spec))
    out.append(_TAIL)
    return "".join(out)


def _print_fields(m: Message) -> str:
    arg = "m" if m.fields else "/*m*/"
    out = [f"inline void print_fields(FILE* f, const proto::{m.class_name}& {arg}) {{\n"]
    out.append(f'    fputs("{m.name}", f);\n')
    for fld in m.fields:
        out.append(f'    fputs(" {fld.name}=", f);\n')
        if fld.max_len is not None:
            out.append(f"    print_hex(f, reinterpret_cast<const uint8_t*>(m.{fld.name}), m.{fld.name}_len);\n")
            continue
        value = f"m.{fld.name}{'[k]' if fld.count else ''}"
        if fld.is_float:
            line = f"print_f32(f, {value});"
        elif fld.prim == "u32":
            line = f'fprintf(f, "%lu", static_cast<unsigned long>({value}));'
        else:
            line = f'fprintf(f, "%ld", static_cast<long>({value}));'
        if fld.count:
            out.append(f"    for (uint8_t k = 0; k < {fld.count}; ++k) {{\n")
            out.append(f"        if (k) fputc(',', f);\n        {line}\n    }}\n")
        else:
            out.append(f"    {line}\n")
    out.append("}\n\n")
    return "".join(out)


def _set_field(m: Message) -> str:
    arg = "m" if m.fields else "/*m*/"
    out = [f"inline bool set_field(proto::{m.class_name}& {arg}, const char* name, const char* value) {{\n"]
    if not m.fields:
        out.append("    (void)name;\n    (void)value;\n    return false;\n}\n\n")
        return "".join(out)
    for fld in m.fields:
        out.append(f'    if (strcmp(name, "{fld.name}") == 0) {{\n')
        out.append(_parse_into(fld))
        out.append("        return true;\n    }\n")
    out.append("    return false;\n}\n\n")
    return "".join(out)


def _parse_into(fld: Field) -> str:
    """Statements setting `m.<field>` from the text `value` (comma-separated for arrays)."""
    if fld.max_len is not None:
        return (
            f"        m.{fld.name}_len = parse_hex(value, reinterpret_cast<uint8_t*>(m.{fld.name}), {fld.max_len});\n"
        )
    cty = ctype(fld)
    if fld.enum is not None and not fld.enum.flags:
        cty = f"proto::{cty}"
    if fld.is_float:
        conv = "parse_f32(v)"
    elif fld.prim == "u32":
        conv = f"static_cast<{cty}>(strtoul(v, NULL, 10))"
    else:
        conv = f"static_cast<{cty}>(strtol(v, NULL, 10))"
    if not fld.count:
        return f"        const char* v = value;\n        m.{fld.name} = {conv};\n"
    return (
        f"        const char* v = value;\n        for (uint8_t k = 0; k < {fld.count}; ++k) {{\n"
        f"            m.{fld.name}[k] = {conv};\n"
        f"            v = strchr(v, ',');\n            if (!v) return k == {fld.count - 1};\n"
        "            ++v;\n        }\n"
    )


def _by_id_and_name(spec: Spec) -> str:
    """with_message(): a zeroed message of a msg_id; id_of(): the msg_id of a NAME."""
    out = ["// Calls fn(msg) with a zeroed message of type `msg_id`; false for an unknown id.\n"]
    out.append("template <class Fn>\nbool with_message(uint8_t msg_id, Fn& fn) {\n    switch (msg_id) {\n")
    for m in spec.messages:
        out.append(f"    case proto::{m.class_name}::ID: {{\n        proto::{m.class_name} m;\n")
        out.append("        memset(&m, 0, sizeof m);\n        fn(m);\n        return true;\n    }\n")
    out.append("    default:\n        return false;\n    }\n}\n\n")
    out.append("// msg_id of a message NAME, or -1.\ninline int id_of(const char* name) {\n")
    for m in spec.messages:
        out.append(f'    if (strcmp(name, "{m.name}") == 0) return proto::{m.class_name}::ID;\n')
    out.append("    return -1;\n}\n\n")
    return "".join(out)
