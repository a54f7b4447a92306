// DO NOT EDIT: generated from protocol/spec/roverlink.toml by `python -m protocol generate`.
// spec hash: 0xBDF31659
// The firmware version reported in IDENTITY.firmware_version.
#ifndef ROVERLINK_CORE_VERSION_H
#define ROVERLINK_CORE_VERSION_H

#define ROVERLINK_FIRMWARE_VERSION_MAJOR 0
#define ROVERLINK_FIRMWARE_VERSION_MINOR 1
#define ROVERLINK_FIRMWARE_VERSION_PATCH 0
#define ROVERLINK_FIRMWARE_VERSION "0.1.0"

#endif  // ROVERLINK_CORE_VERSION_H
