"""The code generator: reads protocol/spec/*.toml, checks it, and renders every generated file.

`python -m protocol generate | check | hash` runs it (protocol/__main__.py). Nothing at run time
imports it: the SDK and the emulator use only what it wrote (protocol/generated, protocol.codec).
"""
