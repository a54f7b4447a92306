// libroverlink_sim: the RoverLink firmware core, built natively, behind a small C ABI.
//
// Build:  make -C tests/firmware/native sim        ->  build/native/sim/libroverlink_sim.so
// Python: tests/support/native_sim.py (ctypes, builds the library when needed).
//
// What it is. The same src/core/ that runs on the Arduino, on src/hal/native/'s NativeBoard and
// MemoryStream, on a simulated clock. The host side (a test, the emulator comparison suite, a
// firmware-in-the-loop harness) writes the bytes the host would send, advances time, moves the
// encoders (its own plant model), and reads back the bytes the firmware sent plus every output
// pin-level value. Nothing here runs in real time: everything happens inside rl_sim_advance_us().
//
// Time. The simulation clock starts at 0 at rl_sim_create(). The board's micros() is the time since
// the last boot (plus rl_sim_set_boot_micros()). rl_sim_advance_us(h, us) first polls at the
// current time (so bytes fed since the last call are handled "now"), then advances in steps of the
// poll interval (default 1000 us), polling after each step. A poll calls Firmware::poll(), which
// handles at most one frame, until the bytes received so far are all read (on a board the loop's
// next pass follows within microseconds). Control ticks follow
// micros() (every 10 000 us from boot), so with the default interval they happen exactly on time.
//
// Profiles. The three reference robots, from the examples' generated robot_profile.h:
//   index  name                 example
//   0      diffdrive-tb6612     DiffDriveTB6612
//   1      diffdrive-bts7960    DiffDriveBTS7960
//   2      picar                AckermannPiCar
// rl_sim_create() accepts either name, or the index as a string ("0", "1", "2").
//
// Functions (all take the handle from rl_sim_create unless noted; none of them can fail on a valid
// handle except where a return value says so; a NULL handle is ignored / returns 0):
//
//   uint32_t rl_sim_api_version(void)              RL_SIM_API_VERSION below
//   uint32_t rl_sim_outputs_size(void)             sizeof(rl_sim_outputs), to check a binding
//   int      rl_sim_profile_count(void)
//   const char* rl_sim_profile_name(int i)         NULL when out of range
//   const char* rl_sim_profile_example(int i)      NULL when out of range
//   rl_sim*  rl_sim_create(const char* profile, uint32_t seed)
//            New robot, booted (its IDENTITY is already waiting to be read). `seed` drives the
//            board's entropy() and so the boot_id. NULL for an unknown profile.
//   void     rl_sim_destroy(rl_sim*)
//   void     rl_sim_reset(rl_sim*)                 power cycle: reboot, EEPROM kept, bytes in
//                                                  flight and encoder counters lost
//   void     rl_sim_set_poll_interval_us(rl_sim*, uint32_t us)   0 is taken as 1
//   void     rl_sim_set_boot_micros(rl_sim*, uint32_t us)        micros() at the next boot
//   void     rl_sim_feed_host_bytes(rl_sim*, const uint8_t* buf, size_t len)
//   size_t   rl_sim_read_mcu_bytes(rl_sim*, uint8_t* buf, size_t cap)   bytes copied (drained)
//   size_t   rl_sim_mcu_bytes_available(rl_sim*)
//   void     rl_sim_advance_us(rl_sim*, uint64_t us)
//   uint64_t rl_sim_time_us(rl_sim*)
//   void     rl_sim_set_encoder(rl_sim*, uint8_t wheel, int32_t count)    raw hardware counter
//   void     rl_sim_add_encoder(rl_sim*, uint8_t wheel, int32_t delta)    wraps at 32 bits
//   void     rl_sim_get_outputs(rl_sim*, rl_sim_outputs* out)
//   uint32_t rl_sim_eeprom_size(void)              1024
//   int      rl_sim_eeprom_read(rl_sim*, uint32_t addr, uint8_t* buf, uint32_t len)   1 ok, 0 range
//   int      rl_sim_eeprom_write(rl_sim*, uint32_t addr, const uint8_t* buf, uint32_t len)
//            pokes bytes directly (corruption tests); 1 ok, 0 out of range
//   void     rl_sim_eeprom_erase(rl_sim*)          every byte 0xFF
//   void     rl_sim_eeprom_fail_writes(rl_sim*, int fail)   the firmware's writes fail while set
//
// rl_sim_outputs: see the struct below; enums are their wire values (SessionState, FailsafeReason,
// Status bits, FeedbackMode) and MotorMode is 0 DRIVE, 1 COAST, 2 BRAKE.
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "profiles.h"
#include "sim.h"

#define RL_SIM_API_VERSION 1u

extern "C" {

typedef struct rl_sim rl_sim;

typedef struct rl_sim_outputs {
    uint64_t time_us;          // simulation time
    uint32_t micros;           // the board's micros() (since the last boot)
    uint32_t boot_id;
    uint32_t ticks_skipped;    // control ticks the firmware skipped because poll() came late
    uint32_t duplicates;       // reliable requests answered again
    uint32_t frames_sent;
    uint32_t motor_calls[2];   // drive() calls per wheel since the last boot
    int32_t encoder[2];        // the board's raw counters
    int32_t counts[2];         // the firmware's cumulative counts (encoder_invert applied)
    float ramped_mm_s[2];      // ramped setpoints
    float integral[2];         // PID integrators, permille
    int16_t motor_effort[2];   // last drive() effort, permille (motor_invert applied)
    uint8_t motor_mode[2];     // last drive() MotorMode
    uint16_t esc_us;           // last ESC pulse width (0: none yet)
    uint16_t steering_us;      // last steering servo pulse width (0: none yet)
    uint16_t tick;             // control tick counter
    uint16_t steering_cdeg;    // commanded servo angle
    uint16_t watchdog_ms;      // granted by the last accepted HELLO
    int16_t target_mm_s[2];    // applied setpoints
    int16_t measured_mm_s[2];  // measured speeds
    int16_t effort_permille[2];  // PID outputs (before motor_invert)
    uint8_t lights;            // Lights bits
    uint8_t state;             // SessionState
    uint8_t failsafe_reason;   // FailsafeReason
    uint8_t status;            // Status bits as FEEDBACK would carry them now
    uint8_t feedback_mode;     // in effect
    uint8_t feedback_hz;       // in effect
    uint8_t ack_seq;
    uint8_t reserved;
} rl_sim_outputs;

uint32_t rl_sim_api_version(void) { return RL_SIM_API_VERSION; }
uint32_t rl_sim_outputs_size(void) { return static_cast<uint32_t>(sizeof(rl_sim_outputs)); }
int rl_sim_profile_count(void) { return sim_profiles::count(); }

const char* rl_sim_profile_name(int i) {
    const sim_profiles::Profile* p = sim_profiles::at(i);
    return p != 0 ? p->name : 0;
}

const char* rl_sim_profile_example(int i) {
    const sim_profiles::Profile* p = sim_profiles::at(i);
    return p != 0 ? p->example : 0;
}

rl_sim* rl_sim_create(const char* profile, uint32_t seed) {
    const sim_profiles::Profile* p = sim_profiles::find(profile);
    if (p == 0) {
        return 0;
    }
    return reinterpret_cast<rl_sim*>(new Sim(*p->robot, seed));
}

static Sim* sim_of(rl_sim* h) { return reinterpret_cast<Sim*>(h); }

void rl_sim_destroy(rl_sim* h) { delete sim_of(h); }

void rl_sim_reset(rl_sim* h) {
    if (h != 0) {
        sim_of(h)->power_cycle();
    }
}

void rl_sim_set_poll_interval_us(rl_sim* h, uint32_t us) {
    if (h != 0) {
        sim_of(h)->poll_interval_us = us != 0 ? us : 1;
    }
}

void rl_sim_set_boot_micros(rl_sim* h, uint32_t us) {
    if (h != 0) {
        sim_of(h)->boot_micros = us;
    }
}

void rl_sim_feed_host_bytes(rl_sim* h, const uint8_t* buf, size_t len) {
    if (h != 0 && buf != 0) {
        sim_of(h)->feed(buf, len);
    }
}

size_t rl_sim_read_mcu_bytes(rl_sim* h, uint8_t* buf, size_t cap) {
    return h != 0 && buf != 0 ? sim_of(h)->read(buf, cap) : 0;
}

size_t rl_sim_mcu_bytes_available(rl_sim* h) { return h != 0 ? sim_of(h)->port.host_available() : 0; }

void rl_sim_advance_us(rl_sim* h, uint64_t us) {
    if (h != 0) {
        sim_of(h)->advance_us(us);
    }
}

uint64_t rl_sim_time_us(rl_sim* h) { return h != 0 ? sim_of(h)->time_us() : 0; }

void rl_sim_set_encoder(rl_sim* h, uint8_t wheel, int32_t count) {
    if (h != 0) {
        sim_of(h)->board.set_encoder(wheel, count);
    }
}

void rl_sim_add_encoder(rl_sim* h, uint8_t wheel, int32_t delta) {
    if (h != 0) {
        sim_of(h)->board.add_encoder(wheel, delta);
    }
}

void rl_sim_get_outputs(rl_sim* h, rl_sim_outputs* out) {
    if (h == 0 || out == 0) {
        return;
    }
    memset(out, 0, sizeof *out);
    Sim& s = *sim_of(h);
    const roverlink::Firmware& fw = *s.fw;
    out->time_us = s.time_us();
    out->micros = s.board.micros();
    out->boot_id = fw.boot_id();
    out->ticks_skipped = fw.ticks_skipped();
    out->duplicates = fw.duplicates();
    out->frames_sent = fw.link().counts().frames_sent;
    for (uint8_t w = 0; w < 2; ++w) {
        out->motor_calls[w] = s.board.motor(w).calls;
        out->encoder[w] = s.board.encoder(w);
        out->counts[w] = fw.counts(w);
        out->ramped_mm_s[w] = fw.ramped(w);
        out->integral[w] = fw.integral(w);
        out->motor_effort[w] = s.board.motor(w).effort;
        out->motor_mode[w] = static_cast<uint8_t>(s.board.motor(w).mode);
        out->target_mm_s[w] = fw.target(w);
        out->measured_mm_s[w] = fw.measured(w);
        out->effort_permille[w] = fw.effort(w);
    }
    out->esc_us = s.board.esc_us();
    out->steering_us = s.board.steering_us();
    out->tick = fw.tick();
    out->steering_cdeg = fw.steering_cdeg();
    out->watchdog_ms = fw.watchdog_ms();
    out->lights = s.board.lights_mask();
    out->state = static_cast<uint8_t>(fw.state());
    out->failsafe_reason = static_cast<uint8_t>(fw.failsafe_reason());
    out->status = fw.status();
    out->feedback_mode = static_cast<uint8_t>(fw.feedback_mode());
    out->feedback_hz = fw.feedback_hz();
    out->ack_seq = fw.ack_seq();
}

uint32_t rl_sim_eeprom_size(void) { return roverlink::NativeBoard::EEPROM_SIZE; }

int rl_sim_eeprom_read(rl_sim* h, uint32_t addr, uint8_t* buf, uint32_t len) {
    if (h == 0 || buf == 0 || addr > roverlink::NativeBoard::EEPROM_SIZE ||
        len > roverlink::NativeBoard::EEPROM_SIZE - addr) {
        return 0;
    }
    memcpy(buf, sim_of(h)->board.eeprom() + addr, len);
    return 1;
}

int rl_sim_eeprom_write(rl_sim* h, uint32_t addr, const uint8_t* buf, uint32_t len) {
    if (h == 0 || buf == 0 || addr > roverlink::NativeBoard::EEPROM_SIZE ||
        len > roverlink::NativeBoard::EEPROM_SIZE - addr) {
        return 0;
    }
    for (uint32_t i = 0; i < len; ++i) {
        const uint16_t a = static_cast<uint16_t>(addr + i);
        sim_of(h)->board.corrupt_eeprom(a, static_cast<uint8_t>(sim_of(h)->board.eeprom()[a] ^ buf[i]));
    }
    return 1;
}

void rl_sim_eeprom_erase(rl_sim* h) {
    if (h != 0) {
        sim_of(h)->board.erase_eeprom();
    }
}

void rl_sim_eeprom_fail_writes(rl_sim* h, int fail) {
    if (h != 0) {
        sim_of(h)->board.set_eeprom_write_fails(fail != 0);
    }
}

}  // extern "C"
