// The RoverLink firmware core: the session (link, protocol, session rules) composed with the
// control loop and the configuration, over a Board.
//
//   roverlink::Firmware firmware(Serial, board, ROBOT);
//   void setup() { Serial.begin(115200); firmware.begin(); }
//   void loop() { firmware.poll(); }
//
// Behaviour is docs/control.md; the design, the choices that page leaves open, and tuning are in
// docs/firmware.md. The session (session.h) owns frames, the state table, requests and replies;
// Firmware is its App: the control tick, the outputs, the configuration and the EEPROM image.
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
#include "session.h"

namespace roverlink {

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
    proto::SessionState state() const { return session_.state(); }
    uint32_t boot_id() const { return session_.boot_id(); }
    proto::FailsafeReason failsafe_reason() const { return session_.failsafe_reason(); }
    uint8_t status() const { return session_.status(); }  // FEEDBACK.status bits, as of now
    uint16_t tick() const { return v_.tick; }              // control ticks run since boot (first is 1)
    uint32_t ticks_skipped() const { return v_.ticks_skipped; }
    uint32_t next_tick_us() const { return v_.next_tick_us; }  // micros() of the next control tick
    const proto::SetConfig& config() const { return v_.cfg; }
    const control::Gains& gains(uint8_t w) const { return v_.gains[w < proto::WHEEL_COUNT ? w : 0]; }
    uint16_t watchdog_ms() const { return session_.watchdog_ms(); }  // granted by the last accepted HELLO
    proto::FeedbackMode feedback_mode() const { return session_.feedback_mode(); }  // in effect
    uint8_t feedback_hz() const { return session_.feedback_hz(); }  // in effect (the config's in IDLE)
    int32_t counts(uint8_t w) const { return wheel(w).count; }
    int16_t target(uint8_t w) const { return wheel(w).target; }
    float ramped(uint8_t w) const { return static_cast<float>(wheel(w).ramp) / control::RAMP_UNITS_PER_MM_S; }
    float integral(uint8_t w) const { return wheel(w).integral; }
    int16_t measured(uint8_t w) const { return wheel(w).measured; }
    int16_t effort(uint8_t w) const { return wheel(w).effort; }
    uint16_t steering_cdeg() const { return v_.servo_cdeg; }
    uint8_t ack_seq() const { return v_.ack_seq; }
    uint16_t ack_tick() const { return v_.ack_tick; }
    uint32_t duplicates() const { return session_.duplicates(); }
    const Link& link() const { return session_.link(); }

private:
    friend class Session<Firmware>;  // the App interface below is for the session only

    // A setpoint waiting for the tick that applies it.
    struct Queued {
        int16_t wheel[proto::WHEEL_COUNT];  // mm/s
        int16_t steer_mrad;
        uint8_t seq;
    };

    struct Wheel {
        int32_t ramp;      // the ramped setpoint the PID follows, in 0.01 mm/s
        float integral;    // permille
        int32_t count;     // cumulative encoder count at the last tick (encoder_invert applied)
        int16_t target;    // mm/s, from the last applied setpoint
        int16_t measured;  // mm/s
        int16_t effort;    // permille, applied this tick (before motor_invert)
        uint8_t stalled;   // consecutive ticks of |effort| >= 300 without a count
    };

    // The control loop's and the configuration's state: begin() resets it in one go. Small, often
    // used members first, so that on AVR they stay within reach of the 6-bit displacement.
    struct Vars {
        bool config_defaults;
        bool encoder_fault;
        bool saturated;
        bool esc_ready;            // the ESC arming window is over
        uint8_t queued;            // setpoints waiting (stream mode: at most 1, lockstep LOCKSTEP_QUEUE)
        uint8_t ack_seq;
        uint8_t blink;
        uint8_t lights;
        uint8_t late_holdoff;      // ticks before another "late" LOG may be sent
        uint16_t caps;             // robot capabilities (a copy: one load instead of two per test)
        uint16_t tick;
        uint16_t ack_tick;
        uint16_t servo_cdeg;
        int16_t steer_mrad;
        Queued queue[proto::LOCKSTEP_QUEUE];  // the oldest first
        uint32_t next_tick_us;
        uint32_t boot_us;
        uint32_t ticks_skipped;
        float mm_s_per_count;      // derived from the config (apply_config)
        Wheel wheels[proto::WHEEL_COUNT];
        control::Gains gains[proto::WHEEL_COUNT];
        proto::SetConfig cfg;
        proto::SetLights lights_set;  // the mode and masks in force (SET_LIGHTS, else the power-up mode)
    };

    // -- the App interface of Session<Firmware> (session.h; config() is the public one) -------
    void session_actions(uint16_t actions);
    uint8_t set_config(const proto::SetConfig& c, uint8_t& detail);
    void set_pid(const proto::SetPid& m);
    void pid(uint8_t wheel, proto::SetPid& out) const;
    uint8_t save_config();
    void reset_odometry();
    void request(const proto::HostToMcu& m, uint8_t id);
    void setpoint(int16_t left, int16_t right, int16_t steer_mrad, uint8_t seq);
    uint8_t status_bits() const;

    const Wheel& wheel(uint8_t w) const { return v_.wheels[w < proto::WHEEL_COUNT ? w : 0]; }
    bool has(uint16_t capability) const { return (v_.caps & capability) != 0; }
    uint8_t driven_wheels() const;

    void motors_safe();
    uint8_t lights_mask() const;
    void apply_config(const proto::SetConfig& c);
    void control_tick(uint16_t periods, uint32_t now);
    enum : uint8_t { WHEEL_RAMPING = 1, WHEEL_SATURATED = 2, WHEEL_STALLED = 4 };  // tick_wheel()
    uint8_t tick_wheel(uint8_t w, int32_t raw, uint16_t periods, bool hold);
    void write_outputs(bool drive);
    void send_feedback(uint32_t sample_us);

    Vars v_;
    Board& board_;
    const Robot& robot_;
    Session<Firmware> session_;  // last: the link's buffers would push v_ out of short addressing
};

}  // namespace roverlink

#endif  // ROVERLINK_CORE_FIRMWARE_H
