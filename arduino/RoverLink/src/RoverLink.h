// RoverLink Arduino library: include this header in a sketch.
#ifndef ROVERLINK_H
#define ROVERLINK_H

#include "codec/codec.h"

#endif  // ROVERLINK_H
