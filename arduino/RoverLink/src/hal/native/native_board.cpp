#if !defined(ARDUINO)

#include "native_board.h"

#include <string.h>

namespace roverlink {

NativeBoard::NativeBoard(uint32_t seed)
    : micros_(0),
      eeprom_writes_(0),
      eeprom_bytes_written_(0),
      eeprom_write_fails_(false),
      eeprom_write_xor_(0),
      noise_(seed ^ 0xA5A5F00Du) {
    if (noise_ == 0) {
        noise_ = 0x6D2B79F5u;  // xorshift needs a non-zero state
    }
    erase_eeprom();
    power_cycle();
}

void NativeBoard::reset_outputs() {
    for (uint8_t w = 0; w < proto::WHEEL_COUNT; ++w) {
        motors_[w].effort = 0;
        motors_[w].mode = MotorMode::COAST;
        motors_[w].calls = 0;
    }
    esc_us_ = 0;
    steering_us_ = 0;
    lights_ = 0;
    esc_calls_ = 0;
    steering_calls_ = 0;
    lights_calls_ = 0;
    zero_calls_ = 0;
}

void NativeBoard::power_cycle() {
    micros_ = 0;
    for (uint8_t w = 0; w < proto::WHEEL_COUNT; ++w) {
        counts_[w] = 0;
    }
    reset_outputs();
}

void NativeBoard::read_encoders(int32_t counts[proto::WHEEL_COUNT]) {
    for (uint8_t w = 0; w < proto::WHEEL_COUNT; ++w) {
        counts[w] = counts_[w];
    }
}

void NativeBoard::zero_encoders() {
    for (uint8_t w = 0; w < proto::WHEEL_COUNT; ++w) {
        counts_[w] = 0;
    }
    ++zero_calls_;
}

void NativeBoard::set_encoder(uint8_t wheel, int32_t count) {
    if (wheel < proto::WHEEL_COUNT) {
        counts_[wheel] = count;
    }
}

void NativeBoard::add_encoder(uint8_t wheel, int32_t delta) {
    if (wheel < proto::WHEEL_COUNT) {
        counts_[wheel] = static_cast<int32_t>(static_cast<uint32_t>(counts_[wheel]) + static_cast<uint32_t>(delta));
    }
}

int32_t NativeBoard::encoder(uint8_t wheel) const { return wheel < proto::WHEEL_COUNT ? counts_[wheel] : 0; }

void NativeBoard::drive(uint8_t wheel, int16_t effort_permille, MotorMode mode) {
    if (wheel >= proto::WHEEL_COUNT) {
        return;
    }
    motors_[wheel].effort = effort_permille;
    motors_[wheel].mode = mode;
    ++motors_[wheel].calls;
}

void NativeBoard::esc_pulse(uint16_t pulse_us) {
    esc_us_ = pulse_us;
    ++esc_calls_;
}

void NativeBoard::steering_pulse(uint16_t pulse_us) {
    steering_us_ = pulse_us;
    ++steering_calls_;
}

void NativeBoard::lights(uint8_t mask) {
    lights_ = mask;
    ++lights_calls_;
}

bool NativeBoard::eeprom_read(uint16_t address, uint8_t* data, uint16_t length) {
    if (static_cast<uint32_t>(address) + length > EEPROM_SIZE) {
        return false;
    }
    memcpy(data, eeprom_ + address, length);
    return true;
}

bool NativeBoard::eeprom_write(uint16_t address, const uint8_t* data, uint16_t length) {
    ++eeprom_writes_;
    if (eeprom_write_fails_ || static_cast<uint32_t>(address) + length > EEPROM_SIZE) {
        return false;
    }
    for (uint16_t i = 0; i < length; ++i) {
        eeprom_[address + i] = static_cast<uint8_t>(data[i] ^ eeprom_write_xor_);
    }
    eeprom_bytes_written_ += length;
    return true;
}

uint32_t NativeBoard::entropy() {
    noise_ ^= noise_ << 13;
    noise_ ^= noise_ >> 17;
    noise_ ^= noise_ << 5;
    return noise_;
}

void NativeBoard::erase_eeprom() { memset(eeprom_, 0xFF, sizeof eeprom_); }

void NativeBoard::corrupt_eeprom(uint16_t address, uint8_t xor_mask) {
    if (address < EEPROM_SIZE) {
        eeprom_[address] = static_cast<uint8_t>(eeprom_[address] ^ xor_mask);
    }
}

}  // namespace roverlink

#endif  // !ARDUINO
