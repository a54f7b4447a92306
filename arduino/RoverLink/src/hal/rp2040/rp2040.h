// The RP2040 hardware layer (Raspberry Pi Pico), register-level: include through <RoverLink.h>
// in a build that defines ROVERLINK_ARCH_RP2040 (`roverlink firmware build` for board = "pico").
#ifndef ROVERLINK_HAL_RP2040_RP2040_H
#define ROVERLINK_HAL_RP2040_RP2040_H

#if defined(ROVERLINK_ARCH_RP2040)

#include "board.h"
#include "clocks.h"
#include "io.h"
#include "uart_stream.h"
#include "watchdog.h"

#endif  // ROVERLINK_ARCH_RP2040
#endif  // ROVERLINK_HAL_RP2040_RP2040_H
