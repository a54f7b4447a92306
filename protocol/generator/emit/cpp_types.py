"""C++ spellings shared by the C++ emitters: types and literals."""

from __future__ import annotations

from protocol.generator.model import Field

CTYPE = {
    "u8": "uint8_t",
    "i8": "int8_t",
    "u16": "uint16_t",
    "i16": "int16_t",
    "u32": "uint32_t",
    "i32": "int32_t",
    "f32": "float",
    "char": "char",
}


def comment(text: str, indent: str = "") -> str:
    return f"{indent}// {text}\n"


def ctype(f: Field) -> str:
    if f.enum is not None and not f.enum.flags:
        return f.enum.name
    return CTYPE[f.prim]


def int_lit(value: int, prim: str) -> str:
    if prim == "u32":
        return f"{value}UL"
    if prim == "i32":
        # INT32_MIN cannot be written as a literal without overflow warnings.
        return "(-2147483647L - 1)" if value == -(2**31) else f"{value}L"
    return str(value)


def float_lit(value: float) -> str:
    text = repr(float(value))
    if "e" not in text and "." not in text:
        text += ".0"
    return text + "f"


# -- header ------------------------------------------------------------------------------------
