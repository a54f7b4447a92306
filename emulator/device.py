"""The emulated robot: firmware model + plant + serial line + faults, on a virtual clock.

    emu = Emulator("diffdrive-tb6612", seed=0)
    emu.host_write(encode_frame(messages.Hello(...), seq=0))
    emu.advance(0.05)                 # 50 ms of virtual time, as fast as the CPU allows
    reply = emu.host_read()           # bytes the MCU sent that have reached the host by now
    emu.truth.plant.x_m               # ground truth

Scheduling (all on the VirtualClock, so one seed and one input give one output):

* physics every `physics_dt_us` (1 ms), fixed step;
* the firmware's control tick every 10 ms of *MCU* time (its crystal may drift: `drift_ppm`);
* host bytes reach the firmware when they arrive at the MCU (after baud pacing and latency); the
  firmware handles a frame when its delimiter arrives, as its loop() would within microseconds;
* an EEPROM write stalls the firmware's loop for 3.4 ms per changed byte: the next tick runs late,
  once, and the missed ones are skipped (the C++ core's rule); host bytes wait in the 63-byte
  receive buffer and are lost beyond it (silently, as the Arduino core does; the truth counts them).

Resets: power-on and brown-out start the sketch after `power_on_ms`; an external or DTR reset
runs the bootloader first (`bootloader_ms`, a few garbage bytes on the line). Every boot is a new
Firmware object (RAM lost); the EEPROM (config, boot counter) persists.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Callable
from typing import Any

from emulator.clock import PRIORITY_PHYSICS, PRIORITY_RX, PRIORITY_TICK, Timer, VirtualClock
from emulator.errors import EmulatorValueError
from emulator.faults import FaultSpec
from emulator.firmware.config import IMAGE_ADDR, Gains, encode_image
from emulator.firmware.core import Firmware
from emulator.firmware.statemachine import SessionEvent
from emulator.firmware.tick import TICK_US
from emulator.injection import MAX_FAULT_LOG, FaultInjection, ResetKind, checked_board_options
from emulator.line import SerialLink
from emulator.physical import Physical
from emulator.plant.plant import WHEEL_CHANNELS, Plant
from emulator.profiles import EmulatorProfile, get_profile
from emulator.rng import Streams
from emulator.truth import FaultRecord, McuTruth, PlantTruth, Truth, WheelTruth
from emulator.world.world import World
from protocol.generated.enums import Board as BoardId
from protocol.generated.hardware import MotorMode

_U32 = 1 << 32
__all__ = ["MAX_FAULT_LOG", "Emulator", "McuPhase", "ResetKind", "saved_eeprom_image"]


class McuPhase(enum.Enum):
    RESET = "reset"
    BOOTLOADER = "bootloader"
    RUNNING = "running"


class _McuBoard:
    """The firmware's Board for one boot: pins to the plant, micros() from the virtual clock."""

    def __init__(self, emu: Emulator) -> None:
        self._emu = emu
        self.eeprom_size = len(emu.eeprom)
        self.stall_us = 0
        """Loop time consumed inside the current firmware call (EEPROM writes)."""
        self._encoder_base = emu.plant.encoder_counts()

    def micros(self) -> int:
        emu = self._emu
        elapsed = emu.mcu_elapsed_us(emu.clock.now_us + self.stall_us)
        res = emu.profile.plant.timing.micros_resolution_us
        return (emu.micros_offset_us + elapsed - elapsed % res) % _U32

    def read_encoders(self) -> list[int]:
        counts = self._emu.plant.encoder_counts()
        return [counts[w] - self._encoder_base[w] for w in range(WHEEL_CHANNELS)]

    def zero_encoders(self) -> None:
        self._encoder_base = self._emu.plant.encoder_counts()

    def drive(self, wheel: int, effort_permille: int, mode: MotorMode) -> None:
        self._emu.plant.drive(wheel, effort_permille, mode)

    def esc_pulse(self, pulse_us: int) -> None:
        self._emu.plant.esc_pulse(pulse_us)

    def steering_pulse(self, pulse_us: int) -> None:
        self._emu.plant.steering_pulse(pulse_us)

    def lights(self, mask: int) -> None:
        self._emu.plant.lights(mask)

    def eeprom_read(self, address: int, length: int) -> bytes:
        return bytes(self._emu.eeprom[address : address + length])

    def eeprom_write(self, address: int, data: bytes) -> bool:
        emu = self._emu
        per_byte = round(emu.profile.plant.timing.eeprom_write_ms * 1000)
        for i, byte in enumerate(data):
            at = address + i
            if emu.eeprom[at] == byte:
                continue  # EEPROM.update(): unchanged cells are not programmed
            self.stall_us += per_byte
            if emu.eeprom_failing:
                continue  # a worn cell keeps its old value: the read-back will not match
            emu.pending_eeprom.append((emu.clock.now_us + self.stall_us, at, emu.eeprom[at]))
            emu.eeprom[at] = byte
        return True

    def entropy(self) -> int:
        return self._emu.streams.get("entropy").getrandbits(32)

    def serial_write(self, data: bytes) -> None:
        emu = self._emu
        emu.m2h.send(data, emu.clock.now_us + self.stall_us)  # the host polls: nothing to schedule


def saved_eeprom_image(profile: EmulatorProfile) -> tuple[int, bytes]:
    """(address, bytes) of the EEPROM image a board whose defaults were saved holds (`eeprom="saved"`):
    the profile's config and PID defaults in the C++ core's layout."""
    robot = profile.robot
    return IMAGE_ADDR, encode_image(robot.config, [Gains.of(robot.pid)] * WHEEL_CHANNELS)


class Emulator(FaultInjection):
    """A RoverLink robot in software. See the module docstring and docs/emulator.md."""

    def __init__(
        self,
        profile: str | EmulatorProfile = "diffdrive-tb6612",
        seed: int = 0,
        *,
        faults: str | FaultSpec | None = None,
        baud: int = 115200,
        latency_us: int = 1000,
        jitter_us: int = 0,
        drift_ppm: float = 0.0,
        physics_dt_us: int = 1000,
        micros_offset_us: int = 0,
        eeprom: str = "blank",
        bootloader_ms: int | None = None,
        board_id: BoardId = BoardId.EMULATOR,
        physical: Physical | None = None,
        stand: bool = False,
    ) -> None:
        self.profile = get_profile(profile) if isinstance(profile, str) else profile
        if physical is not None:
            self.profile = self.profile.with_physical(physical)
        if not (isinstance(baud, int) and 300 <= baud <= 2_000_000):
            raise EmulatorValueError("baud", baud, "an integer in 300..2000000")
        self.bootloader_ms = checked_board_options(self.profile, latency_us, drift_ppm, bootloader_ms)
        if not (isinstance(physics_dt_us, int) and 100 <= physics_dt_us <= TICK_US and TICK_US % physics_dt_us == 0):
            raise EmulatorValueError("physics_dt_us", physics_dt_us, f"a divisor of {TICK_US} in 100..{TICK_US} us")
        if eeprom not in ("blank", "saved"):
            raise EmulatorValueError("eeprom", eeprom, "'blank' (a new board) or 'saved' (defaults saved)")
        self.seed = seed
        self.board_id = board_id
        self.clock = VirtualClock()
        self.realtime_us: Callable[[], int] | None = None
        """On the real clock (set by EmulatorTransport): the emulated time that matches the wall clock
        now. A device that renders (the camera) skips what is already stale when it falls behind."""
        self.streams = Streams(seed)
        self.physics_dt_us = physics_dt_us
        self.drift_ppb = round(drift_ppm * 1000)
        self.micros_offset_us = micros_offset_us & 0xFFFFFFFF
        timing = self.profile.plant.timing
        self.plant = Plant(self.profile, physics_dt_us / 1e6)
        self.faults: list[FaultRecord] = []
        self.faults_dropped = 0
        self.link = SerialLink(self.streams, baud, latency_us, log=self._log, jitter_us=jitter_us)
        self.h2m = self.link.h2m
        self.m2h = self.link.m2h
        self.eeprom = bytearray(b"\xff" * timing.eeprom_bytes)
        if eeprom == "saved":
            address, image = saved_eeprom_image(self.profile)
            self.eeprom[address : address + len(image)] = image
        self.eeprom_failing = False
        self.pending_eeprom: list[tuple[int, int, int]] = []
        self.firmware: Firmware | None = None
        self.phase = McuPhase.RESET
        self.resets = 0
        self.boot_ids: list[int] = []
        self.bytes_lost_not_running = 0
        self._board: _McuBoard | None = None
        self._app_start_us = 0
        self._tick_index = 0
        self._last_tick_index = 0
        self.ticks_skipped = 0
        """Control ticks the firmware skipped because its loop was stalled (EEPROM writes)."""
        self.rx_overrun_bytes = 0
        """Host bytes lost because the MCU's receive buffer was full (the firmware cannot know)."""
        self._tick_timer: Timer | None = None
        self._boot_timer: Timer | None = None
        self._busy_until = 0
        self._busy_from = 0
        self._rx_deferred: Timer | None = None
        self.world: World | None = None
        """The robot's surroundings (emulator.sensors.attach): collisions stop the plant."""
        self.sensors: Any = None
        """The SensorRig attached with emulator.sensors.attach, else None."""
        if stand:
            self.plant.vehicle.set_lifted(True)
        self.clock.call_at(physics_dt_us, self._physics, PRIORITY_PHYSICS)
        self._begin_reset(ResetKind.POWER_ON, hold_us=0)
        self.apply_faults(faults or FaultSpec())

    # == time ======================================================================================
    @property
    def now_us(self) -> int:
        return self.clock.now_us

    def advance(self, seconds: float) -> None:
        """Run `seconds` of virtual time."""
        if not (math.isfinite(seconds) and seconds >= 0):
            raise EmulatorValueError("seconds", seconds, "a finite number >= 0")
        self.clock.advance(round(seconds * 1e6))

    def advance_us(self, us: int) -> None:
        self.clock.advance(us)

    def advance_to_us(self, time_us: int) -> None:
        self.clock.advance_to(time_us)

    def run_until(self, predicate: Callable[[], bool], timeout_s: float, step_us: int = 1000) -> bool:
        """Advance in `step_us` steps until `predicate()` holds or `timeout_s` of virtual time pass."""
        deadline = self.clock.now_us + round(timeout_s * 1e6)
        while not predicate():
            if self.clock.now_us >= deadline:
                return False
            self.clock.advance_to(min(deadline, self.clock.now_us + step_us))
        return True

    def mcu_elapsed_us(self, time_us: int) -> int:
        """MCU microseconds since the running sketch started (crystal drift applied)."""
        return (time_us - self._app_start_us) * (1_000_000_000 + self.drift_ppb) // 1_000_000_000

    def _virtual_time_of_mcu(self, mcu_us: int) -> int:
        return self._app_start_us + -(-mcu_us * 1_000_000_000 // (1_000_000_000 + self.drift_ppb))

    # == the host's end of the line ================================================================
    def host_write(self, data: bytes) -> None:
        """Bytes from the host, sent now; they reach the MCU after pacing and latency."""
        for wake in self.h2m.send(bytes(data), self.clock.now_us):
            self.clock.call_at(wake, self._on_rx, PRIORITY_RX)

    def host_read(self) -> bytes:
        """Every byte from the MCU that has reached the host by now."""
        return self.m2h.receive(self.clock.now_us)

    # == physics ===================================================================================
    def _physics(self) -> None:
        now = self.clock.now_us
        world = self.world
        if world is not None:
            world.before_step(self.plant)
        self.plant.step(now)
        if world is not None:
            world.after_step(self.plant, now)
        if self.pending_eeprom and self.pending_eeprom[0][0] <= now:
            self.pending_eeprom = [p for p in self.pending_eeprom if p[0] > now]
        self.clock.call_at(now + self.physics_dt_us, self._physics, PRIORITY_PHYSICS)

    # == the MCU ===================================================================================
    def _begin_reset(self, kind: ResetKind, hold_us: int) -> None:
        now = self.clock.now_us
        fw = self.firmware
        if fw is not None:
            fw.session.fire(SessionEvent.RESET)  # the table's RESET row: BOOT, motors safe
        self.firmware = None
        self._board = None
        for timer in (self._tick_timer, self._boot_timer, self._rx_deferred):
            if timer is not None:
                timer.cancel()
        self._tick_timer = self._boot_timer = self._rx_deferred = None
        self._busy_until = 0
        # An EEPROM write cut short: cells not yet programmed keep their old contents.
        for done_us, address, old in reversed(self.pending_eeprom):
            if done_us > now:
                self.eeprom[address] = old
        self.pending_eeprom = []
        bootloader = kind in (ResetKind.EXTERNAL, ResetKind.DTR)
        self.link.mcu_reset(now, bootloader=bootloader)
        self.plant.pins_released()
        self.phase = McuPhase.RESET
        if kind is not ResetKind.POWER_ON:
            self.resets += 1
        if kind is ResetKind.BROWN_OUT:
            self.plant.power_cycle()
        if bootloader:
            self.phase = McuPhase.BOOTLOADER
            start = now + self.bootloader_ms * 1000
        else:
            start = now + hold_us + self.profile.plant.timing.power_on_ms * 1000
        self._boot_timer = self.clock.call_at(start, self._start_app, PRIORITY_TICK)

    def _start_app(self) -> None:
        self._boot_timer = None
        self.phase = McuPhase.RUNNING
        self._app_start_us = self.clock.now_us
        self._busy_until = 0
        # Host bytes that arrived in reset are lost; Serial.begin() makes the adapter read a break.
        self.bytes_lost_not_running += self.link.sketch_started(self.clock.now_us)
        board = _McuBoard(self)
        self._board = board
        fw = Firmware(board, self.profile.robot, self.board_id)
        self.firmware = fw
        fw.setup()
        self.boot_ids.append(fw.boot_id)
        self._after_call()
        self._tick_index = 1
        self._last_tick_index = 0
        self._schedule_tick()

    def _schedule_tick(self) -> None:
        at = self._virtual_time_of_mcu(self._tick_index * TICK_US)
        self._tick_timer = self.clock.call_at(at, self._on_tick, PRIORITY_TICK)

    def _on_tick(self) -> None:
        fw = self.firmware
        if fw is None:
            return
        now = self.clock.now_us
        if now < self._busy_until:
            # The loop is stalled (EEPROM write): the tick runs when it resumes.
            self._tick_timer = self.clock.call_at(self._busy_until, self._on_tick, PRIORITY_TICK)
            return
        self._process_rx()  # bytes that waited in the buffer are read before the tick
        if self.firmware is not fw:
            return
        # A late tick (the loop was stalled) runs once and skips the grid points it missed, as
        # the C++ core does; its speed measurement spans them all.
        reached = self.mcu_elapsed_us(self.clock.now_us) // TICK_US
        periods = max(1, reached - self._last_tick_index)
        self.ticks_skipped += periods - 1
        self._last_tick_index = max(reached, self._tick_index)
        fw.tick(periods)
        self._after_call()
        self._tick_index = self._last_tick_index + 1
        self._schedule_tick()

    def _after_call(self) -> None:
        """Account the loop time the firmware just spent programming EEPROM."""
        board = self._board
        if board is not None and board.stall_us:
            self._busy_from = self.clock.now_us
            self._busy_until = self.clock.now_us + board.stall_us
            board.stall_us = 0

    def _on_rx(self) -> None:
        if self.phase is not McuPhase.RUNNING:
            self._drain_rx_while_not_running()
            return
        if self.clock.now_us < self._busy_until:
            if self._rx_deferred is None:
                self._rx_deferred = self.clock.call_at(self._busy_until, self._on_rx_resumed, PRIORITY_RX)
            return
        self._process_rx()

    def _on_rx_resumed(self) -> None:
        self._rx_deferred = None
        self._on_rx()

    def _process_rx(self) -> None:
        fw = self.firmware
        if fw is None:
            return
        timed = self.h2m.receive_timed(self.clock.now_us)
        if not timed:
            return
        busy_from, busy_until = self._busy_from, self._busy_until
        capacity = self.profile.plant.timing.rx_buffer_bytes
        data = bytearray()
        waited = 0
        overruns = 0
        for arrival, byte in timed:
            if busy_from < arrival <= busy_until:
                # Arrived while the loop was stalled: only the ring buffer's worth survives.
                waited += 1
                if waited > capacity:
                    overruns += 1
                    continue
            data.append(byte)
        if overruns:
            # The Arduino core drops them silently: LINK_STATS.rx_overruns stays 0, as on a board.
            self.rx_overrun_bytes += overruns
            self._log(self.clock.now_us, "rx_overrun", f"{overruns} bytes lost: receive buffer full during a stall")
        fw.on_bytes(bytes(data))
        self._after_call()

    def _drain_rx_while_not_running(self) -> None:
        lost = self.h2m.receive(self.clock.now_us)
        self.bytes_lost_not_running += len(lost)

    # == faults (the rest: emulator.injection.FaultInjection) ====================================
    def _h2m_wake(self, time_us: int) -> None:
        self.clock.call_at(time_us, self._on_rx, PRIORITY_RX)

    def fail_eeprom(self, failing: bool = True) -> None:
        """Worn EEPROM: writes no longer change the cells (SAVE_CONFIG gets EEPROM_ERROR)."""
        self.eeprom_failing = failing
        self._log(self.clock.now_us, "eeprom_fail" if failing else "eeprom_ok", "")

    def set_stand(self, on: bool = True) -> None:
        """Lift the robot onto a stand (wheels in the air, the body held still) or put it back down."""
        self.plant.vehicle.set_lifted(on)
        self._log(self.clock.now_us, "stand", "lifted" if on else "on the ground")

    # == ground truth ==============================================================================
    @property
    def truth(self) -> Truth:
        return Truth(
            time_us=self.clock.now_us,
            profile=self.profile.name,
            seed=self.seed,
            mcu=McuTruth(
                phase=self.phase.value,
                resets=self.resets,
                boot_ids=tuple(self.boot_ids),
                bytes_lost_not_running=self.bytes_lost_not_running,
                rx_overrun_bytes=self.rx_overrun_bytes,
                ticks_skipped=self.ticks_skipped,
                eeprom_failing=self.eeprom_failing,
            ),
            firmware=self.firmware.snapshot() if self.firmware is not None else None,
            plant=self._plant_truth(),
            host_to_mcu=self.h2m.truth(),
            mcu_to_host=self.m2h.truth(),
            faults=tuple(self.faults),
            world=self.world.truth(self.plant) if self.world is not None else None,
        )

    def _plant_truth(self) -> PlantTruth:
        plant = self.plant
        v = plant.vehicle
        r = self.profile.wheel_radius_m
        wheels = []
        for unit in plant.units:
            m = unit.motor
            enc = unit.encoder
            duty = m.duty
            if plant.esc is not None:
                duty = plant.esc.throttle
            wheels.append(
                WheelTruth(
                    rim_speed_mm_s=unit.omega_rad_s * r * 1000,
                    ground_speed_mm_s=(v.v_m_s - unit.y_m * v.wz_rad_s) * 1000,
                    angle_rad=unit.angle_rad,
                    revolutions=unit.angle_rad / (2 * math.pi),
                    duty=duty,
                    mode=m.mode,
                    voltage_v=m.voltage_v,
                    current_a=m.current_a,
                    torque_nm=unit.torque_nm,
                    encoder_edges=enc.count if enc is not None else 0,
                    encoder_connected=enc.connected if enc is not None else False,
                    stalled=unit.stalled,
                    slipping=unit.slipping,
                )
            )
        servo, esc = plant.servo, plant.esc
        return PlantTruth(
            x_m=v.x_m,
            y_m=v.y_m,
            theta_rad=v.theta_rad,
            speed_m_s=v.v_m_s,
            yaw_rate_rad_s=v.wz_rad_s,
            distance_m=v.distance_m,
            wheels=tuple(wheels),
            steering_rad=servo.wheel_angle_rad if servo is not None else 0.0,
            servo_deg=servo.angle_deg if servo is not None else None,
            servo_pulse_us=servo.pulse_us if servo is not None else None,
            esc_state=esc.state if esc is not None else None,
            esc_pulse_us=esc.pulse_us if esc is not None else None,
            esc_neutral_us=esc.learned_neutral_us if esc is not None else None,
            leds=plant.leds.states(),
            led_toggles=tuple(plant.leds.toggles),
            traction_mu=v.mu,
            on_stand=v.lifted,
        )
