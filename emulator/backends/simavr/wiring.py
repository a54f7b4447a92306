"""Which registers carry which wire: a robot's pins (its profile's `wiring`, from its robot file)
mapped to the MCU's registers (mcu.py), and one register snapshot decoded into what the board's
wires carry (duty, direction, brake/coast, pulse widths, LEDs)."""

from __future__ import annotations

from dataclasses import dataclass

from emulator.backends.pins import RELEASED, PinState, bts7960, hbridge
from emulator.backends.simavr.mcu import COM_BIT, MCUS, Mcu
from emulator.errors import EmulatorValueError
from protocol.generated.profiles import RobotProfile, WiredPart


@dataclass(frozen=True)
class PwmPin:
    """An analogWrite() pin: the timer's TCCRnA (COM bit says the PWM is connected) and OCRnx, or the
    PORT bit when analogWrite(0/255) / digitalWrite() made it a plain output."""

    tccr_a: int
    com_bit: int
    ocr: int
    port: int
    bit: int


@dataclass(frozen=True)
class PortPin:
    port: int
    bit: int


@dataclass(frozen=True)
class HBridgeChannel:
    """TB6612 (with STBY) or L298N (without) channel."""

    pwm: PwmPin
    in1: PortPin
    in2: PortPin
    standby: PortPin | None


@dataclass(frozen=True)
class Bts7960Channel:
    rpwm: PwmPin
    lpwm: PwmPin
    r_en: PortPin
    l_en: PortPin


@dataclass(frozen=True)
class PulsePin:
    """A 16-bit timer's fast-PWM mode 14 servo channel: high for OCRnx + 1 half-microseconds
    (rc_pulses.h)."""

    tccr_a: int
    com_bit: int
    ocr: int


@dataclass(frozen=True)
class BoardWiring:
    example: str
    mcu: str
    encoders: tuple[tuple[str, str], ...]
    """Port and bit of each encoder's A and B channel ("E4"), as the harness's --enc takes them."""
    motors: tuple[HBridgeChannel | Bts7960Channel, ...] = ()
    """DC motor driver channels, in wheel-channel order."""
    esc: PulsePin | None = None
    servo: PulsePin | None = None
    leds: tuple[PortPin, ...] = ()
    """In Lights bit order."""
    pcint_k: bool = False
    """An encoder is on port K: the harness models the Mega's PCINT2 (simavr lacks it)."""

    def watch(self) -> list[int]:
        """Data-space addresses the harness reports; 16-bit registers as two bytes."""
        out: list[int] = []
        for ch in self.motors:
            if isinstance(ch, HBridgeChannel):
                out += [*_pwm_regs(ch.pwm), ch.in1.port, ch.in2.port]
                out += [ch.standby.port] if ch.standby is not None else []
            else:
                out += [*_pwm_regs(ch.rpwm), *_pwm_regs(ch.lpwm), ch.r_en.port, ch.l_en.port]
        for p in (self.esc, self.servo):
            if p is not None:
                out += [p.tccr_a, p.ocr, p.ocr + 1]
        out += [led.port for led in self.leds]
        return sorted(set(out))


def _pwm_regs(p: PwmPin) -> list[int]:
    return [p.tccr_a, p.ocr, p.port]


class _Pins:
    """Arduino pin numbers of one MCU -> the register views above."""

    def __init__(self, mcu: Mcu, example: str) -> None:
        self.mcu = mcu
        self.example = example

    def port(self, pin: int) -> PortPin:
        letter, bit = self.mcu.port_bit(pin)
        return PortPin(self.mcu.port[letter], bit)

    def pwm(self, pin: int) -> PwmPin:
        output = self._output(pin, "a PWM pin")
        p = self.port(pin)
        return PwmPin(self.mcu.tccr_a[int(output[0])], COM_BIT[output[1]], self.mcu.ocr[output], p.port, p.bit)

    def pulse(self, pin: int) -> PulsePin:
        output = self._output(pin, "a 16-bit timer's pin (servo pulses)")
        if output[0] in ("0", "2"):
            raise EmulatorValueError("wiring", pin, f"a 16-bit timer's pin on the {self.mcu.name} ({self.example})")
        return PulsePin(self.mcu.tccr_a[int(output[0])], COM_BIT[output[1]], self.mcu.ocr[output])

    def _output(self, pin: int, what: str) -> str:
        output = self.mcu.pwm.get(pin)
        if output is None:
            raise EmulatorValueError("wiring", pin, f"{what} of the {self.mcu.name} ({self.example})")
        return output

    def motor(self, part: WiredPart) -> HBridgeChannel | Bts7960Channel:
        roles = dict(part.pins)
        if part.kind == "BTS7960":
            return Bts7960Channel(
                self.pwm(roles["rpwm"]), self.pwm(roles["lpwm"]), self.port(roles["r_en"]), self.port(roles["l_en"])
            )
        standby = self.port(roles["standby"]) if "standby" in roles else None
        return HBridgeChannel(self.pwm(roles["pwm"]), self.port(roles["in1"]), self.port(roles["in2"]), standby)


def board_wiring(profile: RobotProfile) -> BoardWiring:
    """The harness's view of a reference robot: its pins on its board's MCU."""
    mcu = MCUS[profile.board]
    w = profile.wiring
    pins = _Pins(mcu, profile.example)
    encoders = tuple((mcu.pins[e.pin("a")], mcu.pins[e.pin("b")]) for e in w.encoders)
    return BoardWiring(
        example=profile.example,
        mcu=mcu.name,
        encoders=encoders,
        motors=tuple(pins.motor(m) for m in w.motors),
        esc=pins.pulse(w.esc_pin) if w.esc_pin is not None else None,
        servo=pins.pulse(w.servo_pin) if w.servo_pin is not None else None,
        leds=tuple(pins.port(p) for p in w.led_pins),
        pcint_k=any(code.startswith("K") for pair in encoders for code in pair),
    )


def decode_pins(wiring: BoardWiring, regs: dict[int, int]) -> PinState:
    def bit(p: PortPin) -> bool:
        return bool(regs[p.port] >> p.bit & 1)

    def pwm(p: PwmPin) -> float:
        if regs[p.tccr_a] >> p.com_bit & 1:
            return regs[p.ocr] / 255.0
        return 1.0 if regs[p.port] >> p.bit & 1 else 0.0

    def pulse(p: PulsePin | None) -> int:
        if p is None or not regs[p.tccr_a] >> p.com_bit & 1:
            return 0
        return (regs[p.ocr] | regs[p.ocr + 1] << 8) + 1 >> 1

    channels = [
        hbridge(bit(ch.in1), bit(ch.in2), None if ch.standby is None else bit(ch.standby), pwm(ch.pwm))
        if isinstance(ch, HBridgeChannel)
        else bts7960(bit(ch.r_en), bit(ch.l_en), pwm(ch.rpwm), pwm(ch.lpwm))
        for ch in wiring.motors
    ]
    leds = sum(1 << i for i, led in enumerate(wiring.leds) if bit(led))
    return PinState(
        tuple(d for d, _ in channels), tuple(m for _, m in channels), pulse(wiring.esc), pulse(wiring.servo), leds
    )


__all__ = ["RELEASED", "BoardWiring", "PinState", "board_wiring", "decode_pins"]
