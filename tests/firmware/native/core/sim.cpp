#include "sim.h"

Sim::Sim(const roverlink::Robot& robot_, uint32_t seed, uint32_t poll_interval)
    : poll_interval_us(poll_interval != 0 ? poll_interval : 1),
      boot_micros(0),
      robot(robot_),
      board(seed),
      fw(0),
      now_(0),
      boot_at_(0),
      booted_micros_(0) {
    boot();
}

Sim::~Sim() { delete fw; }

void Sim::boot() {
    delete fw;
    board.power_cycle();
    port.clear();
    boot_at_ = now_;
    booted_micros_ = boot_micros;
    sync_clock();
    fw = new roverlink::Firmware(port, board, robot);
    fw->begin();
}

void Sim::power_cycle() { boot(); }

void Sim::advance_us(uint64_t us) {
    sync_clock();
    poll_now();
    const uint64_t step = poll_interval_us != 0 ? poll_interval_us : 1;
    while (us > 0) {
        const uint64_t d = us < step ? us : step;
        now_ += d;
        us -= d;
        sync_clock();
        poll_now();
    }
}

// Firmware::poll() handles at most one frame; on a board the next loop pass follows within
// microseconds, so the frames already received are all handled at this instant.
void Sim::poll_now() {
    for (;;) {
        const int before = port.available();
        fw->poll();
        const int after = port.available();
        if (after == 0 || after >= before) {
            return;
        }
    }
}
