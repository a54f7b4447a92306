// An in-memory Stream for native builds: two byte queues, one per direction.
//
// The firmware reads what the test (the "host") wrote with host_write(), and the test reads what
// the firmware wrote with host_read(). Unbounded (test code may use the heap; the core never does).
#ifndef ROVERLINK_HAL_NATIVE_MEMORY_STREAM_H
#define ROVERLINK_HAL_NATIVE_MEMORY_STREAM_H

#if !defined(ARDUINO)

#include <stddef.h>
#include <stdint.h>

#include <deque>

#include "stream.h"

namespace roverlink {

class MemoryStream final : public Stream {
public:
    // Firmware side (roverlink::Stream).
    int available() override;
    int read() override;
    size_t write(const uint8_t* data, size_t size) override;

    // Host side.
    void host_write(const uint8_t* data, size_t size);  // bytes for the firmware to read
    size_t host_read(uint8_t* out, size_t cap);         // bytes the firmware wrote; returns count
    size_t host_available() const { return to_host_.size(); }
    size_t pending_to_mcu() const { return to_mcu_.size(); }
    void clear();  // drops both queues (a power cycle loses bytes in flight)

    uint64_t bytes_to_mcu() const { return bytes_to_mcu_; }
    uint64_t bytes_to_host() const { return bytes_to_host_; }

private:
    std::deque<uint8_t> to_mcu_;
    std::deque<uint8_t> to_host_;
    uint64_t bytes_to_mcu_ = 0;
    uint64_t bytes_to_host_ = 0;
};

}  // namespace roverlink

#endif  // !ARDUINO

#endif  // ROVERLINK_HAL_NATIVE_MEMORY_STREAM_H
