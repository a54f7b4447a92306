// Quadrature decoding: which way an encoder moved, from the previous and the current level of
// its two channels.
//
// This header is pure logic with no AVR dependency on purpose (and so, unlike the rest of
// src/hal/avr/, it is not wrapped in `#if defined(ARDUINO_ARCH_AVR)`): the interrupt handlers in
// encoder.h call it, and tests/firmware/native/avr_hal/ checks every transition of every resolution with
// g++ and sanitizers.
//
// Channel levels are packed as `ab = (A << 1) | B`. Turning forward (A leads B) walks the Gray
// sequence 00 -> 10 -> 11 -> 01 -> 00; backward walks it the other way.
//
// * X4 counts every edge of both channels: 4 counts per encoder cycle.
// * X2 counts the edges of channel A only: 2 counts per cycle.
// * X1 counts one edge per cycle, the A edge between 00 and 10, +1 one way and -1 the other, so a
//   shaft that dithers on that edge adds nothing up.
//
// Both channels are sampled on every edge in every resolution (both pins interrupt), so a
// transition where both levels changed is always visible: an edge was missed (noise, or the
// interrupt latency was longer than the time between two edges). The direction of such a step is
// unknowable, so it counts nothing and is reported as an error instead.
#ifndef ROVERLINK_HAL_AVR_QUADRATURE_H
#define ROVERLINK_HAL_AVR_QUADRATURE_H

#include <stdint.h>

#if defined(__AVR__)
#include <avr/pgmspace.h>
#define ROVERLINK_QUADRATURE_TABLE PROGMEM
#define ROVERLINK_QUADRATURE_READ(p) static_cast<int8_t>(pgm_read_byte(p))
#else
#define ROVERLINK_QUADRATURE_TABLE
#define ROVERLINK_QUADRATURE_READ(p) (*(p))
#endif

namespace roverlink {
namespace quadrature {

// Counts per encoder cycle (per slot of the code wheel).
enum class Resolution : uint8_t {
    X1 = 1,
    X2 = 2,
    X4 = 4,
};

// Result of one transition: the count delta, or INVALID when both channels changed.
static const int8_t INVALID = 2;

// One table per resolution, indexed by (previous_ab << 2) | current_ab. Written out in full
// rather than computed so the interrupt handler is one table read, and so a reader can check it
// against the Gray sequence above line by line.
#define ROVERLINK_Q_ROWS(f0010, f1011, f1101, f0100)                                                 \
    /* previous 00: to 00, 01 (back), 10 (fwd), 11 (both changed) */                                   \
    0, static_cast<int8_t>(-(f0100)), (f0010), INVALID,                                                \
        /* previous 01: to 00 (fwd), 01, 10 (both changed), 11 (back) */                               \
        (f0100), 0, INVALID, static_cast<int8_t>(-(f1101)),                                            \
        /* previous 10: to 00 (back), 01 (both changed), 10, 11 (fwd) */                               \
        static_cast<int8_t>(-(f0010)), INVALID, 0, (f1011),                                            \
        /* previous 11: to 00 (both changed), 01 (fwd), 10 (back), 11 */                               \
        INVALID, (f1101), static_cast<int8_t>(-(f1011)), 0

// Arguments: whether the forward step 00->10 (A rises), 10->11 (B rises), 11->01 (A falls) and
// 01->00 (B falls) counts; the backward step over the same edge counts -1 when the forward one does.
static const int8_t TABLE_X4[16] ROVERLINK_QUADRATURE_TABLE = {ROVERLINK_Q_ROWS(1, 1, 1, 1)};
static const int8_t TABLE_X2[16] ROVERLINK_QUADRATURE_TABLE = {ROVERLINK_Q_ROWS(1, 0, 1, 0)};
static const int8_t TABLE_X1[16] ROVERLINK_QUADRATURE_TABLE = {ROVERLINK_Q_ROWS(1, 0, 0, 0)};

#undef ROVERLINK_Q_ROWS

constexpr const int8_t* table_for(Resolution resolution) {
    return resolution == Resolution::X4 ? TABLE_X4 : resolution == Resolution::X2 ? TABLE_X2 : TABLE_X1;
}

// Count delta (-1, 0, +1) of the step previous_ab -> current_ab, or INVALID. Only the low two
// bits of each level are used.
inline int8_t step(const int8_t* table, uint8_t previous_ab, uint8_t current_ab) {
    return ROVERLINK_QUADRATURE_READ(&table[((previous_ab & 3u) << 2) | (current_ab & 3u)]);
}

inline int8_t step(Resolution resolution, uint8_t previous_ab, uint8_t current_ab) {
    return step(table_for(resolution), previous_ab, current_ab);
}

// The decoder state of one encoder. Not synchronised: encoder.h wraps it in an interrupt handler
// and reads it with interrupts off; the native tests use it directly.
struct Decoder {
    int32_t count;    // cumulative, wraps like any i32 (the host unwraps)
    uint16_t errors;  // invalid transitions (saturates rather than wrapping back to 0)
    uint8_t ab;       // last level seen
    const int8_t* table;

    void reset(Resolution resolution, uint8_t initial_ab) {
        count = 0;
        errors = 0;
        ab = static_cast<uint8_t>(initial_ab & 3u);
        table = table_for(resolution);
    }

    void update(uint8_t current_ab) {
        current_ab &= 3u;
        const int8_t delta = step(table, ab, current_ab);
        if (delta == INVALID) {
            if (errors != 0xFFFFu) {
                ++errors;
            }
        } else {
            // Unsigned arithmetic: wrapping past INT32_MAX is defined, not an overflow.
            const uint32_t sum = static_cast<uint32_t>(count) + static_cast<uint32_t>(static_cast<int32_t>(delta));
            count = static_cast<int32_t>(sum);
        }
        ab = current_ab;
    }
};

}  // namespace quadrature
}  // namespace roverlink

#endif  // ROVERLINK_HAL_AVR_QUADRATURE_H
