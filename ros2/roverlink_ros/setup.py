"""The roverlink_ros ament_python package: the `roverlink` executable and the bringup launch file.

Nothing of RoverLink is copied: the executable runs `roverlink.commands.ros2:main` from the
RoverLink installed in the active virtual environment; the launch and parameters files are
installed from examples/ros2 of the checkout this folder belongs to (docs/ros2.md).
"""

import os
import xml.etree.ElementTree as ET
from pathlib import Path

from setuptools import setup

PACKAGE = "roverlink_ros"
HERE = Path(__file__).resolve().parent
# Relative to this folder: setuptools refuses absolute data_files sources.
EXAMPLES = Path(os.path.relpath(HERE.parents[1] / "examples" / "ros2", HERE))
CONFIG_FILES = ("roverlink.yaml", "slam_toolbox.yaml", "nav2.yaml")
# Every reference robot's parameters folder (examples/ros2/<robot>/, one per protocol/robots/<robot>.toml).
ROBOTS = sorted(p.parent.name for p in (HERE / EXAMPLES).glob(f"*/{CONFIG_FILES[0]}"))
# package.xml carries the release's version and licence (set from the spec by `python -m protocol generate`).
MANIFEST = ET.parse(HERE / "package.xml").getroot()

os.chdir(HERE)  # the relative paths above, wherever colcon runs this from
setup(
    name=PACKAGE,
    version=MANIFEST.findtext("version"),
    packages=[],
    data_files=[
        ("share/ament_index/resource_index/packages", [f"resource/{PACKAGE}"]),
        (f"share/{PACKAGE}", ["package.xml"]),
        (f"share/{PACKAGE}/launch", [str(EXAMPLES / "bringup.launch.py")]),
        *((f"share/{PACKAGE}/config/{robot}", [str(EXAMPLES / robot / f) for f in CONFIG_FILES]) for robot in ROBOTS),
    ],
    install_requires=["setuptools"],
    zip_safe=True,
    maintainer="RoverLink",
    maintainer_email="roverlink@example.invalid",
    description="The RoverLink ROS 2 node as a ROS package (ros2 run / ros2 launch).",
    license=MANIFEST.findtext("license"),
    entry_points={"console_scripts": ["roverlink = roverlink.commands.ros2:main"]},
)
