"""Golden bytes written from the public protocol documents (docs/sensors.md names them), checked
against both sides: the emulator's encoders produce them, the SDK's parsers decode them."""

from __future__ import annotations

import math

import numpy as np
import pytest

from emulator.sensors import rplidar as emu_rplidar
from emulator.sensors import wit as emu_wit
from emulator.sensors import ydlidar as emu_ydlidar
from emulator.sensors.lidar import LidarSamples
from emulator.sensors.mjpeg import Frame
from host_sdk.sensors import rplidar, wit, ydlidar
from host_sdk.sensors.mjpeg import MjpegParser

# -- RPLIDAR (Slamtec interface protocol, A1/A2) ------------------------------------------------------
DESCRIPTORS = {
    "scan": bytes.fromhex("a55a0500004081"),
    "info": bytes.fromhex("a55a1400000004"),
    "health": bytes.fromhex("a55a0300000006"),
    "samplerate": bytes.fromhex("a55a0400000015"),
}
# quality 15, start of a revolution, 0.5 deg (q6 32), 1000 mm (q2 4000)
NODE_START = bytes.fromhex("3d4100a00f")
# quality 20, not a start, 359.5 deg (q6 23008), 0 mm (no return)
NODE_NO_RETURN = bytes.fromhex("52c1b30000")


def test_rplidar_requests_and_descriptors_match_the_protocol() -> None:
    assert rplidar.request(rplidar.SCAN) == b"\xa5\x20"
    assert rplidar.request(rplidar.GET_HEALTH) == b"\xa5\x52"
    # EXPRESS_SCAN with its 5-byte payload: A5 82 05 00 00 00 00 00 22 (checksum = XOR of all)
    assert rplidar.request(0x02, bytes(5)) == bytes.fromhex("a58205000000000022")
    assert emu_rplidar.descriptor(5, 1, 0x81) == DESCRIPTORS["scan"]
    assert emu_rplidar.descriptor(20, 0, 0x04) == DESCRIPTORS["info"]
    assert emu_rplidar.descriptor(3, 0, 0x06) == DESCRIPTORS["health"]
    assert emu_rplidar.descriptor(4, 0, 0x15) == DESCRIPTORS["samplerate"]


def test_rplidar_node_bytes_both_ways() -> None:
    samples = LidarSamples(
        time_us=np.array([0, 500], dtype=np.int64),
        angle_deg=np.array([0.5, 359.5]),
        range_m=np.array([1.0, 0.0]),
        quality=np.array([15, 20], dtype=np.int64),
        start=np.array([True, False]),
        true_range_m=np.array([1.0, np.inf]),
    )
    assert emu_rplidar.encode_nodes(samples) == [NODE_START, NODE_NO_RETURN]
    parser = rplidar.RPLidarParser()
    filler = NODE_NO_RETURN * 60  # a start flag is believed once per 50 nodes or more
    parser.receive_data(DESCRIPTORS["scan"] + NODE_START + NODE_NO_RETURN + filler + NODE_START, t=1.0)
    (scan,) = parser.events()
    assert scan.angles_rad[:2].tolist() == pytest.approx([-math.radians(0.5), math.radians(0.5)])  # CW -> CCW
    assert scan.ranges_m[0] == pytest.approx(1.0)
    assert math.isnan(scan.ranges_m[1])
    assert scan.qualities[:2].tolist() == [15, 20]
    # 63 nodes arrived together at t = 1.0, 0.5 ms apart (the A1's standard sample duration).
    assert scan.times_s[:2].tolist() == pytest.approx([1.0 - 62 * 0.0005, 1.0 - 61 * 0.0005])


def test_rplidar_single_answers() -> None:
    parser = rplidar.RPLidarParser()
    info = DESCRIPTORS["info"] + bytes([0x18, 29, 1, 7]) + bytes(range(16))
    health = DESCRIPTORS["health"] + bytes([2, 0x34, 0x12])
    rate = DESCRIPTORS["samplerate"] + (508).to_bytes(2, "little") + (254).to_bytes(2, "little")
    parser.receive_data(info + health + rate)
    got = parser.events()
    assert got[0] == rplidar.DeviceInfo(0x18, (1, 29), 7, bytes(range(16)).hex().upper())
    assert got[1] == rplidar.DeviceHealth(2, 0x1234) and got[1].name == "error"
    assert got[2] == rplidar.SampleRate(508, 254)
    assert parser.sample_period_s == pytest.approx(508e-6)


# -- YDLIDAR (YDLidar-SDK communication protocol) -----------------------------------------------------
ZERO_PACKET = bytes.fromhex("aa55010153ae53aeab540000")  # the protocol document's example


def test_ydlidar_zero_packet_of_the_protocol_document() -> None:
    angle = (0xAE53 >> 1) / 64
    assert emu_ydlidar.encode_packet(1, np.array([angle]), np.array([0.0])) == ZERO_PACKET
    parser = ydlidar.YDLidarParser()
    parser.receive_data(DESCRIPTORS["scan"] + ZERO_PACKET)
    assert parser.counters.checksum_errors == 0 and parser.counters.points == 1


def test_ydlidar_distance_and_angle_correction_of_the_protocol_document() -> None:
    assert int.from_bytes(bytes.fromhex("e56f"), "little") / 4 == 7161.25
    # FSA 0x6FE5 -> 223.78 deg, LSA 0x79BD -> 243.47 deg; a 1000 mm sample is corrected by -6.7622 deg.
    assert pytest.approx(223.78, abs=0.01) == (0x6FE5 >> 1) / 64
    assert pytest.approx(243.47, abs=0.01) == (0x79BD >> 1) / 64
    corr = emu_ydlidar.angle_correction_deg(np.array([1000.0, 8000.0, 0.0]))
    assert corr.tolist() == pytest.approx([-6.7622, -7.8374, 0.0], abs=1e-3)


def test_ydlidar_packet_round_trip_with_the_correction() -> None:
    angles = 100.0 + 0.72 * np.arange(40)
    ranges = np.linspace(0.5, 3.0, 40)
    packet = emu_ydlidar.encode_packet(0, angles, ranges)
    assert len(packet) == 10 + 80
    parser = ydlidar.YDLidarParser()
    parser.receive_data(DESCRIPTORS["scan"] + ZERO_PACKET + packet + ZERO_PACKET, t=2.0)
    (scan,) = parser.events()
    expect = angles[:] + emu_ydlidar.angle_correction_deg(np.rint(ranges * 4000) / 4)
    got = np.degrees(-scan.angles_rad[1:]) % 360
    assert got == pytest.approx(expect, abs=0.02)
    assert scan.ranges_m[1:] == pytest.approx(ranges, abs=0.00025)


# -- WIT standard protocol --------------------------------------------------------------------------
ACC_1G = bytes.fromhex("55510000000000080000ae")  # az = 2048/32768*16 g = 1 g
ANGLE_YAW_90 = bytes.fromhex("55530000000000400000e8")  # yaw = 16384/32768*180 = 90 deg


def test_wit_packets_of_the_protocol_formulas() -> None:
    assert emu_wit.packet(0x51, bytes.fromhex("0000000000080000")) == ACC_1G
    parser = wit.WitParser()
    parser.receive_data(ACC_1G + ANGLE_YAW_90 + ACC_1G)
    events = parser.events()
    acc, angle, sample = events[0], events[1], events[2]
    assert isinstance(acc, wit.Acceleration) and acc.xyz == pytest.approx((0.0, 0.0, wit.G))
    assert isinstance(angle, wit.Angle) and angle.yaw == pytest.approx(math.pi / 2)
    assert isinstance(sample, wit.ImuSample) and sample.angle == pytest.approx((0.0, 0.0, math.pi / 2))


def test_wit_configuration_commands() -> None:
    assert wit.unlock() == bytes.fromhex("ffaa6988b5")
    assert wit.save() == bytes.fromhex("ffaa000000")
    assert wit.set_rate(200) == bytes.fromhex("ffaa030b00")
    assert wit.set_baud(115200) == bytes.fromhex("ffaa040600")
    assert wit.set_outputs("acc", "gyro", "angle", "mag", "quat") == bytes.fromhex("ffaa021e02")
    assert wit.calibrate("heading_zero") == bytes.fromhex("ffaa010400")
    assert wit.read_registers(0x3D) == bytes.fromhex("ffaa273d00")
    with pytest.raises(ValueError, match="rate_hz = 300 is not allowed"):
        wit.set_rate(300)


def test_mjpeg_part_round_trip() -> None:
    jpeg = b"\xff\xd8" + b"--not a boundary--" + b"\xff\xd9"
    parser = MjpegParser()
    data = b"HTTP/1.0 200 OK\r\n\r\n" + Frame(7, 1_500_000, jpeg).part() + Frame(9, 1_566_667, jpeg).part()
    for i in range(0, len(data), 5):
        parser.receive_data(data[i : i + 5], t=3.0)
    parts = parser.parts()
    assert [p.jpeg for p in parts] == [jpeg, jpeg]
    assert [p.frame for p in parts] == [7, 9]
    assert parts[0].timestamp == pytest.approx(1.5)


def test_wit_every_packet_type_decodes() -> None:
    import struct

    packets = [
        emu_wit.packet(0x50, bytes([25, 11, 25, 10, 30, 5]) + struct.pack("<H", 250)),
        emu_wit.packet(0x52, struct.pack("<4h", 0, 0, 16384, 2512)),  # 1000 deg/s about z, 25.12 C
        emu_wit.packet(0x54, struct.pack("<4h", 360, 105, 122, 2500)),
        emu_wit.packet(0x55, struct.pack("<4h", 1, 0, 1023, 0)),
        emu_wit.packet(0x56, struct.pack("<2i", 101325, 1234)),
        emu_wit.packet(0x57, struct.pack("<2i", 1134567890, 223012345)),  # 113 deg 45.6789', 22 deg 30.12345'
        emu_wit.packet(0x58, struct.pack("<2hi", 123, 9000, 36500)),
        emu_wit.packet(0x5A, struct.pack("<4h", 9, 150, 90, 120)),
        emu_wit.packet(0x59, struct.pack("<4h", 32767, 0, 0, 0)),
    ]
    parser = wit.WitParser()
    parser.receive_data(b"".join(packets), 5.0)
    events = [e for e in parser.events() if not isinstance(e, wit.ImuSample)]
    assert parser.counters.checksum_errors == 0 and len(events) == len(packets)
    time, gyro, mag, port, pressure, position, velocity, accuracy, quat = events
    assert isinstance(time, wit.TimePacket) and (time.year, time.hour, time.millisecond) == (2025, 10, 250)
    assert isinstance(gyro, wit.AngularVelocity) and gyro.xyz[2] == pytest.approx(math.radians(1000))
    assert gyro.temperature_c == pytest.approx(25.12)
    assert isinstance(mag, wit.Magnetic) and mag.xyz == (360, 105, 122)
    assert isinstance(port, wit.PortStatus) and port.d == (1, 0, 1023, 0)
    assert isinstance(pressure, wit.Pressure) and (pressure.pascal, pressure.height_m) == (101325, 12.34)
    assert isinstance(position, wit.GpsPosition)
    assert position.longitude_deg == pytest.approx(113 + 45.6789 / 60)
    assert position.latitude_deg == pytest.approx(22 + 30.12345 / 60)
    assert isinstance(velocity, wit.GpsVelocity) and (velocity.height_m, velocity.heading_deg) == (12.3, 90.0)
    assert velocity.speed_km_h == pytest.approx(36.5)
    assert isinstance(accuracy, wit.GpsAccuracy) and (accuracy.satellites, accuracy.hdop) == (9, 0.9)
    assert isinstance(quat, wit.Quaternion) and quat.wxyz[0] == pytest.approx(1.0, abs=1e-4)
