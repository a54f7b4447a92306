"""The sketch `roverlink firmware sketch|build --robot FILE` writes speaks of the user's file: its
first comment is made from the file, and the code's comments name the file, not the reference robot's."""

from __future__ import annotations

from pathlib import Path

from protocol.robotfile import load, reference_path
from roverlink.firmware.robot import write_sketch


def test_the_sketch_names_the_users_file_and_none_of_the_reference_robots_facts(tmp_path: Path) -> None:
    text = reference_path("picar").read_text(encoding="utf-8")
    path = tmp_path / "mycar.toml"
    assert text.count('name = "picar"') == 1
    path.write_text(text.replace('name = "picar"', 'name = "mycar"'), encoding="utf-8")
    robot = load(path)
    sketch = write_sketch(robot, tmp_path / "MyCar")
    ino = (sketch / "MyCar.ino").read_text(encoding="utf-8") if sketch.is_dir() else sketch.read_text("utf-8")
    assert ino.startswith("// mycar: ackermann drive")
    assert "picar.toml" not in ino and "generated from mycar.toml" in ino
