// The host link on the Pico: UART0 (GP0 TX, GP1 RX) as the core's Stream. Received bytes are moved
// from the UART's 32-byte FIFO into a ring buffer by its interrupt, so a control tick or a long
// frame written out never overruns the FIFO, even at 1 Mbaud (a byte every 10 us); the same
// interrupt wakes the core from WFI. Writes wait for room in the transmit FIFO, as the Arduino
// core's Serial.write() waits for its buffer.
//
//   roverlink::rp2040::UartStream port;
//   extern "C" void isr_uart0() { port.on_interrupt(); }
//   ...  port.begin(115200);
#ifndef ROVERLINK_HAL_RP2040_UART_STREAM_H
#define ROVERLINK_HAL_RP2040_UART_STREAM_H

#if defined(ROVERLINK_ARCH_RP2040)

#include <stddef.h>
#include <stdint.h>

#include "../../generated/roverlink_protocol.h"
#include "../stream.h"
#include "io.h"

namespace roverlink {
namespace rp2040 {

class UartStream : public Stream {
public:
    // Room for three of the longest frames: the core reads every byte at each poll().
    static const uint16_t RX_BUFFER = 256;
    static_assert(RX_BUFFER >= 3u * proto::MAX_FRAME, "three frames fit");
    static_assert((RX_BUFFER & (RX_BUFFER - 1u)) == 0, "a power of two: indices wrap by masking");

    void begin(uint32_t baud) {
        Uart0::begin(baud);
        Uart0::interrupt_on_receive();
    }

    /// From isr_uart0: the FIFO into the ring. A byte with no room is counted, not stored.
    void on_interrupt() {
        while (Uart0::readable()) {
            const uint8_t byte = Uart0::read();
            const uint16_t next = static_cast<uint16_t>((head_ + 1u) & (RX_BUFFER - 1u));
            if (next == tail_) {
                ++overruns_;
            } else {
                rx_[head_] = byte;
                head_ = next;
            }
        }
    }

    int available() override { return static_cast<int>((head_ - tail_) & (RX_BUFFER - 1u)); }

    int read() override {
        if (head_ == tail_) {
            return -1;
        }
        const uint8_t byte = rx_[tail_];
        tail_ = static_cast<uint16_t>((tail_ + 1u) & (RX_BUFFER - 1u));
        return byte;
    }

    size_t write(const uint8_t* data, size_t size) override {
        for (size_t i = 0; i < size; ++i) {
            Uart0::write(data[i]);
        }
        return size;
    }

    /// Bytes dropped because the ring was full (the core's poll() stalled for RX_BUFFER bytes).
    uint32_t overruns() const { return overruns_; }

private:
    uint8_t rx_[RX_BUFFER];
    volatile uint16_t head_ = 0;  // written by the interrupt only
    volatile uint16_t tail_ = 0;  // written by read() only
    volatile uint32_t overruns_ = 0;
};

}  // namespace rp2040
}  // namespace roverlink

#endif  // ROVERLINK_ARCH_RP2040
#endif  // ROVERLINK_HAL_RP2040_UART_STREAM_H
