// The RoverLink firmware core: link, session, control loop and configuration over a Board.
//
//   roverlink::Firmware firmware(Serial, board, ROBOT);
//   void setup() { Serial.begin(115200); firmware.begin(); }
//   void loop() { firmware.poll(); }
//
// Behaviour is docs/control.md; the design, the choices that page leaves open, and tuning are in
// docs/firmware.md. The session is driven only by the generated state table (proto::step): every
// state change and its actions come from a row of it.
//
// No heap, no String, no delay(), no printf: one TX frame buffer, the frame decoder, and a few
// bytes per wheel. poll() never blocks except inside Stream::write() when the UART's transmit
// buffer is full, and for SAVE_CONFIG's EEPROM writes (refused while ARMED).
#ifndef ROVERLINK_CORE_FIRMWARE_H
#define ROVERLINK_CORE_FIRMWARE_H

#include <stddef.h>
#include <stdint.h>

#include "../codec/codec.h"
#include "../generated/roverlink_protocol.h"
#include "../hal/board.h"
#include "../hal/stream.h"
#include "config.h"
#include "control.h"
#include "link.h"
#include "robot.h"
#include "version.h"

namespace roverlink {

static const FirmwareVersion FIRMWARE_VERSION = {ROVERLINK_FIRMWARE_VERSION_MAJOR, ROVERLINK_FIRMWARE_VERSION_MINOR,
                                                 ROVERLINK_FIRMWARE_VERSION_PATCH};

class Firmware {
public:
    // Stores references only: safe to construct as a global before the Arduino core is up.
    Firmware(Stream& port, Board& board, const Robot& robot);

    // Loads the configuration, draws the boot_id, puts the motors in the safe state and sends the
    // boot IDENTITY (and a LOG if the EEPROM config was unusable). Call once, from setup().
    void begin();

    // Handles every byte that has arrived, then runs the control tick if one is due. Call as
    // often as possible (every loop()); ticks follow micros(), not the call rate.
    void poll();

    // -- read-only view (tests, the native simulator, diagnostics) ------------------------------
    proto::SessionState state() const { return v_.state; }
    uint32_t boot_id() const { return v_.boot_id; }
    proto::FailsafeReason failsafe_reason() const { return v_.reason; }
    uint8_t status() const;                             // FEEDBACK.status bits, as of now
    uint16_t tick() const { return v_.tick; }           // control ticks run since boot (first is 1)
    uint32_t ticks_skipped() const { return v_.ticks_skipped; }
    const proto::SetConfig& config() const { return v_.cfg; }
    const control::Gains& gains(uint8_t w) const { return v_.gains[w < proto::WHEEL_COUNT ? w : 0]; }
    uint16_t watchdog_ms() const { return v_.watchdog_ms; }  // granted by the last accepted HELLO
    proto::FeedbackMode feedback_mode() const;               // in effect (STREAM in IDLE)
    uint8_t feedback_hz() const;                             // in effect (the config's in IDLE)
    int32_t counts(uint8_t w) const { return wheel(w).count; }
    int16_t target(uint8_t w) const { return wheel(w).target; }
    float ramped(uint8_t w) const { return static_cast<float>(wheel(w).ramp) / control::RAMP_UNITS_PER_MM_S; }
    float integral(uint8_t w) const { return wheel(w).integral; }
    int16_t measured(uint8_t w) const { return wheel(w).measured; }
    int16_t effort(uint8_t w) const { return wheel(w).effort; }
    uint16_t steering_cdeg() const { return v_.servo_cdeg; }
    uint8_t ack_seq() const { return v_.ack_seq; }
    uint16_t ack_tick() const { return v_.ack_tick; }
    uint32_t duplicates() const { return v_.duplicates; }
    const Link& link() const { return link_; }

private:
    struct Rx;  // adapts the generated dispatcher's handle(msg, seq) calls to on_message()

    struct Wheel {
        int32_t ramp;      // the ramped setpoint the PID follows, in 0.01 mm/s
        float integral;    // permille
        int32_t count;     // cumulative encoder count at the last tick (encoder_invert applied)
        int16_t target;    // mm/s, from the last applied setpoint
        int16_t measured;  // mm/s
        int16_t effort;    // permille, applied this tick (before motor_invert)
        uint8_t stalled;   // consecutive ticks of |effort| >= 300 without a count
    };

    // How a request is handled before its own code runs (request()).
    enum Kind : uint8_t {
        PLAIN,     // HELLO, PING, setpoints: seq accounting and VALID_FRAME only
        TABLE,     // ARM, DISARM: + duplicate detection; the state table answers
        RELIABLE,  // SET_*, SAVE_CONFIG, RESET_ODOMETRY: + duplicate replay, NO_SESSION in IDLE
        QUERY,     // GET_*: + duplicates answered afresh, NO_SESSION in IDLE
    };

    // Every piece of mutable state: begin() resets it in one go. Small, often used members first,
    // so that on AVR they stay within reach of the 6-bit load/store displacement.
    struct Vars {
        proto::SessionState state;
        proto::FailsafeReason reason;
        proto::FeedbackMode mode;  // granted by the last accepted HELLO
        uint8_t feedback_hz;       // granted by the last accepted HELLO
        uint8_t fb_countdown;      // ticks until the next stream FEEDBACK
        uint8_t req_id;            // the request being handled
        uint8_t req_seq;
        uint8_t dup_id;            // the last reliable request, for duplicate detection ...
        uint8_t dup_seq;
        uint8_t dup_reason;        // ... and its answer: 0 = ACK, else the NackReason
        uint8_t dup_detail;
        bool dup_valid;
        bool config_defaults;
        bool encoder_fault;
        bool saturated;
        bool esc_ready;            // the ESC arming window is over
        bool has_pending;
        uint8_t pending_seq;
        uint8_t ack_seq;
        uint8_t blink;
        uint8_t lights;
        uint8_t late_holdoff;      // ticks before another "late" LOG may be sent
        uint16_t caps;             // robot capabilities
        uint16_t watchdog_ms;      // granted by the last accepted HELLO
        uint16_t tick;
        uint16_t ack_tick;
        uint16_t servo_cdeg;
        uint16_t micros_wraps;     // for uptime_ms
        int16_t steer_mrad;
        int16_t pending_steer;
        int16_t pending[proto::WHEEL_COUNT];
        uint32_t last_valid_us;    // the watchdog's reference
        uint32_t next_tick_us;
        uint32_t boot_us;
        uint32_t last_micros;
        uint32_t boot_id;
        uint32_t duplicates;
        uint32_t ticks_skipped;
        float mm_s_per_count;      // derived from the config (apply_config)
        float max_effort;
        Wheel wheels[proto::WHEEL_COUNT];
        control::Gains gains[proto::WHEEL_COUNT];
        proto::SetConfig cfg;
    };

    const Wheel& wheel(uint8_t w) const { return v_.wheels[w < proto::WHEEL_COUNT ? w : 0]; }
    bool has(uint16_t capability) const { return (v_.caps & capability) != 0; }
    uint8_t driven_wheels() const;

    // session
    uint16_t fire(proto::SessionEvent ev, uint8_t guards, proto::FailsafeReason reason);
    bool request(uint8_t msg_id, uint8_t seq, Kind kind);
    void on_valid_frame(uint8_t seq);
    void answer(uint8_t reason, uint8_t detail);       // to the current request; remembered
    void send_answer(uint8_t reason, uint8_t detail);  // 0: ACK, else NACK(reason, detail)
    void send_identity(proto::IdentityReason reason);
    void accept_hello(const proto::Hello& h);
    void motors_safe();
    void setpoint(int16_t left, int16_t right, int16_t steer_mrad, uint8_t bad_field, uint16_t capability);
    void apply_config(const proto::SetConfig& c);
    void log(proto::LogLevel level, const char* flash_text, uint32_t number, bool with_number);

    // messages (valid frames, after the dispatcher unpacked them)
    void on_message(const proto::Hello& m, uint8_t seq);
    void on_message(const proto::Ping& m, uint8_t seq);
    void on_message(const proto::Arm& m, uint8_t seq);
    void on_message(const proto::Disarm& m, uint8_t seq);
    void on_message(const proto::SetPid& m, uint8_t seq);
    void on_message(const proto::GetPid& m, uint8_t seq);
    void on_message(const proto::SetConfig& m, uint8_t seq);
    void on_message(const proto::GetConfig& m, uint8_t seq);
    void on_message(const proto::SaveConfig& m, uint8_t seq);
    void on_message(const proto::ResetOdometry& m, uint8_t seq);
    void on_message(const proto::GetLinkStats& m, uint8_t seq);
    void on_message(const proto::SetWheelSpeeds& m, uint8_t seq);
    void on_message(const proto::SetAckermann& m, uint8_t seq);

    // control
    void receive();
    void control_tick(uint16_t periods, uint32_t now);
    void write_outputs(bool drive);
    void send_feedback(uint32_t sample_us);
    uint32_t clock();  // micros(), keeping count of its wraps for uptime_ms

    Vars v_;
    Stream& port_;
    Board& board_;
    const Robot& robot_;
    Link link_;  // last: its buffers would push the other members out of AVR's short addressing
};

}  // namespace roverlink

#endif  // ROVERLINK_CORE_FIRMWARE_H
