"""Seed inputs for the fuzz targets, from the golden vectors (protocol/vectors/*.json).

    python3 -m tests.firmware.fuzz.seeds OUT_DIR     # from the repository root; writes OUT_DIR/{decoder,firmware,config}/*

`make -C tests/firmware/fuzz corpus` runs this, then minimises the seeds together with what fuzzing found
into tests/firmware/fuzz/corpus/ (committed). The firmware seeds speak fuzz_firmware.cpp's operation
script: keep the encoding below in step with it.
"""

from __future__ import annotations

import json
import struct
import sys
from pathlib import Path

from protocol.codec.crc import crc16
from protocol.generated.messages import BY_ID, SetConfig, SetPid
from protocol.generated.profiles import PROFILES

ROOT = Path(__file__).resolve().parents[3]

VECTORS = ROOT / "protocol" / "vectors"
PROFILE_ORDER = ["diffdrive-tb6612", "diffdrive-bts7960", "picar"]  # tests/firmware/native/core/profiles.cpp
IMAGE_VERSION = 1  # arduino/RoverLink/src/core/config.h


def vectors() -> list[tuple[int, dict[str, object]]]:
    out = []
    for path in sorted(VECTORS.glob("*.json")):
        data = json.loads(path.read_text(encoding="utf-8"))
        out += [(int(data["msg_id"]), v) for v in data["vectors"]]
    return out


# -- fuzz_firmware.cpp's operations: (kind | arg << 3), operands ---------------------------------
def raw(data: bytes) -> bytes:
    out = b""
    for i in range(0, len(data), 32):
        part = data[i : i + 32]
        out += bytes([(len(part) - 1) << 3 | 0]) + part
    return out


def advance(ms: int) -> bytes:
    return bytes([30 << 3 | 3, ms - 1])  # arg 30: byte % 31 + 1 ms; ms <= 31


def hello() -> bytes:
    return bytes([0 << 3 | 2, 0, 0, 0, 0])  # mode STREAM, watchdog 0 (default), hz 0 (default)


def arm() -> bytes:
    return bytes([1 << 3 | 2])  # ARM with the live boot_id


def wheels(delta: int) -> bytes:
    return bytes([0 << 3 | 4, delta & 0xFF, delta & 0xFF])


def firmware_seeds() -> dict[str, bytes]:
    host = [(i, v) for i, v in vectors() if BY_ID[i].DIRECTION.value == "host_to_mcu"]
    seeds = {}
    for index, name in enumerate(PROFILE_ORDER):
        session = bytes([index]) + hello() + advance(20) + arm() + advance(20)
        frames = b"".join(bytes.fromhex(str(v["frame"])) for _, v in host)
        seeds[f"{name}-vectors"] = session + raw(frames) + advance(30) + wheels(20) + advance(30)
        diff = int(name != "picar")  # 1: SET_WHEEL_SPEEDS, 0: SET_ACKERMANN
        drive = b"".join(bytes([3 << 3 | 2, 0x2C, 0x01, 0x2C, 0x01, diff]) + advance(10) for _ in range(10))
        seeds[f"{name}-drive-then-silence"] = session + drive + wheels(40) + advance(31) * 12 + arm() + advance(20)
    return seeds


def decoder_seeds() -> dict[str, bytes]:
    frames = {f"{BY_ID[i].NAME.lower()}-{v['case']}": bytes.fromhex(str(v["frame"])) for i, v in vectors()}
    frames["stream"] = b"".join(frames.values())
    return frames


def image(config: bytes, pid: bytes) -> bytes:
    body = bytes([ord("R"), ord("L"), IMAGE_VERSION, SetConfig.CRC_EXTRA, SetPid.CRC_EXTRA]) + config
    for wheel in range(2):
        body += bytes([wheel]) + pid[1:]
    return body + struct.pack("<H", crc16(body))


def config_seeds() -> dict[str, bytes]:
    configs = {f"vector-{v['case']}": bytes.fromhex(str(v["payload"])) for i, v in vectors() if i == SetConfig.MSG_ID}
    configs |= {f"profile-{name}": p.config.pack() for name, p in PROFILES.items()}
    pid = next(bytes.fromhex(str(v["payload"])) for i, v in vectors() if i == SetPid.MSG_ID)
    return {name: bytes([k % 3 << 2]) + image(c, pid) for k, (name, c) in enumerate(sorted(configs.items()))}


def main(out: Path) -> None:
    for target, seeds in (("decoder", decoder_seeds()), ("firmware", firmware_seeds()), ("config", config_seeds())):
        folder = out / target
        folder.mkdir(parents=True, exist_ok=True)
        for name, data in seeds.items():
            (folder / name).write_bytes(data)
        print(f"{folder}: {len(seeds)} seeds")


if __name__ == "__main__":
    main(Path(sys.argv[1]))
