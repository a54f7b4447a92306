// One simulated robot: the firmware core on a NativeBoard, talking over a MemoryStream, on a
// simulated clock. Used by the C++ tests and wrapped by sim_api.cpp for Python (ctypes).
#ifndef ROVERLINK_TESTS_CORE_SIM_H
#define ROVERLINK_TESTS_CORE_SIM_H

#include <stddef.h>
#include <stdint.h>

#include <RoverLink.h>

#include "hal/native/memory_stream.h"
#include "hal/native/native_board.h"

class Sim {
public:
    // Boots the firmware at simulated time 0 (begin() runs here).
    Sim(const roverlink::Robot& robot, uint32_t seed, uint32_t poll_interval_us = 1000);
    ~Sim();
    Sim(const Sim&) = delete;
    Sim& operator=(const Sim&) = delete;

    // Power cycle: the firmware restarts from begin() with micros() back at boot_micros; the
    // EEPROM survives, bytes in flight and encoder counters do not. Simulated time goes on.
    void power_cycle();

    void feed(const uint8_t* data, size_t size) { port.host_write(data, size); }
    size_t read(uint8_t* out, size_t cap) { return port.host_read(out, cap); }

    // Polls at the current time (handles the bytes fed so far), then advances the clock in steps
    // of poll_interval_us, polling after each step: ticks come on schedule from micros().
    void advance_us(uint64_t us);

    uint64_t time_us() const { return now_; }
    uint32_t poll_interval_us;  // >= 1
    uint32_t boot_micros;       // micros() at the next boot (tests of the 32-bit wrap)

    const roverlink::Robot& robot;
    roverlink::NativeBoard board;
    roverlink::MemoryStream port;
    roverlink::Firmware* fw;

private:
    void boot();
    void poll_now();  // Firmware::poll() until the bytes fed so far are all read
    void sync_clock() { board.set_micros(static_cast<uint32_t>(booted_micros_ + (now_ - boot_at_))); }

    uint64_t now_;
    uint64_t boot_at_;
    uint32_t booted_micros_;
};

#endif  // ROVERLINK_TESTS_CORE_SIM_H
