// Consistent Overhead Byte Stuffing over whole buffers (no delimiter is written or expected).
// For tools and tests: the frame encoder and decoder each do their own single-pass COBS.
#ifndef ROVERLINK_WIRE_COBS_H
#define ROVERLINK_WIRE_COBS_H

#include <stddef.h>
#include <stdint.h>

namespace roverlink {

// Upper bound of the encoded size of n bytes (exact except when n is a non-zero multiple of 254).
inline size_t cobs_max_encoded_size(size_t n) { return n + n / 254u + 1u; }

// Encodes `len` bytes into `out`. Returns the encoded length (always >= 1), or 0 when `cap` is too
// small. `in` and `out` must not overlap.
size_t cobs_encode(const uint8_t* in, size_t len, uint8_t* out, size_t cap);

// Decodes one encoded chunk. Returns false (and leaves out_len alone) when the input is empty,
// contains 0x00, has a block that runs past its end, or does not fit in `cap`.
bool cobs_decode(const uint8_t* in, size_t len, uint8_t* out, size_t cap, size_t& out_len);

}  // namespace roverlink

#endif  // ROVERLINK_WIRE_COBS_H
