#include "control.h"

#include "../wire/compiler.h"
#include "../hal/board.h"

namespace roverlink {
namespace control {

int32_t round_half_away(float x) {
    // Callers keep |x| well inside int32 (speeds, efforts, angles, pulse widths).
    return x >= 0.0f ? static_cast<int32_t>(x + 0.5f) : -static_cast<int32_t>(0.5f - x);
}

// Out of line (as div_round and signed_mul_round): each has several callers, and an inlined copy
// per caller costs more AVR flash than the call.
ROVERLINK_NOINLINE int16_t round_to_i16(float x) {
    if (!(x == x)) {
        return 0;  // NaN
    }
    const float lim = 32767.0f;
    return static_cast<int16_t>(round_half_away(x > lim ? lim : (x < -lim - 1.0f ? -lim - 1.0f : x)));
}

ROVERLINK_NOINLINE int32_t div_round(int32_t a, int32_t b) {
    return a >= 0 ? (a + b / 2) / b : -((-a + b / 2) / b);
}

uint32_t mul_round(uint16_t x, uint8_t whole, uint32_t frac) {
    // x * frac / 2^32 + 1/2, from two 16 x 16 -> 32-bit products: exact floor of the sum.
    const uint32_t a = static_cast<uint32_t>(x) * static_cast<uint16_t>(frac >> 16);
    const uint32_t c = static_cast<uint32_t>(x) * static_cast<uint16_t>(frac) + 0x80000000UL;
    return static_cast<uint32_t>(whole) * x + ((a + (c >> 16)) >> 16);
}

int16_t pid_step(const Gains& g, float r, int16_t m, int16_t m_prev, float max_effort, float& integral,
                 bool& saturated) {
    // A lowered max_effort bounds the integrator from this tick on, integrating or not.
    integral = integral > max_effort ? max_effort : (integral < -max_effort ? -max_effort : integral);
    const float e = r - static_cast<float>(m);
    // Derivative on the measurement (no kick on setpoint steps): -kd * (m - m_prev) / dt.
    const float d = g.kd * static_cast<float>((static_cast<int32_t>(m_prev) - m) * static_cast<int32_t>(proto::CONTROL_RATE_HZ));
    // Static friction is fed forward with the setpoint's sign, so a wheel starting from rest or
    // reversing gets its breakaway effort at once instead of waiting for the integrator to learn it.
    const float s = r > 0.0f ? g.ks : (r < 0.0f ? -g.ks : 0.0f);
    float u = g.kf * r + s + g.kp * e + integral + d;
    const bool high = u > max_effort;
    const bool low = u < -max_effort;
    saturated = high || low;
    // Conditional integration: only while unsaturated, or when the error pulls the output back.
    if (!saturated || (high && e < 0.0f) || (low && e > 0.0f)) {
        float i = integral + g.ki * e * DT_S;
        integral = i > max_effort ? max_effort : (i < -max_effort ? -max_effort : i);
    }
    if (high) {
        u = max_effort;
    } else if (low) {
        u = -max_effort;
    }
    return round_to_i16(u);
}

void limit_targets(int16_t (&t)[proto::WHEEL_COUNT], uint16_t max_speed) {
    static_assert(proto::WHEEL_COUNT == 2, "two targets");
    const int32_t a = t[0] < 0 ? -static_cast<int32_t>(t[0]) : t[0];
    const int32_t b = t[1] < 0 ? -static_cast<int32_t>(t[1]) : t[1];
    const int32_t peak = a > b ? a : b;
    if (peak <= max_speed) {
        return;
    }
    for (uint8_t w = 0; w < proto::WHEEL_COUNT; ++w) {
        // |t| <= peak <= 32768 and max_speed <= 20000 (spec): the product fits an int32.
        t[w] = static_cast<int16_t>(div_round(static_cast<int32_t>(t[w]) * max_speed, peak));
    }
}

ROVERLINK_NOINLINE int32_t ramp_step(int32_t ramped, int32_t target, uint16_t up, uint16_t down) {
    const int32_t diff = target - ramped;
    // Speeding up (|target| > |ramped| on ramped's side of zero, or from 0) is exactly a step away
    // from zero; everything else (slowing down, reversing through zero) uses the decel limit.
    const int32_t limit = (diff > 0 ? ramped >= 0 : ramped <= 0) ? up : down;
    if (diff > limit) {
        return ramped + limit;
    }
    if (diff < -limit) {
        return ramped - limit;
    }
    return target;
}

float mm_s_per_count(const proto::SetConfig& c) {
    const float cpr = c.encoder_cpr != 0 ? static_cast<float>(c.encoder_cpr) : 1.0f;
    return PI_F * static_cast<float>(c.wheel_diameter_um) / 1000.0f / cpr / DT_S;
}

int16_t measure_speed(int32_t delta_counts, float mm_s_per_count_, uint16_t periods) {
    if (periods == 0) {
        periods = 1;
    }
    return round_to_i16(static_cast<float>(delta_counts) * mm_s_per_count_ / static_cast<float>(periods));
}

// 18000 / (1000 pi) = 5 + 0xBAC59EE1 / 2^32 and 1000 pi / 18000 = 0x2CAE3096 / 2^32.
static const uint32_t CDEG_PER_MRAD_FRAC = 0xBAC59EE1UL;
static const uint32_t MRAD_PER_CDEG_FRAC = 0x2CAE3096UL;

ROVERLINK_NOINLINE static int16_t signed_mul_round(int16_t x, uint8_t whole, uint32_t frac) {
    const uint16_t mag = static_cast<uint16_t>(x < 0 ? -static_cast<int32_t>(x) : x);
    const int16_t r = static_cast<int16_t>(mul_round(mag, whole, frac));
    return x < 0 ? static_cast<int16_t>(-r) : r;
}

static uint16_t magnitude(int16_t x) {
    return x < 0 ? static_cast<uint16_t>(0u - static_cast<uint16_t>(x)) : static_cast<uint16_t>(x);
}

static int16_t clamp16(int16_t x, int16_t lo, int16_t hi) { return x < lo ? lo : (x > hi ? hi : x); }

uint16_t steering_cdeg(int16_t mrad, const proto::SetConfig& c) {
    // mrad is within SET_ACKERMANN's range (check_ranges) and the angles within 0..180 degrees, so
    // int16 holds it all.
    const int16_t center = static_cast<int16_t>(c.steering_center_cdeg);
    const int16_t lo = static_cast<int16_t>(c.steering_min_cdeg);
    const int16_t hi = static_cast<int16_t>(c.steering_max_cdeg);
    const int16_t m = clamp16(mrad, proto::SetAckermann::STEERING_MRAD_MIN, proto::SetAckermann::STEERING_MRAD_MAX);
    int16_t s = clamp16(static_cast<int16_t>(center + signed_mul_round(m, 5, CDEG_PER_MRAD_FRAC)), lo, hi);
    const int16_t step = static_cast<int16_t>(c.steering_step_cdeg);
    if (step > 0) {
        const int16_t off = static_cast<int16_t>(s - center);
        const int16_t mag = static_cast<int16_t>(((off < 0 ? -off : off) + step / 2) / step);
        s = clamp16(static_cast<int16_t>(center + step * (off < 0 ? -mag : mag)), lo, hi);
    }
    return static_cast<uint16_t>(s < 0 ? 0 : s);
}

int16_t steering_mrad(uint16_t cdeg, const proto::SetConfig& c) {
    const int16_t offset = static_cast<int16_t>(static_cast<int16_t>(cdeg) - static_cast<int16_t>(c.steering_center_cdeg));
    return signed_mul_round(offset, 0, MRAD_PER_CDEG_FRAC);
}

uint16_t servo_pulse_us(uint16_t cdeg, const proto::SetConfig& c) {
    const int32_t span = static_cast<int32_t>(c.servo_max_us) - static_cast<int32_t>(c.servo_min_us);
    return static_cast<uint16_t>(c.servo_min_us + div_round(static_cast<int32_t>(cdeg) * span, 18000));
}

ROVERLINK_NOINLINE uint16_t esc_pulse_us(int16_t u, const proto::SetConfig& c) {
    const int32_t neutral = c.esc_neutral_us;
    const int32_t span = u >= 0 ? static_cast<int32_t>(c.esc_max_us) - neutral : neutral - static_cast<int32_t>(c.esc_min_us);
    return static_cast<uint16_t>(neutral + div_round(static_cast<int32_t>(u) * span, 1000));
}

uint8_t lights_for(const proto::SetLights& host, proto::SessionState state, int16_t left, int16_t right,
                   int16_t steer_cdeg, bool ackermann, uint8_t blink) {
    const uint8_t LEFT = Lights::FRONT_LEFT | Lights::REAR_LEFT;
    const uint8_t RIGHT = Lights::FRONT_RIGHT | Lights::REAR_RIGHT;
    const uint8_t FRONT = Lights::FRONT_LEFT | Lights::FRONT_RIGHT;
    const uint8_t REAR = Lights::REAR_LEFT | Lights::REAR_RIGHT;
    const uint8_t ALL = LEFT | RIGHT;
    const uint8_t half = BLINK_PERIOD_TICKS / 2;
    const bool on = blink < half;                                          // 1.5 Hz
    const bool fast = (on ? blink : static_cast<uint8_t>(blink - half)) < BLINK_PERIOD_TICKS / 4;  // 3 Hz
    if (state == proto::SessionState::FAILSAFE) {
        return fast ? ALL : 0;  // in every mode
    }
    if (host.mode != proto::LightsMode::AUTO) {
        if (host.mode != proto::LightsMode::MANUAL) {
            return 0;  // OFF
        }
        return static_cast<uint8_t>(host.steady | (on ? host.slow : 0) | (fast ? host.fast : 0));
    }
    if (state != proto::SessionState::ARMED) {
        return on ? FRONT : REAR;  // BOOT, IDLE, DISARMED: front and rear pairs alternate
    }
    if (!on) {
        return 0;
    }
    if (ackermann) {
        return steer_cdeg > 0 ? LEFT : (steer_cdeg < 0 ? RIGHT : 0);
    }
    if ((left > 0 && right < 0) || (left < 0 && right > 0)) {
        return ALL;  // rotating in place: hazard
    }
    // right - left > max(|left|, |right|) / 8, in integers: turn > floor(mag / 8).
    const uint16_t ml = magnitude(left);
    const uint16_t mr = magnitude(right);
    const int32_t eighth = (ml > mr ? ml : mr) / 8u;
    const int32_t turn = static_cast<int32_t>(right) - left;  // > 0: the heading turns left
    if (turn > eighth) {
        return LEFT;
    }
    if (-turn > eighth) {
        return RIGHT;
    }
    return 0;
}

}  // namespace control
}  // namespace roverlink
