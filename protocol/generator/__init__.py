"""The code generator: reads protocol/spec/*.toml, checks it, and renders every generated file.

`python -m protocol generate | check | hash` runs it (protocol/__main__.py). The SDK and the
emulator use what it wrote (protocol/generated, protocol.codec); at run time only the robot-file
reader imports it, for the boards' pin rules (`wiring.py`, over hardware.toml).
"""
