// Fuzz target: the frame decoder (arduino/RoverLink/src/codec/frame_decoder.cpp) against a
// reference decoder written here from the wire format alone (docs/protocol.md): its own COBS, its
// own bitwise CRC-16/CCITT-FALSE, its own chunking, resynchronisation and over-long-chunk rule.
//
// Every input is a byte stream from the host. Both decoders see it byte by byte and must agree on
// every push() result, on every accepted frame's id, seq and payload, and on every counter. Each
// accepted frame must then re-encode (encode_frame) to exactly the bytes received, and unpack, pack
// and encode_message() back to them; the dispatcher may refuse a payload only for its values.
// The library's standalone cobs_encode()/cobs_decode() are checked against the reference COBS on
// the whole input. A disagreement aborts (a finding), as does any ASan or UBSan report.
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <algorithm>
#include <vector>

#include "codec/codec.h"
#include "fuzz_check.h"

using namespace roverlink;

namespace {

typedef std::vector<uint8_t> Bytes;

// -- the reference ------------------------------------------------------------------------------

// CRC-16/CCITT-FALSE, one bit at a time: poly 0x1021, init 0xFFFF, no reflection, no final xor.
uint16_t ref_crc(const uint8_t* p, size_t n, uint16_t crc = 0xFFFF) {
    for (size_t i = 0; i < n; ++i) {
        crc = static_cast<uint16_t>(crc ^ (p[i] << 8));
        for (int b = 0; b < 8; ++b) {
            crc = static_cast<uint16_t>((crc & 0x8000) ? (crc << 1) ^ 0x1021 : crc << 1);
        }
    }
    return crc;
}

// COBS decode of one chunk: false if it is empty, holds a 0x00 or a block runs past its end. A
// 0xFF block has no implied zero; every other block but the last is followed by one.
bool ref_cobs(const Bytes& in, Bytes& out) {
    out.clear();
    if (in.empty() || std::find(in.begin(), in.end(), 0) != in.end()) {
        return false;
    }
    size_t i = 0;
    while (i < in.size()) {
        const uint8_t code = in[i++];
        if (i + code - 1 > in.size()) {
            return false;
        }
        out.insert(out.end(), in.begin() + static_cast<long>(i), in.begin() + static_cast<long>(i + code - 1));
        i += code - 1;
        if (code != 0xFF && i < in.size()) {
            out.push_back(0);
        }
    }
    return true;
}

struct Event {
    FrameDecoder::Result result;  // what push() must return for this byte
    Bytes body;                   // a FRAME's decoded body (id, seq, payload; no CRC)
    size_t chunk_begin;           // a FRAME's encoded chunk in the input: [chunk_begin, delimiter)
};

// The decoder's contract: chunks end at 0x00; an empty chunk is nothing; a chunk that reaches
// MAX_BODY + 2 bytes without a delimiter is one COBS error at that byte, and everything up to the
// next 0x00 is discarded; at the delimiter: COBS, then body length >= 4, then a known id, then
// the CRC (over id, seq, payload and the message's CRC_EXTRA), then the payload length.
class Reference {
public:
    DecoderStats stats;

    Reference() : skipping_(false), begin_(0) { memset(&stats, 0, sizeof stats); }

    Event push(uint8_t byte, size_t at) {
        Event e;
        e.result = FrameDecoder::NONE;
        e.chunk_begin = begin_;
        if (byte != 0) {
            if (skipping_) {
                ++stats.bytes_discarded;
            } else if (chunk_.size() == MAX_CHUNK) {
                stats.bytes_discarded += MAX_CHUNK + 1;
                ++stats.cobs_errors;
                chunk_.clear();
                skipping_ = true;
                e.result = FrameDecoder::ERR_OVERLONG;
            } else {
                chunk_.push_back(byte);
            }
            return e;
        }
        const Bytes chunk = chunk_;
        const bool skipped = skipping_;
        chunk_.clear();
        skipping_ = false;
        begin_ = at + 1;
        if (skipped || chunk.empty()) {
            return e;
        }
        e.result = verdict(chunk, e.body);
        switch (e.result) {
        case FrameDecoder::FRAME:
            ++stats.frames_ok;
            return e;
        case FrameDecoder::ERR_COBS:
            ++stats.cobs_errors;
            break;
        case FrameDecoder::ERR_LENGTH:
            ++stats.length_errors;
            break;
        case FrameDecoder::ERR_UNKNOWN_ID:
            ++stats.unknown_ids;
            break;
        default:
            ++stats.crc_errors;
            break;
        }
        stats.bytes_discarded += chunk.size();
        return e;
    }

private:
    static const size_t MAX_CHUNK = proto::MAX_BODY + 1;

    static FrameDecoder::Result verdict(const Bytes& chunk, Bytes& body) {
        Bytes b;
        if (!ref_cobs(chunk, b)) {
            return FrameDecoder::ERR_COBS;
        }
        if (b.size() < 4) {
            return FrameDecoder::ERR_LENGTH;
        }
        proto::MessageBounds bounds;
        if (!proto::message_bounds(b[0], bounds)) {
            return FrameDecoder::ERR_UNKNOWN_ID;
        }
        const size_t n = b.size();
        uint16_t crc = ref_crc(b.data(), n - 2);
        crc = ref_crc(&bounds.crc_extra, 1, crc);
        if (crc != static_cast<uint16_t>(b[n - 2] | (b[n - 1] << 8))) {
            return FrameDecoder::ERR_CRC;
        }
        const size_t payload = n - 4;
        if (payload < bounds.min_payload || payload > bounds.max_payload) {
            return FrameDecoder::ERR_LENGTH;
        }
        body.assign(b.begin(), b.end() - 2);
        return FrameDecoder::FRAME;
    }

    Bytes chunk_;
    bool skipping_;
    size_t begin_;
};

// -- what an accepted frame must survive --------------------------------------------------------

// dispatch_*()'s handler: the message packs back to the payload and encodes back to the frame.
struct RoundTrip {
    const uint8_t* payload;
    uint8_t len;
    const Bytes* frame;
    bool handled;

    template <class M>
    void handle(const M& m, uint8_t seq) {
        handled = true;
        uint8_t packed[proto::MAX_PAYLOAD];
        FUZZ_CHECK(proto::pack(m, packed) == len && memcmp(packed, payload, len) == 0);
        uint8_t out[proto::MAX_FRAME];
        const size_t n = encode_message(m, seq, out, sizeof out);
        FUZZ_CHECK(n == frame->size() && memcmp(out, frame->data(), n) == 0);
    }
};

void check_frame(const FrameDecoder& d, const uint8_t* data, const Event& e, size_t delimiter) {
    FUZZ_CHECK(e.body.size() >= 2 && d.msg_id() == e.body[0] && d.seq() == e.body[1]);
    FUZZ_CHECK(d.payload_len() == e.body.size() - 2 && memcmp(d.payload(), e.body.data() + 2, d.payload_len()) == 0);
    FUZZ_CHECK(d.bounds().min_payload <= d.payload_len() && d.payload_len() <= d.bounds().max_payload);
    // The encoder gives back exactly what came in (COBS without 0xFF blocks is canonical).
    const Bytes frame(data + e.chunk_begin, data + delimiter + 1);
    uint8_t out[proto::MAX_FRAME];
    const size_t n = encode_frame(d.msg_id(), d.seq(), d.bounds().crc_extra, d.payload(), d.payload_len(), out,
                                  sizeof out);
    FUZZ_CHECK(n == frame.size() && memcmp(out, frame.data(), n) == 0);
    RoundTrip rt = {d.payload(), d.payload_len(), &frame, false};
    proto::DispatchResult r = proto::dispatch_host_to_mcu(d.msg_id(), d.seq(), d.payload(), d.payload_len(), rt);
    if (r == proto::DISPATCH_WRONG_DIRECTION) {
        r = proto::dispatch_mcu_to_host(d.msg_id(), d.seq(), d.payload(), d.payload_len(), rt);
    }
    // Length and id were checked by the decoder: only an undefined value can refuse the payload.
    FUZZ_CHECK(r == proto::DISPATCH_OK ? rt.handled : r == proto::DISPATCH_BAD_PAYLOAD);
}

bool same(const DecoderStats& a, const DecoderStats& b) { return memcmp(&a, &b, sizeof a) == 0; }

// The library's standalone COBS (cobs.cpp, 0xFF blocks included) against the reference: the input
// encodes to something without 0x00 that decodes back, and decodes (as if it were encoded) to what
// the reference makes of it, or is refused by both.
void check_cobs(const uint8_t* data, size_t size) {
    const Bytes input(data, data + size);
    Bytes enc(cobs_max_encoded_size(size));
    const size_t n = cobs_encode(data, size, enc.data(), enc.size());
    FUZZ_CHECK(n >= 1 && n <= enc.size());
    enc.resize(n);
    Bytes ref;
    FUZZ_CHECK(ref_cobs(enc, ref) && ref == input);
    Bytes out(size + 1);
    size_t m = 0;
    FUZZ_CHECK(cobs_decode(enc.data(), n, out.data(), out.size(), m) && m == size && memcmp(out.data(), data, m) == 0);
    const bool valid = ref_cobs(input, ref);
    FUZZ_CHECK(cobs_decode(data, size, out.data(), out.size(), m) == valid);
    FUZZ_CHECK(!valid || (m == ref.size() && memcmp(out.data(), ref.data(), m) == 0));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    check_cobs(data, size);
    FrameDecoder decoder;
    Reference ref;
    for (size_t i = 0; i < size; ++i) {
        const Event e = ref.push(data[i], i);
        const FrameDecoder::Result got = decoder.push(data[i]);
        FUZZ_CHECK(got == e.result);
        if (got == FrameDecoder::FRAME && e.result == FrameDecoder::FRAME) {
            check_frame(decoder, data, e, i);
        }
        FUZZ_CHECK(same(decoder.stats(), ref.stats));
    }
    // reset() drops a partial chunk and keeps the counters; the next frame decodes from scratch.
    const DecoderStats before = decoder.stats();
    decoder.reset();
    FUZZ_CHECK(same(decoder.stats(), before));
    uint8_t ping[proto::MAX_FRAME];
    const proto::Ping p = {0x01020304u};
    const size_t n = encode_message(p, 7, ping, sizeof ping);
    FrameDecoder::Result last = FrameDecoder::NONE;
    for (size_t i = 0; i < n; ++i) {
        last = decoder.push(ping[i]);
    }
    FUZZ_CHECK(last == FrameDecoder::FRAME && decoder.msg_id() == proto::Ping::ID && decoder.seq() == 7);
    return 0;
}
