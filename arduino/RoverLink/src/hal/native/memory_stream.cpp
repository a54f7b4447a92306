#if !defined(ARDUINO)

#include "memory_stream.h"

namespace roverlink {

int MemoryStream::available() {
    const size_t n = to_mcu_.size();
    return n > 0x7FFF ? 0x7FFF : static_cast<int>(n);  // Arduino's Stream reports an int
}

int MemoryStream::read() {
    if (to_mcu_.empty()) {
        return -1;
    }
    const uint8_t b = to_mcu_.front();
    to_mcu_.pop_front();
    return b;
}

size_t MemoryStream::write(const uint8_t* data, size_t size) {
    to_host_.insert(to_host_.end(), data, data + size);
    bytes_to_host_ += size;
    return size;
}

void MemoryStream::host_write(const uint8_t* data, size_t size) {
    to_mcu_.insert(to_mcu_.end(), data, data + size);
    bytes_to_mcu_ += size;
}

size_t MemoryStream::host_read(uint8_t* out, size_t cap) {
    size_t n = 0;
    while (n < cap && !to_host_.empty()) {
        out[n++] = to_host_.front();
        to_host_.pop_front();
    }
    return n;
}

void MemoryStream::clear() {
    to_mcu_.clear();
    to_host_.clear();
}

}  // namespace roverlink

#endif  // !ARDUINO
