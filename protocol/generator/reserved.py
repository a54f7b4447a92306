"""Names a spec may not use because a target language (or the Arduino core's macros) owns them."""

from __future__ import annotations

import keyword

CPP_KEYWORDS = frozenset(
    """alignas alignof and and_eq asm auto bitand bitor bool break case catch char char16_t char32_t
    class compl const constexpr const_cast continue decltype default delete do double dynamic_cast
    else enum explicit export extern false float for friend goto if inline int long mutable namespace
    new noexcept not not_eq nullptr operator or or_eq private protected public register
    reinterpret_cast return short signed sizeof static static_assert static_cast struct switch
    template this thread_local throw true try typedef typeid typename union unsigned using virtual
    void volatile wchar_t while xor xor_eq NULL""".split()
)

# Macros from the Arduino core and avr-libc that would silently rewrite an identifier.
ARDUINO_MACROS = frozenset(
    """HIGH LOW INPUT OUTPUT INPUT_PULLUP LED_BUILTIN DEFAULT EXTERNAL INTERNAL INTERNAL1V1
    INTERNAL2V56 CHANGE FALLING RISING LSBFIRST MSBFIRST PI HALF_PI TWO_PI DEG_TO_RAD RAD_TO_DEG
    EULER SERIAL DISPLAY DEC HEX OCT BIN abs min max round radians degrees sq constrain bit lowByte
    highByte bitRead bitSet bitClear bitWrite interrupts noInterrupts F PSTR PROGMEM NOT_A_PIN
    NOT_A_PORT NOT_AN_INTERRUPT NOT_ON_TIMER TIMER0A TIMER1A TIMER2A SREG SPCR SPSR SPDR UDR0 TCNT0
    TCNT1 OCR1A OCR1B ICR1 EEAR EEDR RAMEND FLASHEND E2END""".split()
)

# Attribute names the generated Python and C++ message types define themselves.
GENERATED_MEMBERS = frozenset(
    """MSG_ID CRC_EXTRA PAYLOAD_SIZE PAYLOAD_MAX NAME DIRECTION DELIVERY FIELDS ID pack unpack
    self cls""".split()
)


def reserved_reason(name: str) -> str | None:
    """Why `name` cannot be used, or None if it is free."""
    if keyword.iskeyword(name) or keyword.issoftkeyword(name):
        return "a Python keyword"
    if name in CPP_KEYWORDS:
        return "a C++ keyword"
    if name in ARDUINO_MACROS:
        return "an Arduino core or avr-libc macro"
    if name in GENERATED_MEMBERS:
        return "a member of the generated message types"
    if name.startswith("_") or "__" in name:
        return "leading or double underscores are reserved in C++"
    return None
