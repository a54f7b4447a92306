// What the MCU itself provides to every board: EEPROM and entropy. DiffDriveBoard and
// AckermannBoard forward Board::eeprom_read/eeprom_write/entropy here, and so can a board of your
// own. (The boards derive from roverlink::Board directly rather than from a shared AVR base class:
// avr-gcc keeps every intermediate class's vtable in SRAM, 24 bytes each.)
#ifndef ROVERLINK_HAL_AVR_MCU_H
#define ROVERLINK_HAL_AVR_MCU_H

#if defined(ARDUINO_ARCH_AVR)

#include <stdint.h>

namespace roverlink {
namespace avr {

// EEPROM of the MCU (1 KB on the Uno, 4 KB on the Mega). False when the range does not exist;
// a write is read back and false when it does not match (worn-out cell, brown-out).
bool eeprom_read(uint16_t address, uint8_t* data, uint16_t length);
bool eeprom_write(uint16_t address, const uint8_t* data, uint16_t length);

// 32 bits mixed from the low bits of many ADC conversions of an unconnected analog pin (thermal
// and supply noise: the physical part) and the Timer0 counter (which only differs between boots
// as much as interrupt timing does). The core mixes this with an EEPROM boot counter, so two
// boots never share a boot_id even if the ADC happens to be quiet. Takes about 2 ms.
uint32_t adc_entropy(uint8_t unconnected_analog_pin);

// A pin as an input (with or without its pull-up) or as an output at a level, through its port
// registers with interrupts off. pinMode() and digitalWrite() do the same and also switch a
// timer's PWM off that pin, which costs ~400 bytes of flash; the encoders and the pulse timers,
// which manage their timers themselves, use these.
void pin_input(uint8_t pin, bool pullup);
void pin_output(uint8_t pin, bool high);

}  // namespace avr
}  // namespace roverlink

#endif  // ARDUINO_ARCH_AVR
#endif  // ROVERLINK_HAL_AVR_MCU_H
