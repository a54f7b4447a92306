#include "session.h"

namespace roverlink {

using proto::FailsafeReason;
using proto::NackReason;
using proto::SessionEvent;
using proto::SessionState;

namespace {

const uint32_t MS_PER_MICROS_WRAP = 4294967u;  // 2^32 us, in whole ms

// A compare, not a shift by the guard's number: at most one guard holds per event.
struct Guards {
    uint8_t holds;  // the guard that holds, or 0 (no guard is 0)
    bool check(proto::Guard g) const { return static_cast<uint8_t>(g) == holds; }
};
static_assert(static_cast<uint8_t>(proto::Guard::COMPATIBLE) != 0 &&
                  static_cast<uint8_t>(proto::Guard::BOOT_ID_MATCHES) != 0,
              "0 must mean no guard holds");

// Four Feistel rounds over the halves of x: the high half, multiplied (16 x 16 -> 32 bits, folded
// to 16), is XORed into the low one, and the halves swap. Every input bit affects every output bit,
// and no 32-bit multiply routine is needed. The halves are copied out and back, not shifted:
// avr-gcc rebuilds a shifted 32-bit value byte by byte. (half[0] is the low half on AVR and x86;
// on a big-endian CPU the roles swap, which mixes just as well.)
uint32_t mix32(uint32_t x) {
    uint16_t half[2];
    memcpy(half, &x, sizeof x);
    uint16_t lo = half[0];
    uint16_t hi = half[1];
    for (uint8_t i = 0; i < 4; ++i) {
        const uint32_t p = static_cast<uint32_t>(hi) * 0x9E37u;
        const uint16_t t = static_cast<uint16_t>(lo ^ static_cast<uint16_t>(static_cast<uint16_t>(p >> 16) +
                                                                           static_cast<uint16_t>(p)));
        lo = hi;
        hi = t;
    }
    half[0] = lo;
    half[1] = hi;
    memcpy(&x, half, sizeof x);
    return x;
}

// floor(us / 1000) without a division routine: us / 8 / 125 by shift and subtract, the quotient's
// bits entering x from the right as the dividend's leave it on the left (the low 3 bits are never
// brought down: they only make up the / 8).
uint32_t ms_of(uint32_t us) {
    uint32_t x = us;
    uint8_t r = 0;  // < 125
    for (uint8_t i = 29; i != 0; --i) {
        r = static_cast<uint8_t>(r << 1);
        if (x & 0x80000000UL) {
            ++r;
        }
        x <<= 1;
        if (r >= 125u) {
            r = static_cast<uint8_t>(r - 125u);
            x |= 1u;
        }
    }
    return x & 0x1FFFFFFFUL;
}

uint16_t magnitude(int16_t x) {
    return x < 0 ? static_cast<uint16_t>(0u - static_cast<uint16_t>(x)) : static_cast<uint16_t>(x);
}

}  // namespace

ROVERLINK_NOINLINE uint8_t SessionCore::checked_speed(int16_t a, int16_t b, uint16_t max, uint8_t other) {
    return magnitude(a) > max ? 0 : (magnitude(b) > max ? 1 : other);
}

// v_ is set by reset() (begin()); until then only the state is read: BOOT, begin() not run yet.
SessionCore::SessionCore(Stream& port, Board& board, const Robot& robot)
    : board_(board), robot_(robot), link_(port) {
    v_.state = SessionState::BOOT;
}

void SessionCore::reset(uint32_t boot_counter, const proto::SetConfig& config) {
    memset(&v_, 0, sizeof v_);  // all plain data; 0 is BOOT, NONE, STREAM
    v_.watchdog_ms = config.watchdog_ms;
    v_.feedback_hz = config.feedback_hz;
    // boot_id: the EEPROM boot counter and the clock mixed with four entropy() samples; never 0.
    uint32_t id = boot_counter ^ clock();
    for (uint8_t i = 0; i < 4; ++i) {
        id = mix32(id ^ board_.entropy());
    }
    v_.boot_id = id != 0 ? id : 1;
}

ROVERLINK_OUT_OF_LINE uint32_t SessionCore::clock() {
    const uint32_t now = board_.micros();
    if (now < v_.last_micros) {
        v_.wrapped_ms += MS_PER_MICROS_WRAP;
    }
    v_.last_micros = now;
    return now;
}

uint16_t SessionCore::step(SessionEvent ev, uint8_t guard, SessionState& from) {
    Guards guards = {guard};
    const proto::StepResult r = proto::step(v_.state, ev, guards);
    from = v_.state;
    if (!r.matched) {
        return 0;
    }
    v_.state = r.target;
    return r.actions;
}

void SessionCore::perform(uint16_t a, SessionEvent ev, SessionState from, FailsafeReason reason,
                   const proto::SetConfig& config) {
    if (a & proto::Action::CLEAR_REASON) {
        v_.reason = FailsafeReason::NONE;
    }
    if (a & proto::Action::LATCH_REASON) {
        v_.reason = reason;
    }
    if (a & proto::Action::FEED_WATCHDOG) {
        v_.last_valid_us = clock();
    }
    if (a & proto::Action::ANNOUNCE) {
        send_identity(proto::IdentityReason::BOOT, config);
    }
    if (a & proto::Action::REJECT_HELLO) {
        v_.fb_countdown = 0;
        send_identity(proto::IdentityReason::HELLO_REJECTED, config);
    }
    if (a & proto::Action::ACK) {
        answer(0, 0);
    }
    if (a & proto::Action::NACK) {
        // "The reason for this state" (docs/control.md 1 and 3).
        NackReason why = NackReason::NO_SESSION;
        uint8_t detail = 0;
        if (from != SessionState::IDLE) {
            if (ev == SessionEvent::ARM) {
                why = NackReason::BOOT_ID_MISMATCH;
            } else if (from == SessionState::FAILSAFE) {
                why = NackReason::FAILSAFE;
                detail = static_cast<uint8_t>(v_.reason);
            } else {
                why = NackReason::NOT_ARMED;
            }
        }
        if (ev == SessionEvent::SETPOINT) {
            send_answer(static_cast<uint8_t>(why), detail);  // setpoints are not reliable: not remembered
        } else {
            answer(static_cast<uint8_t>(why), detail);
        }
    }
}

namespace {

// Every request that is not PLAIN has its id in KIND_BASE .. KIND_BASE + 15, and its Kind in two
// bits of a constant at 2 * (id - KIND_BASE): one shift, no chain of compares (nor a switch, which
// avr-gcc turns into a lookup table in SRAM).
const uint8_t KIND_BASE = proto::Arm::ID;

constexpr uint32_t kind_bits(uint8_t id, uint32_t kind) {
    return id >= KIND_BASE && id - KIND_BASE < 16 ? kind << (2 * (id - KIND_BASE)) : 0xFFFFFFFFUL;
}

}  // namespace

SessionCore::Kind SessionCore::kind_of(uint8_t id) {
    const uint32_t KINDS = kind_bits(proto::Arm::ID, TABLE) | kind_bits(proto::Disarm::ID, TABLE) |
                           kind_bits(proto::GetPid::ID, QUERY) | kind_bits(proto::GetConfig::ID, QUERY) |
                           kind_bits(proto::GetLinkStats::ID, QUERY) | kind_bits(proto::SetPid::ID, RELIABLE) |
                           kind_bits(proto::SetConfig::ID, RELIABLE) | kind_bits(proto::SaveConfig::ID, RELIABLE) |
                           kind_bits(proto::ResetOdometry::ID, RELIABLE) | kind_bits(proto::SetLights::ID, RELIABLE) |
                           kind_bits(proto::GetLights::ID, QUERY);
    static_assert(KINDS != 0xFFFFFFFFUL, "a request id is outside KIND_BASE .. KIND_BASE + 15");
    const uint8_t i = static_cast<uint8_t>(id - KIND_BASE);
    return i < 16 ? static_cast<Kind>((KINDS >> (2 * i)) & 3u) : PLAIN;  // HELLO, PING, setpoints
}

ROVERLINK_OUT_OF_LINE bool SessionCore::request(uint8_t msg_id, uint8_t seq) {
    Vars& v = v_;
    v.req_id = msg_id;
    v.req_seq = seq;
    const Kind kind = kind_of(msg_id);
    if (kind == PLAIN) {
        return true;
    }
    if (v.dup_valid && v.dup_id == msg_id && v.dup_seq == seq) {
        link_.count_duplicate();
        if (kind != QUERY) {
            send_answer(v.dup_reason, v.dup_detail);  // answered again, not applied again
            return false;
        }
    } else {
        v.dup_valid = true;
        v.dup_id = msg_id;
        v.dup_seq = seq;
        v.dup_reason = 0;
        v.dup_detail = 0;
    }
    if (kind != TABLE && v.state == SessionState::IDLE) {
        answer(static_cast<uint8_t>(NackReason::NO_SESSION), 0);
        return false;
    }
    return true;
}

ROVERLINK_NOINLINE void SessionCore::answer(uint8_t reason, uint8_t detail) {
    v_.dup_reason = reason;
    v_.dup_detail = detail;
    send_answer(reason, detail);
}

ROVERLINK_NOINLINE void SessionCore::send_answer(uint8_t reason, uint8_t detail) {
    // An ACK is a NACK's first two fields: one NACK is packed, and sent whole or as the ACK.
    static_assert(proto::Ack::PAYLOAD_SIZE == 2 && offsetof(proto::Ack, req_seq) == offsetof(proto::Nack, req_seq) &&
                      offsetof(proto::Ack, req_id) == 0 && offsetof(proto::Nack, req_id) == 0 &&
                      sizeof(proto::Ack::req_seq) == 1 && sizeof(proto::Nack::req_seq) == 1,
                  "ACK must be the start of NACK");
    const proto::Nack nack = {v_.req_id, v_.req_seq, static_cast<NackReason>(reason), detail};
    const uint8_t len = proto::pack(nack, link_.payload_slot());
    if (reason == 0) {
        link_.send_payload(proto::Ack::ID, proto::Ack::CRC_EXTRA, proto::Ack::PAYLOAD_SIZE);
    } else {
        link_.send_payload(proto::Nack::ID, proto::Nack::CRC_EXTRA, len);
    }
}

ROVERLINK_NOINLINE void SessionCore::send_reply(uint8_t msg_id, uint8_t crc_extra, uint8_t len) {
    link_.reply().req_seq = v_.req_seq;
    link_.send_payload(msg_id, crc_extra, static_cast<uint8_t>(1 + len));
}

// Out of line and not cloned: cloned for the global session, every field store would take an
// absolute address (four bytes) instead of an offset (two).
ROVERLINK_OUT_OF_LINE void SessionCore::send_identity(proto::IdentityReason reason, const proto::SetConfig& config) {
    // Built in the frame buffer, every payload byte written below: a field added to the spec must
    // be added here too.
    static_assert(proto::Identity::PAYLOAD_SIZE == 25 && offsetof(proto::Identity, robot_name) == 25,
                  "send_identity() writes IDENTITY's fields one by one");
    const Vars& v = v_;
    proto::Identity& m = link_.out().identity;
    const uint32_t ms = ms_of(clock());  // before wrapped_ms is read: clock() may add a wrap to it
    m.uptime_ms = v.wrapped_ms + ms;
    m.protocol_version = proto::PROTOCOL_VERSION;
    m.spec_hash = proto::SPEC_HASH;
    m.firmware_version[0] = FIRMWARE_VERSION.major;
    m.firmware_version[1] = FIRMWARE_VERSION.minor;
    m.firmware_version[2] = FIRMWARE_VERSION.patch;
    m.board = robot_.board;
    m.capabilities = robot_.capabilities;
    m.boot_id = v.boot_id;
    m.reason = reason;
    m.hello_seq = v.req_seq;  // the HELLO's; 0 at the boot announcement (reset() zeroed it, no frame yet)
    // Granted values; outside a session, those in force in IDLE (stream at the config's rate).
    if (reason == proto::IdentityReason::HELLO_ACCEPTED) {
        m.watchdog_ms = v.watchdog_ms;
        m.feedback_mode = v.mode;
        m.feedback_hz = v.feedback_hz;
    } else {
        m.watchdog_ms = config.watchdog_ms;
        m.feedback_mode = proto::FeedbackMode::STREAM;
        m.feedback_hz = config.feedback_hz;
    }
    uint8_t n = 0;
    const char* name = robot_.name;  // never null (robot.h)
    while (n < sizeof m.robot_name && name[n] != '\0') {
        m.robot_name[n] = name[n];
        ++n;
    }
    link_.send_payload(proto::Identity::ID, proto::Identity::CRC_EXTRA,
                       static_cast<uint8_t>(proto::Identity::PAYLOAD_SIZE + n));
}

void SessionCore::accept_hello(const proto::Hello& h, const proto::SetConfig& config) {
    Vars& v = v_;
    uint16_t wd = h.watchdog_ms != 0 ? h.watchdog_ms : config.watchdog_ms;
    if (wd == 0) {
        wd = proto::WATCHDOG_DEFAULT_MS;
    }
    v.watchdog_ms = wd < proto::WATCHDOG_MIN_MS ? proto::WATCHDOG_MIN_MS
                                                 : (wd > proto::WATCHDOG_MAX_MS ? proto::WATCHDOG_MAX_MS : wd);
    // Lockstep only where the build can do it; IDENTITY reports what was granted.
    v.mode = has(proto::Capability::LOCKSTEP) ? h.feedback_mode : proto::FeedbackMode::STREAM;
    uint8_t hz = h.feedback_hz != 0 ? h.feedback_hz : config.feedback_hz;
    if (hz == 0) {
        hz = proto::FEEDBACK_HZ_DEFAULT;
    }
    v.feedback_hz = hz > proto::FEEDBACK_HZ_MAX ? proto::FEEDBACK_HZ_MAX : hz;
    v.dup_valid = false;
    link_.restart_seq();
    v.fb_countdown = 0;
    send_identity(proto::IdentityReason::HELLO_ACCEPTED, config);
}

void SessionCore::send_pong(const proto::Ping& m) {
    static_assert(proto::Pong::PAYLOAD_SIZE == 8, "send_pong() writes PONG's fields one by one");
    proto::Pong& pong = link_.out().pong;
    pong.host_time_us = m.host_time_us;
    pong.mcu_time_us = clock();
    link_.send_payload(proto::Pong::ID, proto::Pong::CRC_EXTRA, proto::Pong::PAYLOAD_SIZE);
}

ROVERLINK_OUT_OF_LINE void SessionCore::send_link_stats() {
    // The payload after req_seq is the decoder's counters, then the link's: two copies. The generated
    // code checks that each field set sits in LINK_STATS in its struct's order; here, that they follow
    // req_seq back to back.
    typedef proto::LinkStats S;
    static_assert(offsetof(S, frames_ok) == 1 && offsetof(S, seq_gaps) == 1 + sizeof(DecoderStats) &&
                      S::PAYLOAD_SIZE == 1 + sizeof(DecoderStats) + sizeof(Link::Counts),
                  "LINK_STATS must be req_seq, DecoderStats, Link::Counts");
    S& s = link_.out().link_stats;
    memcpy(&s.frames_ok, &link_.decoder().stats(), sizeof(DecoderStats));
    memcpy(&s.seq_gaps, &link_.counts(), sizeof(Link::Counts));
    send_reply(S::ID, S::CRC_EXTRA, S::PAYLOAD_SIZE - 1);  // + req_seq
}

uint8_t SessionCore::session_status() const {
    uint8_t s = 0;
    switch (v_.state) {
    case SessionState::ARMED:
        s = proto::Status::SESSION | proto::Status::ARMED;
        break;
    case SessionState::FAILSAFE:
        s = proto::Status::SESSION | proto::Status::FAILSAFE;
        break;
    case SessionState::DISARMED:
        s = proto::Status::SESSION;
        break;
    default:
        return 0;
    }
    if (v_.mode == proto::FeedbackMode::LOCKSTEP) {
        s |= proto::Status::LOCKSTEP;
    }
    return s;
}

bool SessionCore::feedback_due(bool applied, uint8_t config_hz) {
    // Lockstep answers setpoints only while ARMED; out of ARMED it streams like stream mode. The
    // countdown is held at 0 meanwhile, so the first tick out of ARMED streams one at once.
    if (armed() && v_.mode == proto::FeedbackMode::LOCKSTEP) {
        v_.fb_countdown = 0;
        return applied;
    }
    if (v_.fb_countdown != 0) {
        --v_.fb_countdown;
        return false;
    }
    // round(CONTROL_RATE_HZ / hz), half up, in 8 bits: floor((floor(2 * 100 / hz) + 1) / 2).
    static_assert(2 * proto::CONTROL_RATE_HZ <= 255, "the stream period is computed in 8 bits");
    // The quotient by subtraction (at most 200 steps, once per FEEDBACK): no division routine.
    const uint8_t hz = in_session() ? v_.feedback_hz : config_hz;
    uint8_t q = 1;  // floor(2 * 100 / hz) + 1; hz = 0 (never granted) counts as 200 Hz
    for (uint8_t r = static_cast<uint8_t>(2 * proto::CONTROL_RATE_HZ); hz != 0 && r >= hz; r -= hz) {
        ++q;
    }
    v_.fb_countdown = static_cast<uint8_t>((hz != 0 ? q : 2u) / 2u - 1u);
    return true;
}

void SessionCore::send_feedback(proto::Feedback& f, uint8_t app_status) {
    f.boot_id = v_.boot_id;
    f.status = static_cast<uint8_t>(session_status() | app_status);
    f.failsafe_reason = v_.reason;
    link_.send(f);
}

ROVERLINK_NOINLINE void SessionCore::log(proto::LogLevel level, const char* flash_text, const char* tail,
                                         uint8_t tail_len) {
    uint8_t* p = link_.payload_slot();
    const uint8_t cap = proto::Log::PAYLOAD_MAX;
    uint8_t n = 0;
    p[n++] = static_cast<uint8_t>(level);
    for (const char* s = flash_text; n < cap; ++s) {
        const uint8_t c = static_cast<uint8_t>(ROVERLINK_READ_BYTE(s));
        if (c == 0) {
            break;
        }
        p[n++] = c;
    }
    for (; tail_len > 0 && n < cap; --tail_len) {
        p[n++] = static_cast<uint8_t>(*tail++);
    }
    link_.send_payload(proto::Log::ID, proto::Log::CRC_EXTRA, n);
}

}  // namespace roverlink
