// Native (non-Arduino) Stream: the subset of Arduino's Stream the firmware core uses.
// Not compiled under Arduino, where roverlink::Stream is the Arduino core's ::Stream.
#ifndef ROVERLINK_HAL_NATIVE_STREAM_H
#define ROVERLINK_HAL_NATIVE_STREAM_H

#if !defined(ARDUINO)

#include <stddef.h>
#include <stdint.h>

namespace roverlink {

class Stream {
public:
    virtual int available() = 0;                                 // bytes ready to read
    virtual int read() = 0;                                      // next byte, or -1 when none
    virtual size_t write(const uint8_t* data, size_t size) = 0;  // bytes accepted

protected:
    ~Stream() {}
};

}  // namespace roverlink

#endif  // !ARDUINO

#endif  // ROVERLINK_HAL_NATIVE_STREAM_H
