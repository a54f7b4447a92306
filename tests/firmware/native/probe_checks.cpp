// The generated checks for what the real spec does not use yet: an enum with gaps, a signed and a
// negative float range, a flags mask with gaps, ASCII bytes in a variable-length field. Compiled
// by tests/firmware/native/test_probe_checks.py against code generated from the spec plus the PROBE message
// that test adds; the last line reads "N passed, M failed".
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "generated/roverlink_protocol.h"

using namespace roverlink;

static float f32(uint32_t bits) {
    float v;
    memcpy(&v, &bits, sizeof v);
    return v;
}

int main() {
    // PROBE: e (values 3, 7, 10, 12), s (-300..-100), f (-1.5..2.5), flags (bits 0x0105), text[..4]
    static_assert(proto::Probe::PAYLOAD_SIZE == 9 && proto::Probe::PAYLOAD_MAX == 13, "the probe's layout");
    uint8_t p[13] = {3, 0x9C, 0xFF, 0, 0, 0, 0, 0x05, 0x01, 'a', 'b', 'c', 'd'};
    proto::Probe m;
    for (int v = 0; v < 256; ++v) {
        CONTEXT("enum value %d", v);
        p[0] = static_cast<uint8_t>(v);
        CHECK(proto::unpack(p, 13, m) == (v == 3 || v == 7 || v == 10 || v == 12));
    }
    p[0] = 7;
    for (int bit = 0; bit < 16; ++bit) {
        CONTEXT("flag bit %d", bit);
        p[7] = static_cast<uint8_t>((1u << bit) & 0xFF);
        p[8] = static_cast<uint8_t>((1u << bit) >> 8);
        CHECK(proto::unpack(p, 13, m) == (((0x0105u >> bit) & 1u) != 0));
    }
    p[7] = 0x05;
    p[8] = 0x01;
    CONTEXT("text");
    CHECK(proto::unpack(p, 13, m) && m.text_len == 4 && m.text[3] == 'd' && m.flags == 0x0105);
    CHECK(proto::unpack(p, 10, m) && m.text_len == 1 && m.s == -100);
    p[11] = 0x80;
    CHECK(!proto::unpack(p, 13, m));
    CHECK(proto::unpack(p, 11, m));  // the bad byte is past the text's length
    CHECK(!proto::unpack(p, 8, m) && !proto::unpack(p, 14, m));
    // the dispatcher: the same message through its direction's unpack
    proto::HostToMcu u;
    CHECK(proto::unpack_host_to_mcu(proto::Probe::ID, p, 13, u) == proto::DISPATCH_BAD_PAYLOAD);
    p[11] = 'c';
    CHECK(proto::unpack_host_to_mcu(proto::Probe::ID, p, 13, u) == proto::DISPATCH_OK && u.probe.text_len == 4);
    CHECK(proto::unpack_mcu_to_host(proto::Probe::ID, p, 13, *reinterpret_cast<proto::McuToHost*>(&u)) ==
          proto::DISPATCH_WRONG_DIRECTION);
    // check_ranges() names an undefined enum value, flag bit or char as out of range (field index).
    CHECK(proto::unpack(p, 13, m) && proto::check_ranges(m) == proto::ALL_FIELDS_VALID);
    m.e = static_cast<proto::ProbeKind>(4);
    CHECK(proto::check_ranges(m) == 0);
    m.e = proto::ProbeKind::TEN;
    m.flags = 0x0002;
    CHECK(proto::check_ranges(m) == 3);
    m.flags = 0x0100;
    m.text[2] = static_cast<char>(0x80);
    CHECK(proto::check_ranges(m) == 4);
    // A reliable request's dispatcher leaves its values to check_ranges() (the firmware NACKs them);
    // unpack() of the message alone still refuses them.
    const uint8_t req[4] = {2, 5, 0x02, 0x00};  // e = 5 (undefined), then flag bit 1 (undefined)
    proto::ProbeRequest r;
    CHECK(!proto::unpack(req, 4, r));
    CHECK(proto::unpack_host_to_mcu(proto::ProbeRequest::ID, req, 4, u) == proto::DISPATCH_OK);
    CHECK(proto::check_ranges(u.probe_request) == 1);
    const uint8_t bad_n[4] = {10, 5, 0x02, 0x00};
    CHECK(proto::unpack_host_to_mcu(proto::ProbeRequest::ID, bad_n, 4, u) == proto::DISPATCH_OK);
    CHECK(proto::check_ranges(u.probe_request) == 0);  // the first field, in order
    const uint8_t flags_only[4] = {2, 12, 0x02, 0x00};
    CHECK(proto::unpack_host_to_mcu(proto::ProbeRequest::ID, flags_only, 4, u) == proto::DISPATCH_OK);
    CHECK(proto::check_ranges(u.probe_request) == 2);
    // pack: the same bytes back.
    CHECK(proto::unpack(p, 12, m));
    uint8_t out[13];
    CHECK(proto::pack(m, out) == 12 && memcmp(out, p, 12) == 0);
    // check_ranges: signed and float ends, NaN, both zeros, infinities.
    struct Case {
        int16_t s;
        uint32_t f;
        uint8_t expected;
    };
    const Case cases[] = {
        {-300, 0x00000000, 0xFF}, {-100, 0x80000000, 0xFF}, {-301, 0, 1},          {-99, 0, 1},
        {0, 0, 1},                {32767, 0, 1},            {-32768, 0, 1},        {-200, 0xBFC00000, 0xFF},
        {-200, 0x40200000, 0xFF}, {-200, 0xBFC00001, 2},    {-200, 0x40200001, 2}, {-200, 0x7FC00000, 2},
        {-200, 0xFFC00000, 2},    {-200, 0x7F800000, 2},    {-200, 0xFF800000, 2}, {-200, 0x7F800001, 2},
        {-200, 0x3F800000, 0xFF}, {-200, 0xBF800000, 0xFF},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        CONTEXT("check_ranges case %zu", i);
        m.s = cases[i].s;
        m.f = f32(cases[i].f);
        CHECK(proto::check_ranges(m) == cases[i].expected);
    }
    return check_summary();
}
