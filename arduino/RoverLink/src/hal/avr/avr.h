// The AVR hardware layer (Arduino Uno, Mega 2560): include through <RoverLink.h>.
#ifndef ROVERLINK_HAL_AVR_AVR_H
#define ROVERLINK_HAL_AVR_AVR_H

#if defined(ARDUINO_ARCH_AVR)

#include "ackermann_board.h"
#include "diff_drive_board.h"
#include "encoder.h"
#include "lights.h"
#include "mcu.h"
#include "motors.h"
#include "quadrature.h"
#include "rc_pulses.h"

#endif  // ARDUINO_ARCH_AVR
#endif  // ROVERLINK_HAL_AVR_AVR_H
