#if defined(ARDUINO_ARCH_AVR)

#include "mcu.h"

#include <Arduino.h>
#include <avr/eeprom.h>

namespace roverlink {
namespace avr {

namespace {

bool eeprom_range_ok(uint16_t address, uint16_t length) {
    return static_cast<uint32_t>(address) + length <= static_cast<uint32_t>(E2END) + 1u;
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
