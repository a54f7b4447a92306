// Native unit tests for the RoverLink codec runtime (arduino/RoverLink/src/wire and src/codec).
// Plain C++: CHECK counts results and the last line reads "N passed, M failed".
// Built against the generated protocol; frame tests find the message ids through
// proto::message_bounds(), and per-message tests go through the generated dispatchers, so spec
// changes need no edits here.
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <vector>

#include "check.h"
#include "codec/codec.h"

using namespace roverlink;

typedef std::vector<uint8_t> Bytes;


// ---------------------------------------------------------------------------------------------
// Helpers

static uint32_t g_rng = 0x12345678u;
static uint8_t rnd() {  // xorshift32: deterministic test data
    g_rng ^= g_rng << 13;
    g_rng ^= g_rng >> 17;
    g_rng ^= g_rng << 5;
    return static_cast<uint8_t>(g_rng >> 24);
}
static uint8_t rnd_nonzero() {
    uint8_t b;
    do {
        b = rnd();
    } while (b == 0);
    return b;
}

// Bit-by-bit CRC-16/CCITT-FALSE straight from the definition: an oracle for the fast one.
static uint16_t ref_crc(const uint8_t* data, size_t len, uint16_t crc = 0xFFFF) {
    for (size_t i = 0; i < len; ++i) {
        crc = static_cast<uint16_t>(crc ^ (data[i] << 8));
        for (int k = 0; k < 8; ++k) {
            crc = static_cast<uint16_t>((crc & 0x8000) ? ((crc << 1) ^ 0x1021) : (crc << 1));
        }
    }
    return crc;
}

// Reference body: id | seq | payload | crc LE, crc over id, seq, payload and crc_extra.
static Bytes ref_body(uint8_t id, uint8_t seq, const Bytes& payload, uint8_t crc_extra) {
    Bytes body;
    body.push_back(id);
    body.push_back(seq);
    body.insert(body.end(), payload.begin(), payload.end());
    Bytes crc_in = body;
    crc_in.push_back(crc_extra);
    const uint16_t crc = ref_crc(crc_in.data(), crc_in.size());
    body.push_back(static_cast<uint8_t>(crc & 0xFF));
    body.push_back(static_cast<uint8_t>(crc >> 8));
    return body;
}

// COBS-encodes any body (even an invalid one) and appends the delimiter.
static Bytes wire_from_body(const Bytes& body) {
    Bytes out(cobs_max_encoded_size(body.size()) + 1);
    const size_t n = cobs_encode(body.data(), body.size(), out.data(), out.size());
    out.resize(n);
    out.push_back(0);
    return out;
}

static Bytes make_frame(uint8_t id, uint8_t seq, uint8_t crc_extra, const Bytes& payload) {
    Bytes out(proto::MAX_FRAME);
    const size_t n = encode_frame(id, seq, crc_extra, payload.data(),
                                  static_cast<uint8_t>(payload.size()), out.data(), out.size());
    out.resize(n);
    return out;
}

static Bytes random_payload(size_t len, bool with_zeros) {
    Bytes p(len);
    for (size_t i = 0; i < len; ++i) {
        p[i] = with_zeros ? ((rnd() & 3) == 0 ? 0 : rnd()) : rnd_nonzero();
    }
    return p;
}

static void append(Bytes& dst, const Bytes& src) { dst.insert(dst.end(), src.begin(), src.end()); }

struct Decoded {
    FrameDecoder::Result result;
    uint8_t id;
    uint8_t seq;
    Bytes payload;
};

// Feeds bytes one at a time and records every non-NONE result.
static std::vector<Decoded> feed(FrameDecoder& dec, const Bytes& bytes, size_t from = 0) {
    std::vector<Decoded> out;
    for (size_t i = from; i < bytes.size(); ++i) {
        const FrameDecoder::Result r = dec.push(bytes[i]);
        if (r == FrameDecoder::NONE) {
            continue;
        }
        Decoded d;
        d.result = r;
        d.id = d.seq = 0;
        if (r == FrameDecoder::FRAME) {
            d.id = dec.msg_id();
            d.seq = dec.seq();
            d.payload.assign(dec.payload(), dec.payload() + dec.payload_len());
        }
        out.push_back(d);
    }
    return out;
}

static bool same_stats(const DecoderStats& a, const DecoderStats& b) {
    return a.frames_ok == b.frames_ok && a.crc_errors == b.crc_errors &&
           a.cobs_errors == b.cobs_errors && a.length_errors == b.length_errors &&
           a.unknown_ids == b.unknown_ids && a.bytes_discarded == b.bytes_discarded;
}

static DecoderStats zero_stats() {
    DecoderStats s;
    memset(&s, 0, sizeof(s));
    return s;
}

// Message ids of the protocol under test, found through message_bounds().
struct Msg {
    uint8_t id;
    proto::MessageBounds b;
};
static std::vector<Msg> g_msgs;
static int g_unknown_id = -1;

static void discover_messages() {
    for (int id = 0; id < 256; ++id) {
        Msg m;
        m.id = static_cast<uint8_t>(id);
        if (proto::message_bounds(m.id, m.b)) {
            g_msgs.push_back(m);
        } else if (g_unknown_id < 0) {
            g_unknown_id = id;
        }
    }
}

// A payload length the message does not allow, just above its max (or just below its min when
// `below`); -1 when there is none within 0..MAX_PAYLOAD.
static int bad_length(const proto::MessageBounds& b, bool below) {
    if (!below && b.max_payload < proto::MAX_PAYLOAD) return b.max_payload + 1;
    if (below && b.min_payload > 0) return b.min_payload - 1;
    return -1;
}

// ---------------------------------------------------------------------------------------------
// CRC

static void test_crc() {
    CONTEXT("crc");
    const uint8_t check[] = {'1', '2', '3', '4', '5', '6', '7', '8', '9'};
    CHECK(crc16(check, sizeof(check)) == 0x29B1);
    CHECK(ref_crc(check, sizeof(check)) == 0x29B1);
    uint16_t c = CRC16_INIT;
    for (size_t i = 0; i < sizeof(check); ++i) c = crc16_update(c, check[i]);
    CHECK(c == 0x29B1);
    CHECK(crc16(check, 4, crc16(check, 0)) == ref_crc(check, 4));
    CHECK(crc16(check + 4, 5, crc16(check, 4)) == 0x29B1);  // continues across calls
    CHECK(crc16(check, 0) == 0xFFFF);
    for (int n = 0; n < 200; ++n) {
        const Bytes d = random_payload(static_cast<size_t>(n), true);
        CONTEXT("crc random len %d", n);
        CHECK(crc16(d.data(), d.size()) == ref_crc(d.data(), d.size()));
    }
    for (int b = 0; b < 256; ++b) {  // every byte value from several states
        const uint8_t v = static_cast<uint8_t>(b);
        CHECK(crc16_update(0xFFFF, v) == ref_crc(&v, 1, 0xFFFF));
        CHECK(crc16_update(0x0000, v) == ref_crc(&v, 1, 0x0000));
        CHECK(crc16_update(0x8408, v) == ref_crc(&v, 1, 0x8408));
    }
}

// ---------------------------------------------------------------------------------------------
// COBS

static void check_cobs_vector(const Bytes& in, const Bytes& expected) {
    Bytes out(expected.size() + 8);
    const size_t n = cobs_encode(in.data(), in.size(), out.data(), out.size());
    out.resize(n);
    CHECK(out == expected);
    Bytes back(in.size() + 8);
    size_t m = 12345;
    CHECK(cobs_decode(expected.data(), expected.size(), back.data(), back.size(), m));
    back.resize(m);
    CHECK(back == in);
}

static void test_cobs_vectors() {
    CONTEXT("cobs vectors");
    check_cobs_vector(Bytes(), Bytes(1, 0x01));
    check_cobs_vector(Bytes(1, 0x00), Bytes(2, 0x01));
    check_cobs_vector(Bytes(2, 0x00), Bytes(3, 0x01));
    const uint8_t a_in[] = {0x11, 0x22, 0x00, 0x33};
    const uint8_t a_out[] = {0x03, 0x11, 0x22, 0x02, 0x33};
    check_cobs_vector(Bytes(a_in, a_in + 4), Bytes(a_out, a_out + 5));
    const uint8_t b_in[] = {0x11, 0x00, 0x00, 0x00};
    const uint8_t b_out[] = {0x02, 0x11, 0x01, 0x01, 0x01};
    check_cobs_vector(Bytes(b_in, b_in + 4), Bytes(b_out, b_out + 5));

    // 254 non-zero bytes: one full block, no trailing code byte.
    Bytes run254;
    for (int i = 1; i <= 254; ++i) run254.push_back(static_cast<uint8_t>(i));
    Bytes exp254(1, 0xFF);
    append(exp254, run254);
    check_cobs_vector(run254, exp254);

    // 255 non-zero bytes: a full block, then a block of one.
    Bytes run255 = run254;
    run255.push_back(0xFF);
    Bytes exp255 = exp254;
    exp255.push_back(0x02);
    exp255.push_back(0xFF);
    check_cobs_vector(run255, exp255);

    // A zero right after a full block.
    Bytes run254z = run254;
    run254z.push_back(0x00);
    Bytes exp254z = exp254;
    exp254z.push_back(0x01);
    exp254z.push_back(0x01);
    check_cobs_vector(run254z, exp254z);

    // Leading zero then 254 non-zero bytes.
    Bytes zrun254(1, 0x00);
    append(zrun254, run254);
    Bytes expz254(1, 0x01);
    append(expz254, exp254);
    check_cobs_vector(zrun254, expz254);
}

static void check_cobs_roundtrip(const Bytes& in) {
    const size_t bound = cobs_max_encoded_size(in.size());
    Bytes enc(bound);
    const size_t n = cobs_encode(in.data(), in.size(), enc.data(), enc.size());
    CHECK(n >= 1 && n <= bound);
    enc.resize(n);
    bool zero_free = true;
    for (size_t i = 0; i < n; ++i) zero_free = zero_free && enc[i] != 0;
    CHECK(zero_free);

    // Exact-size buffers work, one byte less is refused (ASan sees any overrun of these).
    Bytes exact(n);
    CHECK(cobs_encode(in.data(), in.size(), exact.data(), exact.size()) == n);
    CHECK(exact == enc);
    Bytes small(n - 1);
    CHECK(cobs_encode(in.data(), in.size(), small.data(), small.size()) == 0);

    Bytes dec(in.size());
    size_t m = 0;
    CHECK(cobs_decode(enc.data(), enc.size(), dec.data(), dec.size(), m));
    CHECK(m == in.size());
    CHECK(dec == in);
    if (!in.empty()) {
        Bytes tight(in.size() - 1);
        size_t unused = 0;
        CHECK(!cobs_decode(enc.data(), enc.size(), tight.data(), tight.size(), unused));
    }
}

static void test_cobs_roundtrip() {
    const size_t lens[] = {0, 1, 2, 3, 100, 252, 253, 254, 255, 256, 507, 508, 509, 510, 600, 763};
    for (size_t li = 0; li < sizeof(lens) / sizeof(lens[0]); ++li) {
        const size_t len = lens[li];
        CONTEXT("cobs roundtrip zeros len %zu", len);
        check_cobs_roundtrip(Bytes(len, 0x00));
        CONTEXT("cobs roundtrip 0x01 len %zu", len);
        check_cobs_roundtrip(Bytes(len, 0x01));
        CONTEXT("cobs roundtrip 0xFF len %zu", len);
        check_cobs_roundtrip(Bytes(len, 0xFF));
        CONTEXT("cobs roundtrip nonzero len %zu", len);
        check_cobs_roundtrip(random_payload(len, false));
        CONTEXT("cobs roundtrip mixed len %zu", len);
        check_cobs_roundtrip(random_payload(len, true));
    }
    // Non-zero runs of every length around the block size, alone and framed by zeros.
    for (size_t k = 250; k <= 260; ++k) {
        const Bytes run = random_payload(k, false);
        CONTEXT("cobs run %zu", k);
        check_cobs_roundtrip(run);
        Bytes framed(1, 0);
        append(framed, run);
        framed.push_back(0);
        check_cobs_roundtrip(framed);
        Bytes two = run;
        two.push_back(0);
        append(two, run);
        check_cobs_roundtrip(two);
    }
    // Encoded size is exactly n + 1 for bodies shorter than 254 (the frame encoder relies on it).
    for (size_t len = 0; len < 254; ++len) {
        const Bytes in = random_payload(len, true);
        Bytes enc(len + 1);
        CONTEXT("cobs size len %zu", len);
        CHECK(cobs_encode(in.data(), in.size(), enc.data(), enc.size()) == len + 1);
    }
}

static void test_cobs_invalid() {
    CONTEXT("cobs invalid");
    uint8_t out[300] = {0};
    size_t m = 777;
    const uint8_t none[1] = {0x01};
    CHECK(!cobs_decode(none, 0, out, sizeof(out), m));  // empty
    const uint8_t zero[] = {0x00};
    CHECK(!cobs_decode(zero, 1, out, sizeof(out), m));
    const uint8_t past_end[] = {0x03, 0x11};
    CHECK(!cobs_decode(past_end, 2, out, sizeof(out), m));
    const uint8_t inner_zero[] = {0x03, 0x11, 0x00};
    CHECK(!cobs_decode(inner_zero, 3, out, sizeof(out), m));
    const uint8_t zero_code[] = {0x02, 0x11, 0x00, 0x22};
    CHECK(!cobs_decode(zero_code, 4, out, sizeof(out), m));
    CHECK(m == 777);  // untouched on failure

    // Non-canonical but valid: a full block followed by an empty last block.
    Bytes nc(1, 0xFF);
    for (int i = 0; i < 254; ++i) nc.push_back(0x42);
    nc.push_back(0x01);
    CHECK(cobs_decode(nc.data(), nc.size(), out, sizeof(out), m));
    CHECK(m == 254);
}

// ---------------------------------------------------------------------------------------------
// Frames

static void test_single_frames() {
    const uint8_t seqs[] = {0, 1, 0x7F, 0xFF};
    for (size_t mi = 0; mi < g_msgs.size(); ++mi) {
        const Msg& msg = g_msgs[mi];
        for (int len = msg.b.min_payload; len <= msg.b.max_payload; ++len) {
            for (size_t si = 0; si < sizeof(seqs); ++si) {
                CONTEXT("frame id 0x%02X len %d seq %u", msg.id, len, seqs[si]);
                const Bytes payload = random_payload(static_cast<size_t>(len), true);
                const Bytes frame = make_frame(msg.id, seqs[si], msg.b.crc_extra, payload);
                CHECK(frame.size() == frame_size(static_cast<uint8_t>(len)));
                CHECK(frame.size() <= proto::MAX_FRAME);
                // Wire bytes equal COBS of the reference body: checks layout, CRC and CRC_EXTRA.
                CHECK(frame == wire_from_body(ref_body(msg.id, seqs[si], payload, msg.b.crc_extra)));

                FrameDecoder dec;
                size_t frames = 0;
                bool early = false;
                for (size_t i = 0; i < frame.size(); ++i) {
                    const FrameDecoder::Result r = dec.push(frame[i]);
                    if (i + 1 < frame.size()) {
                        early = early || r != FrameDecoder::NONE;
                    } else if (r == FrameDecoder::FRAME) {
                        ++frames;
                        CHECK(dec.msg_id() == msg.id);
                        CHECK(dec.seq() == seqs[si]);
                        CHECK(dec.payload_len() == len);
                        CHECK(Bytes(dec.payload(), dec.payload() + dec.payload_len()) == payload);
                    }
                }
                CHECK(!early);
                CHECK(frames == 1);
                CHECK(dec.stats().frames_ok == 1 && dec.stats().bytes_discarded == 0);
            }
        }
    }
}

// One event of a test stream: bytes on the wire and what the decoder must report for them.
struct Item {
    Bytes wire;
    Decoded expect;  // result NONE: nothing reported
    DecoderStats delta;
};

static Item good_item(const Msg& msg) {
    const int span = msg.b.max_payload - msg.b.min_payload + 1;
    const int len = msg.b.min_payload + (span > 1 ? rnd() % span : 0);
    Item it;
    it.expect.result = FrameDecoder::FRAME;
    it.expect.id = msg.id;
    it.expect.seq = rnd();
    it.expect.payload = random_payload(static_cast<size_t>(len), true);
    it.wire = make_frame(msg.id, it.expect.seq, msg.b.crc_extra, it.expect.payload);
    it.delta = zero_stats();
    it.delta.frames_ok = 1;
    return it;
}

static Item bad_item(FrameDecoder::Result r, const Bytes& wire) {
    Item it;
    it.wire = wire;
    it.expect.result = r;
    it.expect.id = it.expect.seq = 0;
    it.delta = zero_stats();
    // Rejected chunk bytes are discarded; the delimiter is not counted.
    it.delta.bytes_discarded = static_cast<uint32_t>(wire.size() - 1);
    switch (r) {
        case FrameDecoder::ERR_COBS: it.delta.cobs_errors = 1; break;
        case FrameDecoder::ERR_LENGTH: it.delta.length_errors = 1; break;
        case FrameDecoder::ERR_UNKNOWN_ID: it.delta.unknown_ids = 1; break;
        case FrameDecoder::ERR_CRC: it.delta.crc_errors = 1; break;
        default: break;
    }
    return it;
}

// One rejected chunk of a randomly chosen kind, with its exact expected report.
static Item garbage_item() {
    const Msg& msg = g_msgs[rnd() % g_msgs.size()];
    for (;;) {
        switch (rnd() % 9) {
            case 0: {  // block runs past the delimiter
                Bytes w;
                w.push_back(0x09);
                for (int i = 0; i < 1 + rnd() % 7; ++i) w.push_back(rnd_nonzero());
                w.push_back(0);
                return bad_item(FrameDecoder::ERR_COBS, w);
            }
            case 1: {  // body shorter than 4 bytes
                return bad_item(FrameDecoder::ERR_LENGTH, wire_from_body(random_payload(rnd() % 4, true)));
            }
            case 2: {  // unknown id, CRC otherwise right
                if (g_unknown_id < 0) continue;
                const Bytes body = ref_body(static_cast<uint8_t>(g_unknown_id), rnd(),
                                            random_payload(rnd() % 10, true), 0);
                return bad_item(FrameDecoder::ERR_UNKNOWN_ID, wire_from_body(body));
            }
            case 3: {  // payload byte corrupted after the CRC was computed
                Bytes body = ref_body(msg.id, rnd(), random_payload(msg.b.max_payload, true), msg.b.crc_extra);
                body[1] ^= static_cast<uint8_t>(1u << (rnd() % 8));
                return bad_item(FrameDecoder::ERR_CRC, wire_from_body(body));
            }
            case 4: {  // CRC made with another message's CRC_EXTRA
                const Bytes payload = random_payload(msg.b.min_payload, true);
                return bad_item(FrameDecoder::ERR_CRC,
                                make_frame(msg.id, rnd(), static_cast<uint8_t>(msg.b.crc_extra ^ 0x5C), payload));
            }
            case 5: {  // length outside the id's bounds, CRC right
                const int bad = bad_length(msg.b, rnd() & 1);
                if (bad < 0) continue;
                const Bytes body = ref_body(msg.id, rnd(), random_payload(static_cast<size_t>(bad), true),
                                            msg.b.crc_extra);
                return bad_item(FrameDecoder::ERR_LENGTH, wire_from_body(body));
            }
            case 6: {  // over-long run without a delimiter
                Item it;
                const size_t n = proto::MAX_FRAME + rnd() % 200;
                it.wire = random_payload(n, false);
                it.wire.push_back(0);
                it.expect.result = FrameDecoder::ERR_OVERLONG;
                it.expect.id = it.expect.seq = 0;
                it.delta = zero_stats();
                it.delta.cobs_errors = 1;
                it.delta.bytes_discarded = static_cast<uint32_t>(n);
                return it;
            }
            case 7: {  // extra delimiters: nothing at all
                Item it;
                it.wire = Bytes(1 + rnd() % 3, 0);
                it.expect.result = FrameDecoder::NONE;
                it.expect.id = it.expect.seq = 0;
                it.delta = zero_stats();
                return it;
            }
            default: {  // a single-byte chunk: COBS-valid, empty body
                Bytes w(1, 0x01);
                w.push_back(0);
                return bad_item(FrameDecoder::ERR_LENGTH, w);
            }
        }
    }
}

static void add_stats(DecoderStats& s, const DecoderStats& d) {
    s.frames_ok += d.frames_ok;
    s.crc_errors += d.crc_errors;
    s.cobs_errors += d.cobs_errors;
    s.length_errors += d.length_errors;
    s.unknown_ids += d.unknown_ids;
    s.bytes_discarded += d.bytes_discarded;
}

static bool same_decoded(const Decoded& a, const Decoded& b) {
    return a.result == b.result && a.id == b.id && a.seq == b.seq && a.payload == b.payload;
}

static void test_stream_with_garbage() {
    for (int round = 0; round < 20; ++round) {
        CONTEXT("stream round %d", round);
        Bytes stream;
        std::vector<Decoded> expected;
        DecoderStats stats = zero_stats();
        for (int k = 0; k < 60; ++k) {
            const Item it = (rnd() % 2) ? good_item(g_msgs[rnd() % g_msgs.size()]) : garbage_item();
            append(stream, it.wire);
            if (it.expect.result != FrameDecoder::NONE) expected.push_back(it.expect);
            add_stats(stats, it.delta);
        }
        FrameDecoder dec;
        const std::vector<Decoded> got = feed(dec, stream);
        CHECK(got.size() == expected.size());
        bool all_same = got.size() == expected.size();
        for (size_t i = 0; all_same && i < got.size(); ++i) all_same = same_decoded(got[i], expected[i]);
        CHECK(all_same);
        CHECK(same_stats(dec.stats(), stats));
        dec.reset_stats();
        CHECK(same_stats(dec.stats(), zero_stats()));
    }
}

// Joining a stream anywhere (e.g. mid-frame after a reset) loses at most the partial chunk.
static void test_join_at_every_offset() {
    Bytes stream;
    std::vector<size_t> starts;
    std::vector<Decoded> frames;
    for (int k = 0; k < 12; ++k) {
        const Item it = good_item(g_msgs[static_cast<size_t>(k) % g_msgs.size()]);
        starts.push_back(stream.size());
        append(stream, it.wire);
        frames.push_back(it.expect);
    }
    for (size_t off = 0; off < stream.size(); ++off) {
        CONTEXT("join at offset %zu", off);
        size_t first = 0;  // first frame that must decode: one starting at or after off
        while (first < starts.size() && starts[first] < off) ++first;
        FrameDecoder dec;
        const std::vector<Decoded> got = feed(dec, stream, off);
        size_t good = 0;
        bool ok = true;
        for (size_t i = 0; i < got.size(); ++i) {
            if (got[i].result != FrameDecoder::FRAME) {
                ok = ok && i == 0 && first > 0;  // only the partial chunk may fail
                continue;
            }
            ok = ok && first + good < frames.size() && same_decoded(got[i], frames[first + good]);
            ++good;
        }
        CHECK(ok);
        CHECK(good == frames.size() - first);
    }
}

static void test_bit_flips() {
    for (size_t mi = 0; mi < g_msgs.size(); ++mi) {
        const Msg& msg = g_msgs[mi];
        const uint8_t lens[] = {msg.b.min_payload, msg.b.max_payload};
        for (int li = 0; li < 2; ++li) {
            const Bytes payload = random_payload(lens[li], true);
            const Bytes frame = make_frame(msg.id, 0x33, msg.b.crc_extra, payload);
            const Item a = good_item(g_msgs[(mi + 1) % g_msgs.size()]);
            const Item b = good_item(g_msgs[(mi + 2) % g_msgs.size()]);
            for (size_t bit = 0; bit < frame.size() * 8; ++bit) {
                CONTEXT("bit flip id 0x%02X len %u bit %zu", msg.id, lens[li], bit);
                Bytes stream = frame;
                stream[bit / 8] ^= static_cast<uint8_t>(1u << (bit % 8));
                const bool delimiter_hit = bit / 8 == frame.size() - 1;
                append(stream, a.wire);
                append(stream, b.wire);
                FrameDecoder dec;
                const std::vector<Decoded> got = feed(dec, stream);
                std::vector<Decoded> good;
                for (size_t i = 0; i < got.size(); ++i) {
                    if (got[i].result == FrameDecoder::FRAME) good.push_back(got[i]);
                }
                // The flipped frame never gets through; the next one is lost only if the flip
                // removed the delimiter between them.
                if (delimiter_hit) {
                    CHECK(good.size() == 1 && same_decoded(good[0], b.expect));
                } else {
                    CHECK(good.size() == 2 && same_decoded(good[0], a.expect) &&
                          same_decoded(good[1], b.expect));
                }
                CHECK(got.size() > good.size());  // the damage was reported
                const DecoderStats& s = dec.stats();
                CHECK(s.frames_ok == good.size());
                CHECK(s.crc_errors + s.cobs_errors + s.length_errors + s.unknown_ids ==
                      got.size() - good.size());
            }
        }
    }
}

static void test_overlong() {
    CONTEXT("overlong");
    const Item next = good_item(g_msgs[0]);
    FrameDecoder dec;
    // MAX_FRAME - 1 encoded bytes is still a possible frame: no error yet.
    bool quiet = true;
    for (int i = 0; i < proto::MAX_FRAME - 1; ++i) quiet = quiet && dec.push(0x01) == FrameDecoder::NONE;
    CHECK(quiet);
    CHECK(dec.push(0x01) == FrameDecoder::ERR_OVERLONG);
    quiet = true;
    for (int i = 0; i < 500; ++i) quiet = quiet && dec.push(rnd_nonzero()) == FrameDecoder::NONE;
    CHECK(quiet);
    CHECK(dec.push(0x00) == FrameDecoder::NONE);
    const std::vector<Decoded> got = feed(dec, next.wire);
    CHECK(got.size() == 1 && same_decoded(got[0], next.expect));
    DecoderStats s = zero_stats();
    s.cobs_errors = 1;
    s.frames_ok = 1;
    s.bytes_discarded = proto::MAX_FRAME + 500;
    CHECK(same_stats(dec.stats(), s));

    // A chunk of exactly MAX_FRAME - 1 bytes ending in a delimiter is judged normally.
    FrameDecoder dec2;
    Bytes chunk(proto::MAX_FRAME - 1, 0x01);
    chunk.push_back(0);
    const std::vector<Decoded> got2 = feed(dec2, chunk);
    CHECK(got2.size() == 1 && got2[0].result != FrameDecoder::ERR_OVERLONG);

    // A body of MAX_BODY bytes is the longest frame: it must decode if some message allows it.
    for (size_t mi = 0; mi < g_msgs.size(); ++mi) {
        if (g_msgs[mi].b.max_payload != proto::MAX_PAYLOAD) continue;
        CONTEXT("max frame id 0x%02X", g_msgs[mi].id);
        const Bytes payload = random_payload(proto::MAX_PAYLOAD, false);
        const Bytes frame = make_frame(g_msgs[mi].id, 0xFF, g_msgs[mi].b.crc_extra, payload);
        CHECK(frame.size() == proto::MAX_FRAME);
        FrameDecoder dec3;
        const std::vector<Decoded> got3 = feed(dec3, frame);
        CHECK(got3.size() == 1 && got3[0].result == FrameDecoder::FRAME && got3[0].payload == payload);
    }
}

static void test_empty_chunks() {
    CONTEXT("empty chunks");
    FrameDecoder dec;
    bool quiet = true;
    for (int i = 0; i < 10; ++i) quiet = quiet && dec.push(0x00) == FrameDecoder::NONE;
    CHECK(quiet);
    CHECK(same_stats(dec.stats(), zero_stats()));

    const Item a = good_item(g_msgs[0]);
    const Item b = good_item(g_msgs[g_msgs.size() - 1]);
    Bytes stream(2, 0);
    append(stream, a.wire);
    stream.push_back(0);
    stream.push_back(0);
    append(stream, b.wire);
    stream.push_back(0);
    const std::vector<Decoded> got = feed(dec, stream);
    CHECK(got.size() == 2 && same_decoded(got[0], a.expect) && same_decoded(got[1], b.expect));
    DecoderStats s = zero_stats();
    s.frames_ok = 2;
    CHECK(same_stats(dec.stats(), s));
}

// The checks run in the documented order: each case breaks two rules, the earlier one wins.
static void test_error_order() {
    const Msg& msg = g_msgs[0];
    struct Case {
        const char* name;
        Bytes wire;
        FrameDecoder::Result expect;
    };
    std::vector<Case> cases;
    {  // truncated block that would also be too short: COBS first
        Case c = {"cobs before length", Bytes(), FrameDecoder::ERR_COBS};
        c.wire.push_back(0x06);  // promises 5 data bytes, only 2 follow
        c.wire.push_back(0x01);
        c.wire.push_back(0x02);
        c.wire.push_back(0);
        cases.push_back(c);
    }
    {  // a full 0xFF block never completes inside a frame-sized chunk
        Case c = {"0xFF block", Bytes(), FrameDecoder::ERR_COBS};
        c.wire.push_back(0xFF);
        for (int i = 0; i < 10; ++i) c.wire.push_back(static_cast<uint8_t>(i + 1));
        c.wire.push_back(0);
        cases.push_back(c);
    }
    if (g_unknown_id >= 0) {
        Bytes body(3, static_cast<uint8_t>(g_unknown_id));
        Case c = {"short before unknown", wire_from_body(body), FrameDecoder::ERR_LENGTH};
        cases.push_back(c);
        Bytes junk = ref_body(static_cast<uint8_t>(g_unknown_id), 1, Bytes(3, 7), 0);
        junk[junk.size() - 1] ^= 0xFF;
        Case c2 = {"unknown before crc", wire_from_body(junk), FrameDecoder::ERR_UNKNOWN_ID};
        cases.push_back(c2);
    }
    for (size_t mi = 0; mi < g_msgs.size(); ++mi) {  // both length limits of every message
        for (int below = 0; below < 2; ++below) {
            const int bad = bad_length(g_msgs[mi].b, below != 0);
            if (bad < 0) continue;
            Bytes body = ref_body(g_msgs[mi].id, 1, Bytes(static_cast<size_t>(bad), 0x11),
                                  g_msgs[mi].b.crc_extra);
            Case c = {below ? "payload too short" : "payload too long", wire_from_body(body),
                      FrameDecoder::ERR_LENGTH};
            cases.push_back(c);
            body[body.size() - 1] ^= 0x10;
            Case c2 = {"crc before length", wire_from_body(body), FrameDecoder::ERR_CRC};
            cases.push_back(c2);
        }
    }
    {  // exactly 4 bytes: a frame with an empty payload is not a length error per se
        Bytes body = ref_body(msg.id, 9, Bytes(), msg.b.crc_extra);
        Case c = {"empty payload", wire_from_body(body),
                  msg.b.min_payload == 0 ? FrameDecoder::FRAME : FrameDecoder::ERR_LENGTH};
        cases.push_back(c);
    }
    for (size_t i = 0; i < cases.size(); ++i) {
        CONTEXT("error order: %s", cases[i].name);
        FrameDecoder dec;
        const std::vector<Decoded> got = feed(dec, cases[i].wire);
        CHECK(got.size() == 1 && got[0].result == cases[i].expect);
        if (cases[i].expect != FrameDecoder::FRAME) {
            CHECK(dec.stats().bytes_discarded == cases[i].wire.size() - 1);
        }
    }
}

static void test_reset() {
    CONTEXT("reset");
    const Item a = good_item(g_msgs[0]);
    FrameDecoder dec;
    for (size_t i = 0; i < a.wire.size() / 2; ++i) dec.push(a.wire[i]);
    dec.reset();
    const std::vector<Decoded> got = feed(dec, a.wire);
    CHECK(got.size() == 1 && same_decoded(got[0], a.expect));
}

static void test_encode_frame_limits() {
    for (int len = 0; len <= proto::MAX_PAYLOAD; len += 7) {
        const Bytes payload = random_payload(static_cast<size_t>(len), true);
        const size_t need = frame_size(static_cast<uint8_t>(len));
        CHECK(need == static_cast<size_t>(len) + 6);
        for (size_t cap = 0; cap <= need; ++cap) {
            CONTEXT("encode_frame len %d cap %zu", len, cap);
            Bytes out(cap);  // exact size so ASan catches any write past cap
            const size_t n = encode_frame(0x42, 7, 0x99, payload.data(), static_cast<uint8_t>(len),
                                          cap ? out.data() : NULL, cap);
            CHECK(n == (cap == need ? need : 0));
        }
    }
    CONTEXT("encode_frame limits");
    Bytes big(proto::MAX_PAYLOAD + 1, 0x55);
    Bytes out(512);
    CHECK(encode_frame(1, 2, 3, big.data(), static_cast<uint8_t>(big.size()), out.data(), out.size()) == 0);
    CHECK(encode_frame(1, 2, 3, NULL, 5, out.data(), out.size()) == 0);
    CHECK(encode_frame(1, 2, 3, NULL, 0, out.data(), out.size()) == FRAME_OVERHEAD);
    CHECK(encode_frame(1, 2, 3, big.data(), 1, NULL, 100) == 0);

    // In place: a payload already sitting at out + 3 encodes to the same bytes.
    for (int len = 0; len <= proto::MAX_PAYLOAD; ++len) {
        CONTEXT("encode_frame in place len %d", len);
        const Bytes payload = random_payload(static_cast<size_t>(len), true);
        const uint8_t id = static_cast<uint8_t>(len % 3 == 0 ? 0 : len);  // zero ids too
        const Bytes ref = make_frame(id, static_cast<uint8_t>(len * 5), 0x21, payload);
        Bytes buf(frame_size(static_cast<uint8_t>(len)));
        if (len > 0) memcpy(buf.data() + 3, payload.data(), payload.size());
        CHECK(encode_frame(id, static_cast<uint8_t>(len * 5), 0x21, buf.data() + 3,
                           static_cast<uint8_t>(len), buf.data(), buf.size()) == buf.size());
        CHECK(buf == ref);
    }
}

// Every generated message: the generated dispatchers unpack a payload into its struct, and
// the handler checks encode_message() against encode_frame() and decodes the result again.
struct MessageRoundTrip {
    unsigned handled;
    uint8_t seq;

    template <class M>
    void handle(const M& m, uint8_t) {
        uint8_t packed[proto::MAX_PAYLOAD];
        const uint8_t plen = proto::pack(m, packed);
        M back = M();
        if (!proto::unpack(packed, plen, back)) {
            // A reliable request: the dispatcher left its values to check_ranges(), which refuses
            // them (the firmware answers NACK(OUT_OF_RANGE)); unpack() of the message alone does.
            CHECK(proto::check_ranges(m) != proto::ALL_FIELDS_VALID);
            return;
        }
        ++handled;
        CHECK(plen >= M::PAYLOAD_SIZE && plen <= M::PAYLOAD_MAX);

        Bytes out(frame_size(M::PAYLOAD_MAX));  // exact: ASan sees a pack() past PAYLOAD_MAX
        const size_t n = encode_message(m, seq, out.data(), out.size());
        CHECK(n == frame_size(plen));
        out.resize(n);
        CHECK(out == make_frame(M::ID, seq, M::CRC_EXTRA, Bytes(packed, packed + plen)));

        FrameDecoder dec;
        const std::vector<Decoded> got = feed(dec, out);
        CHECK(got.size() == 1 && got[0].result == FrameDecoder::FRAME && got[0].id == M::ID &&
              got[0].seq == seq);
        back = M();
        CHECK(proto::unpack(dec.payload(), dec.payload_len(), back));
        uint8_t repacked[proto::MAX_PAYLOAD];
        CHECK(proto::pack(back, repacked) == plen && memcmp(repacked, packed, plen) == 0);

        Bytes small(frame_size(M::PAYLOAD_MAX) - 1);
        CHECK(encode_message(m, seq, small.data(), small.size()) == 0);
        CHECK(encode_message(m, seq, NULL, 1000) == 0);
    }
};

// Payload candidates, from random bytes to small values that pass enum and range checks.
static Bytes candidate_payload(size_t len, int attempt) {
    if (attempt < 2) return random_payload(len, true);
    if (attempt < 6) {
        Bytes p(len);
        for (size_t i = 0; i < len; ++i) p[i] = rnd() & 1;
        return p;
    }
    return Bytes(len, attempt == 6 ? 1 : 0);
}

static void test_messages() {
    for (size_t mi = 0; mi < g_msgs.size(); ++mi) {
        const Msg& msg = g_msgs[mi];
        MessageRoundTrip h;
        h.handled = 0;
        for (int len = msg.b.min_payload; len <= msg.b.max_payload; ++len) {
            for (int attempt = 0; attempt < 8; ++attempt) {
                CONTEXT("message 0x%02X len %d attempt %d", msg.id, len, attempt);
                const Bytes p = candidate_payload(static_cast<size_t>(len), attempt);
                h.seq = rnd();
                const uint8_t plen = static_cast<uint8_t>(len);
                proto::DispatchResult r = proto::dispatch_host_to_mcu(msg.id, h.seq, p.data(), plen, h);
                if (r == proto::DISPATCH_WRONG_DIRECTION) {
                    r = proto::dispatch_mcu_to_host(msg.id, h.seq, p.data(), plen, h);
                }
                CHECK(r == proto::DISPATCH_OK || r == proto::DISPATCH_BAD_PAYLOAD);
                if (h.handled > 0) break;
            }
        }
        CONTEXT("message 0x%02X", msg.id);
        CHECK(h.handled > 0);  // at least one payload of this message was accepted and checked
    }
}

int main() {
    discover_messages();
    printf("protocol: %zu message ids, MAX_PAYLOAD %u, MAX_BODY %u, MAX_FRAME %u, "
           "sizeof(FrameDecoder) %zu\n",
           g_msgs.size(), proto::MAX_PAYLOAD, proto::MAX_BODY, proto::MAX_FRAME, sizeof(FrameDecoder));
    CHECK(!g_msgs.empty());
    if (g_msgs.empty()) {
        return check_summary();
    }
    test_crc();
    test_cobs_vectors();
    test_cobs_roundtrip();
    test_cobs_invalid();
    test_single_frames();
    test_stream_with_garbage();
    test_join_at_every_offset();
    test_bit_flips();
    test_overlong();
    test_empty_chunks();
    test_error_order();
    test_reset();
    test_encode_frame_limits();
    test_messages();
    return check_summary();
}
