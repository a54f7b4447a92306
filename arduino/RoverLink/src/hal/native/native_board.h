// A Board for native builds (unit tests, the simulator library): simulated time set by the test,
// encoder counters the test sets, every output recorded, a 1 KB in-memory EEPROM that can be
// corrupted or made to fail, and deterministic "noise" from a seed.
#ifndef ROVERLINK_HAL_NATIVE_BOARD_H
#define ROVERLINK_HAL_NATIVE_BOARD_H

#if !defined(ARDUINO)

#include <stddef.h>
#include <stdint.h>

#include "../board.h"

namespace roverlink {

class NativeBoard final : public Board {
public:
    static const uint16_t EEPROM_SIZE = 1024;  // an ATmega328P's

    explicit NativeBoard(uint32_t seed = 1);

    // -- Board --------------------------------------------------------------------------------
    uint32_t micros() override { return micros_; }
    void read_encoders(int32_t counts[proto::WHEEL_COUNT]) override;
    void zero_encoders() override;
    void drive(uint8_t wheel, int16_t effort_permille, MotorMode mode) override;
    void esc_pulse(uint16_t pulse_us) override;
    void steering_pulse(uint16_t pulse_us) override;
    void lights(uint8_t mask) override;
    bool eeprom_read(uint16_t address, uint8_t* data, uint16_t length) override;
    bool eeprom_write(uint16_t address, const uint8_t* data, uint16_t length) override;
    uint32_t entropy() override;

    // -- test controls ------------------------------------------------------------------------
    void set_micros(uint32_t us) { micros_ = us; }
    void advance_micros(uint32_t us) { micros_ += us; }
    void set_encoder(uint8_t wheel, int32_t count);
    void add_encoder(uint8_t wheel, int32_t delta);  // wraps like a 32-bit hardware counter
    int32_t encoder(uint8_t wheel) const;

    // Power cycle: clock, encoder counters and outputs back to their reset values. The EEPROM
    // and the noise generator's state survive (so a reboot never repeats the last one's noise).
    void power_cycle();

    // EEPROM faults.
    void erase_eeprom();                                   // every byte 0xFF, as shipped
    void corrupt_eeprom(uint16_t address, uint8_t xor_mask = 0xFF);
    void set_eeprom_write_fails(bool fail) { eeprom_write_fails_ = fail; }
    // Writes that "succeed" but store this byte pattern XORed in (a failing cell); 0: off.
    void set_eeprom_write_xor(uint8_t mask) { eeprom_write_xor_ = mask; }
    const uint8_t* eeprom() const { return eeprom_; }

    // -- recorded outputs ---------------------------------------------------------------------
    struct Motor {
        int16_t effort;   // last effort passed to drive()
        MotorMode mode;   // last mode
        uint32_t calls;   // drive() calls for this wheel
    };
    const Motor& motor(uint8_t wheel) const { return motors_[wheel < proto::WHEEL_COUNT ? wheel : 0]; }
    uint16_t esc_us() const { return esc_us_; }
    uint16_t steering_us() const { return steering_us_; }
    uint8_t lights_mask() const { return lights_; }
    uint32_t esc_calls() const { return esc_calls_; }
    uint32_t steering_calls() const { return steering_calls_; }
    uint32_t lights_calls() const { return lights_calls_; }
    uint32_t eeprom_writes() const { return eeprom_writes_; }        // eeprom_write() calls
    uint32_t eeprom_bytes_written() const { return eeprom_bytes_written_; }
    uint32_t zero_encoder_calls() const { return zero_calls_; }

private:
    void reset_outputs();

    uint32_t micros_;
    int32_t counts_[proto::WHEEL_COUNT];
    Motor motors_[proto::WHEEL_COUNT];
    uint16_t esc_us_;
    uint16_t steering_us_;
    uint8_t lights_;
    uint32_t esc_calls_;
    uint32_t steering_calls_;
    uint32_t lights_calls_;
    uint32_t zero_calls_;
    uint32_t eeprom_writes_;
    uint32_t eeprom_bytes_written_;
    bool eeprom_write_fails_;
    uint8_t eeprom_write_xor_;
    uint32_t noise_;
    uint8_t eeprom_[EEPROM_SIZE];
};

}  // namespace roverlink

#endif  // !ARDUINO

#endif  // ROVERLINK_HAL_NATIVE_BOARD_H
