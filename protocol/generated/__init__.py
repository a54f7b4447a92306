# DO NOT EDIT: generated from protocol/spec/roverlink.toml by `python -m protocol generate`.
# spec hash: 0xBDF31659
"""Code generated from the RoverLink spec: constants, enums, messages, the session table, the construct oracle."""
