// Native unit tests of the quadrature decoder (arduino/RoverLink/src/hal/avr/quadrature.h).
//
//   test_quadrature          run the tests; the last line is "N passed, 0 failed"
//   test_quadrature --dump   print every table entry as "X4 <prev> <cur> <delta|INVALID>" for the
//                            independent Python oracle in tests/firmware/test_encoder_decoding.py
//
// The expectation here is derived from encoder *positions*, not from the tables' layout: the four
// channel levels are the four positions of one cycle (Gray code), a step of +1 position crosses
// one edge forward, -1 crosses it backward, 2 is a missed edge.
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "hal/avr/quadrature.h"

using roverlink::quadrature::Decoder;
using roverlink::quadrature::INVALID;
using roverlink::quadrature::Resolution;
using roverlink::quadrature::step;

namespace {

int passed = 0;
int failed = 0;

void check(bool ok, const char* what, int line) {
    if (ok) {
        ++passed;
    } else {
        ++failed;
        printf("FAIL line %d: %s\n", line, what);
    }
}

#define CHECK(cond) check((cond), #cond, __LINE__)
#define CHECK_EQ(a, b)                                                                        \
    do {                                                                                      \
        const long long a_ = static_cast<long long>(a), b_ = static_cast<long long>(b);       \
        if (a_ != b_) printf("  %s = %lld, %s = %lld\n", #a, a_, #b, b_);                   \
        check(a_ == b_, #a " == " #b, __LINE__);                                              \
    } while (0)

const Resolution RESOLUTIONS[] = {Resolution::X1, Resolution::X2, Resolution::X4};
const char* name_of(Resolution r) { return r == Resolution::X1 ? "X1" : r == Resolution::X2 ? "X2" : "X4"; }

// Forward Gray sequence: position p has levels SEQUENCE[p] = (A << 1) | B.
const uint8_t SEQUENCE[4] = {0 /*00*/, 2 /*10*/, 3 /*11*/, 1 /*01*/};

int position_of(uint8_t ab) {
    for (int p = 0; p < 4; ++p) {
        if (SEQUENCE[p] == ab) return p;
    }
    return -1;
}

// Edge e lies between positions e and e+1: 0 = A rises, 1 = B rises, 2 = A falls, 3 = B falls.
bool edge_counts(Resolution r, int edge) {
    switch (r) {
        case Resolution::X4: return true;
        case Resolution::X2: return edge == 0 || edge == 2;  // edges of channel A
        case Resolution::X1: return edge == 0;               // A rising only
    }
    return false;
}

int expected_delta(Resolution r, uint8_t prev, uint8_t cur) {
    const int from = position_of(prev), to = position_of(cur);
    const int moved = (to - from + 4) % 4;
    if (moved == 0) return 0;
    if (moved == 2) return INVALID;
    if (moved == 1) return edge_counts(r, from) ? 1 : 0;
    return edge_counts(r, to) ? -1 : 0;  // moved back over the edge between `to` and `from`
}

void test_every_transition() {
    for (Resolution r : RESOLUTIONS) {
        int valid_moves = 0, invalid = 0, counted = 0;
        for (uint8_t prev = 0; prev < 4; ++prev) {
            for (uint8_t cur = 0; cur < 4; ++cur) {
                const int got = step(r, prev, cur), want = expected_delta(r, prev, cur);
                if (got != want) printf("  %s %u%u -> %u%u: got %d, want %d\n", name_of(r), prev >> 1, prev & 1,
                                        cur >> 1, cur & 1, got, want);
                CHECK(got == want);
                if (want == INVALID) ++invalid;
                else if (prev != cur) ++valid_moves;
                if (want == 1 || want == -1) ++counted;
            }
        }
        CHECK_EQ(invalid, 4);      // 00<->11 and 01<->10
        CHECK_EQ(valid_moves, 8);  // 4 edges, each both ways
        CHECK_EQ(counted, 2 * static_cast<int>(r));
    }
}

void test_only_low_two_bits_matter() {
    for (Resolution r : RESOLUTIONS) {
        for (uint8_t prev = 0; prev < 16; ++prev) {
            for (uint8_t cur = 0; cur < 16; ++cur) {
                CHECK_EQ(step(r, prev, cur), step(r, prev & 3u, cur & 3u));
            }
        }
    }
}

// Turn `cycles` full cycles forward (or backward) starting at each of the four positions.
void test_full_cycles_both_directions() {
    for (Resolution r : RESOLUTIONS) {
        for (int start = 0; start < 4; ++start) {
            for (int direction = -1; direction <= 1; direction += 2) {
                Decoder d;
                d.reset(r, SEQUENCE[start]);
                const int cycles = 25;
                int p = start;
                for (int i = 0; i < 4 * cycles; ++i) {
                    p = (p + direction + 4) % 4;
                    d.update(SEQUENCE[p]);
                }
                CHECK_EQ(d.count, direction * cycles * static_cast<int>(r));
                CHECK_EQ(d.errors, 0);
                CHECK_EQ(d.ab, SEQUENCE[start]);
            }
        }
    }
}

// A shaft resting on an edge makes that edge chatter: the count must come back every time.
void test_dither_on_every_edge_cancels() {
    for (Resolution r : RESOLUTIONS) {
        for (int edge = 0; edge < 4; ++edge) {
            Decoder d;
            d.reset(r, SEQUENCE[edge]);
            for (int i = 0; i < 101; ++i) {
                d.update(SEQUENCE[(edge + 1) % 4]);
                CHECK_EQ(d.count, edge_counts(r, edge) ? 1 : 0);
                d.update(SEQUENCE[edge]);
                CHECK_EQ(d.count, 0);
            }
            CHECK_EQ(d.errors, 0);
        }
    }
}

void test_repeated_level_is_no_move() {
    for (Resolution r : RESOLUTIONS) {
        for (uint8_t ab = 0; ab < 4; ++ab) {
            Decoder d;
            d.reset(r, ab);
            d.update(ab);
            d.update(ab);
            CHECK_EQ(d.count, 0);
            CHECK_EQ(d.errors, 0);
        }
    }
}

void test_invalid_transitions_count_errors_not_counts() {
    for (Resolution r : RESOLUTIONS) {
        Decoder d;
        d.reset(r, 0);
        d.update(2);  // 00 -> 10: +1 in every resolution
        CHECK_EQ(d.count, 1);
        d.update(1);  // 10 -> 01: both changed
        CHECK_EQ(d.count, 1);
        CHECK_EQ(d.errors, 1);
        CHECK_EQ(d.ab, 1);  // decoding resumes from the level actually seen
        d.update(0);        // 01 -> 00: +1 in X4 only
        CHECK_EQ(d.count, r == Resolution::X4 ? 2 : 1);
        d.update(3);  // 00 -> 11: both changed
        d.update(0);  // 11 -> 00: both changed
        CHECK_EQ(d.errors, 3);
    }
}

void test_error_counter_saturates() {
    Decoder d;
    d.reset(Resolution::X4, 0);
    d.errors = 0xFFFEu;
    d.update(3);
    d.update(0);
    d.update(3);
    CHECK_EQ(d.errors, 0xFFFFu);
}

// The count is a cumulative i32 that the host unwraps: it must wrap, not overflow (UBSan watches).
void test_count_wraps_at_i32_limits() {
    Decoder d;
    d.reset(Resolution::X4, 0);
    d.count = INT32_MAX;
    d.update(2);  // +1
    CHECK_EQ(d.count, INT32_MIN);
    d.update(0);  // -1
    CHECK_EQ(d.count, INT32_MAX);
}

void test_reset_clears_and_keeps_level() {
    Decoder d;
    d.reset(Resolution::X2, 0);
    d.update(2);
    d.update(1);
    d.reset(Resolution::X4, 7);
    CHECK_EQ(d.count, 0);
    CHECK_EQ(d.errors, 0);
    CHECK_EQ(d.ab, 3);
    d.update(1);  // 11 -> 01: forward A falls, counted in X4
    CHECK_EQ(d.count, 1);
}

void dump() {
    for (Resolution r : RESOLUTIONS) {
        for (uint8_t prev = 0; prev < 4; ++prev) {
            for (uint8_t cur = 0; cur < 4; ++cur) {
                const int8_t d = step(r, prev, cur);
                if (d == INVALID) printf("%s %u%u %u%u INVALID\n", name_of(r), prev >> 1, prev & 1, cur >> 1, cur & 1);
                else printf("%s %u%u %u%u %d\n", name_of(r), prev >> 1, prev & 1, cur >> 1, cur & 1, d);
            }
        }
    }
}

}  // namespace

int main(int argc, char** argv) {
    if (argc > 1 && strcmp(argv[1], "--dump") == 0) {
        dump();
        return 0;
    }
    test_every_transition();
    test_only_low_two_bits_matter();
    test_full_cycles_both_directions();
    test_dither_on_every_edge_cancels();
    test_repeated_level_is_no_move();
    test_invalid_transitions_count_errors_not_counts();
    test_error_counter_saturates();
    test_count_wraps_at_i32_limits();
    test_reset_clears_and_keeps_level();
    printf("%d passed, %d failed\n", passed, failed);
    return failed == 0 ? 0 : 1;
}
