"""Writing a built firmware to a board through its bootloader (avrdude)."""

from __future__ import annotations

from pathlib import Path

from roverlink.firmware.boards import BoardSpec


def avrdude_command(board: BoardSpec, hex_file: Path, port: str, avrdude: str = "avrdude") -> list[str]:
    """The avrdude call that writes hex_file through the board's bootloader on `port`."""
    return [
        avrdude,
        "-p",
        board.mcu,
        "-c",
        board.programmer,
        "-P",
        port,
        "-b",
        str(board.baud),
        *board.avrdude_extra,
        "-U",
        f"flash:w:{hex_file}:i",
    ]
