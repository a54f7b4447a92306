#if defined(ARDUINO_ARCH_AVR)

#include "mcu.h"

#include <Arduino.h>
#include <avr/eeprom.h>
#include <util/atomic.h>

namespace roverlink {
namespace avr {

namespace {

bool eeprom_range_ok(uint16_t address, uint16_t length) {
    return static_cast<uint32_t>(address) + length <= static_cast<uint32_t>(E2END) + 1u;
}

// Sets the pin's DDR bit to `output` and its PORT bit to `high` (an input's pull-up).
void set_pin(uint8_t pin, bool output, bool high) {
    const uint8_t port = digitalPinToPort(pin);
    if (port == NOT_A_PIN) {
        return;
    }
    const uint8_t bit = digitalPinToBitMask(pin);
    volatile uint8_t* const ddr = portModeRegister(port);
    volatile uint8_t* const out = portOutputRegister(port);
    ATOMIC_BLOCK(ATOMIC_RESTORESTATE) {
        *out = static_cast<uint8_t>(high ? (*out | bit) : (*out & ~bit));  // the level first, then the direction
        *ddr = static_cast<uint8_t>(output ? (*ddr | bit) : (*ddr & ~bit));
    }
}

}  // namespace

bool eeprom_read(uint16_t address, uint8_t* data, uint16_t length) {
    if (!eeprom_range_ok(address, length)) {
        return false;
    }
    eeprom_read_block(data, reinterpret_cast<const void*>(address), length);
    return true;
}

bool eeprom_write(uint16_t address, const uint8_t* data, uint16_t length) {
    if (!eeprom_range_ok(address, length)) {
        return false;
    }
    // update, not write: cells that already hold the byte are not rewritten (endurance is
    // 100,000 cycles per cell, and SAVE_CONFIG of an unchanged config then costs nothing).
    eeprom_update_block(data, reinterpret_cast<void*>(address), length);
    for (uint16_t i = 0; i < length; ++i) {
        if (eeprom_read_byte(reinterpret_cast<const uint8_t*>(address + i)) != data[i]) {
            return false;
        }
    }
    return true;
}

void pin_input(uint8_t pin, bool pullup) { set_pin(pin, false, pullup); }

void pin_output(uint8_t pin, bool high) { set_pin(pin, true, high); }

uint32_t adc_entropy(uint8_t unconnected_analog_pin) {
    // FNV-1a over the samples: cheap, and every input bit reaches every output bit.
    uint32_t hash = 2166136261UL;
    for (uint8_t i = 0; i < 16; ++i) {  // 16 conversions of 112 us
        const uint16_t sample = static_cast<uint16_t>(analogRead(unconnected_analog_pin));
        const uint8_t mixed = static_cast<uint8_t>(sample ^ (sample >> 8) ^ TCNT0);
        hash = (hash ^ mixed) * 16777619UL;
    }
    return hash;
}

}  // namespace avr
}  // namespace roverlink

#endif  // ARDUINO_ARCH_AVR
