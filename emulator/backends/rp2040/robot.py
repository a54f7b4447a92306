"""A robot's Pico firmware in rp2040js with its plant around it: the plant loop of the simavr
backend (emulator/backends/plant_loop.py) with the RP2040 harness as its MCU.

    robot = Rp2040Robot(pico_profile("diffdrive-tb6612"), image)   # image: the build's .bin
    robot.host_write(frame); robot.advance_us(20_000); robot.host_read()

The harness watches every output pin the robot file wires (GPIO numbers) and reads back what the
board's wires carry: each motor PWM pin's duty over the step, the direction and enable pins'
levels, the ESC's and servo's pulse widths, the LEDs; the plant's encoder positions become
quadrature edges on the encoder pins. Time is virtual: the harness's clock, the core asleep in WFI
between its wake-ups.
"""

from __future__ import annotations

from pathlib import Path

from emulator.backends.pins import PinState, bts7960, hbridge
from emulator.backends.plant_loop import BAUD, PlantLoop
from emulator.backends.rp2040.harness import Harness, PinReading
from emulator.errors import EmulatorValueError
from emulator.faults import FaultSpec
from emulator.plant.params import plant_from_file
from emulator.profiles import EmulatorProfile
from emulator.robot_file import firmware_defaults, nearest_reference
from protocol.generated.profiles import Wiring
from protocol.robotfile import RobotFile, load, parse, reference_path
from protocol.robotfile.errors import RobotFileError
from protocol.robotfile.pico import on_pico


def pico_robot(name: str) -> RobotFile:
    """Reference robot `name` moved to a Pico (protocol/robotfile/pico.py)."""
    path = reference_path(name)
    robot, problems = parse(on_pico(path.read_text(encoding="utf-8"), str(path)), f"{name} on a Pico")
    if robot is None:
        raise RobotFileError(problems)
    return robot


def pico_profile(robot: str | RobotFile) -> EmulatorProfile:
    """The emulated robot of a Pico robot file (a RobotFile with board = "pico"), or of reference
    robot `robot` moved to a Pico: its plant the reference's own."""
    file = pico_robot(robot) if isinstance(robot, str) else robot
    if file.board != "pico":
        raise EmulatorValueError("board", file.board, '"pico" with the rp2040 backend')
    reference = robot if isinstance(robot, str) else nearest_reference(file)
    return EmulatorProfile(
        robot=firmware_defaults(file),
        plant=plant_from_file(file, load(reference_path(reference))),
        body=file.sensors(),
        robot_file=None if isinstance(robot, str) else file.path,
    )


def watched_pins(w: Wiring) -> tuple[int, ...]:
    pins = [pin for m in w.motors for _, pin in m.pins]
    pins += [p for p in (w.esc_pin, w.servo_pin) if p is not None]
    pins += list(w.led_pins)
    return tuple(sorted(set(pins)))


def decode(w: Wiring, pins: dict[int, PinReading]) -> PinState:
    """What the wired pins carry, from one step's readings."""
    channels = []
    for m in w.motors:
        roles = dict(m.pins)

        def level(role: str, roles: dict[str, int] = roles) -> bool:
            return pins[roles[role]].level

        if m.kind == "BTS7960":
            channels.append(bts7960(level("r_en"), level("l_en"), pins[roles["rpwm"]].high, pins[roles["lpwm"]].high))
        else:
            standby = level("standby") if "standby" in roles else None
            channels.append(hbridge(level("in1"), level("in2"), standby, pins[roles["pwm"]].high))

    def pulse(pin: int | None) -> int:
        return 0 if pin is None else round(pins[pin].pulse_us)

    leds = sum(1 << i for i, pin in enumerate(w.led_pins) if pins[pin].level)
    return PinState(
        tuple(d for d, _ in channels), tuple(m for _, m in channels), pulse(w.esc_pin), pulse(w.servo_pin), leds
    )


class _Rp2040MCU:
    def __init__(self, harness: Harness, wiring: Wiring) -> None:
        self.harness = harness
        self.wiring = wiring

    def step(self, us: int, counts: list[int], rx: bytes) -> tuple[PinState, bytes]:
        readings, out = self.harness.step(us, counts, rx)
        return decode(self.wiring, readings), out

    def reset(self) -> None:
        self.harness.reset()


class Rp2040Robot(PlantLoop):
    """A Pico robot's firmware image (`image`: the build's .bin, a flash image) in rp2040js inside
    the plant loop. `seed` draws the line's faults and the ring oscillator's noise (the boot_id);
    `histogram`: the harness keeps the cycles executed at each PC (Harness.histogram)."""

    def __init__(
        self,
        profile: EmulatorProfile,
        image: Path,
        *,
        baud: int = BAUD,
        seed: int = 1,
        faults: str | FaultSpec | None = None,
        latency_us: int = 0,
        drift_ppm: float = 0.0,
        histogram: bool = False,
    ) -> None:
        w = profile.robot.wiring
        encoders = tuple((dict(e.pins)["a"], dict(e.pins)["b"]) for e in w.encoders)
        self.harness = Harness(
            image, encoders=encoders, watch=watched_pins(w), baud=baud, seed=seed, flash=True, histogram=histogram
        )
        try:
            super().__init__(
                profile,
                _Rp2040MCU(self.harness, w),
                baud=baud,
                seed=seed,
                faults=faults,
                latency_us=latency_us,
                drift_ppm=drift_ppm,
            )
        except BaseException:
            self.harness.close()
            raise

    @property
    def mcu_nanos(self) -> int:
        """The chip's clock (ns since power-up, across resets)."""
        return self.harness.nanos

    def close(self) -> None:
        self.harness.close()

    def __enter__(self) -> Rp2040Robot:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
