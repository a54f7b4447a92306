// The byte stream the firmware core talks over.
//
// On an Arduino it is the core's own Stream (HardwareSerial, SoftwareSerial, USB CDC...), so a
// sketch passes `Serial`. Everywhere else (g++ for tests and the simulator library) it is the
// minimal interface in native/stream.h with only what the core uses.
#ifndef ROVERLINK_HAL_STREAM_H
#define ROVERLINK_HAL_STREAM_H

#if defined(ARDUINO)
#include <Arduino.h>

namespace roverlink {
typedef ::Stream Stream;
}  // namespace roverlink
#else
#include "native/stream.h"
#endif

#endif  // ROVERLINK_HAL_STREAM_H
