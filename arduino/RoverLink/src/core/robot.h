// What a firmware example tells the core about its robot (filled from robot_profile.h).
#ifndef ROVERLINK_CORE_ROBOT_H
#define ROVERLINK_CORE_ROBOT_H

#include <stdint.h>

#include "../generated/roverlink_protocol.h"

namespace roverlink {

struct FirmwareVersion {
    uint8_t major;
    uint8_t minor;
    uint8_t patch;
};

struct Robot {
    const char* name;                                // IDENTITY.robot_name (ASCII, <= 24 chars; never null)
    proto::Board board;
    uint16_t capabilities;                           // proto::Capability bits
    proto::FeedbackMode default_feedback_mode;       // used before the first HELLO
    proto::SetConfig (*default_config)();            // EEPROM fallback (robot_profile.h)
    proto::SetPid (*default_pid)();
    proto::LightsMode lights_mode;                   // turn signals at power-up and at each HELLO (AUTO or OFF)
};

}  // namespace roverlink

#endif  // ROVERLINK_CORE_ROBOT_H
