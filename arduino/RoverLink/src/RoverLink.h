// RoverLink Arduino library: include this header in a sketch.
#ifndef ROVERLINK_H
#define ROVERLINK_H

#include "codec/codec.h"
#include "core/firmware.h"  // roverlink::Firmware, Robot, Board, Stream: the portable core
#include "hal/avr/avr.h"  // the AVR hardware layer; empty on other targets
#include "hal/rp2040/rp2040.h"  // the RP2040 hardware layer; empty on other targets

#endif  // ROVERLINK_H
