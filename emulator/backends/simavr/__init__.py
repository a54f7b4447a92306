"""Firmware in the loop: the compiled AVR firmware (an example's ELF) in simavr, closing the loop
through its pins with the emulator's plant.

    robot = SimavrRobot("diffdrive-tb6612")          # the example's ELF: elf=, or ROVERLINK_SIMAVR_ELF_DIR
    robot.host_write(encode_frame(messages.Ping(1), seq=0))
    robot.advance_us(20_000)
    reply = robot.host_read()
    robot.truth.x_m, robot.truth.encoder_edges       # ground truth from the plant

Two processes cooperate: the C harness (tools/simavr/fil_harness.c) runs the ELF in simavr and
reports, every step, the timer compare and port registers of the motor driver, servo and LED pins
and the bytes UART0 sent; the plant loop decodes those registers into what the board's wires carry
(duty, direction, brake/coast, pulse widths), steps `emulator.plant.Plant` (the same equations and
profiles as the Python emulator) every `PHYSICS_US`, and hands the harness the encoder positions
the plant reached (the harness turns each count change into quadrature edges on the encoder pins)
and the host's bytes. Time is virtual: simavr's cycle counter, 16 per us. Between the host and the
MCU is the Python emulator's serial line (`emulator.line.SerialLink`: pacing, latency, faults, the
bootloader's garbage), and fault specs use its grammar and injection code (`emulator.injection`);
`seed` also draws the board's own randomness (ADC0 noise, EEPROM boot counter). docs/emulator.md,
"The simavr backend", lists what is supported and what is refused. `roverlink emulate --backend
simavr` paces the same loop to the wall clock (emulator.transport.realtime).

One module per job (the plant loop around any MCU is emulator/backends/plant_loop.py):

    mcu.py         the AVR parts' datasheet facts: Arduino pin -> port/bit, PWM timers, register addresses
    wiring.py      a robot's pins (its robot file, through its profile) -> registers; decode_pins()
    harness.py     the fil_harness process (build, start, step, profile, stop)
    robot.py       SimavrRobot: a reference robot's ELF in the harness inside a PlantLoop; EEPROM images
"""

from emulator.backends.plant_loop import BAUD, MCU, PHYSICS_US, PlantLoop, SimTruth
from emulator.backends.simavr.harness import HANDLER_FLAG, Harness, SimavrError, build_harness, prebuilt_elf
from emulator.backends.simavr.robot import SimavrRobot, board_randomness, elf_with_eeprom
from emulator.backends.simavr.wiring import RELEASED, BoardWiring, PinState, board_wiring, decode_pins

__all__ = [
    "BAUD",
    "HANDLER_FLAG",
    "MCU",
    "PHYSICS_US",
    "RELEASED",
    "BoardWiring",
    "Harness",
    "PinState",
    "PlantLoop",
    "SimTruth",
    "SimavrError",
    "SimavrRobot",
    "board_randomness",
    "board_wiring",
    "build_harness",
    "decode_pins",
    "elf_with_eeprom",
    "prebuilt_elf",
]
