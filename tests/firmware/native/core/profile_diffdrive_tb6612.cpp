// The DiffDriveTB6612 example's robot, from its generated robot_profile.h.
#include "profiles.h"

// Every profile header defines the same inline functions (robot_profile::default_config...) with
// external linkage; one header per binary is fine in a sketch, but three in one program would be
// merged by the linker. An unnamed namespace gives each translation unit its own copy (the
// header's own #include <RoverLink.h> is already satisfied by profiles.h).
namespace {
#include "DiffDriveTB6612/robot_profile.h"
}  // namespace

namespace sim_profiles {

const roverlink::Robot DIFFDRIVE_TB6612 = {
    robot_profile::NAME,         robot_profile::BOARD,          robot_profile::CAPABILITIES,
    robot_profile::FEEDBACK_MODE, robot_profile::default_config, robot_profile::default_pid,
    robot_profile::LIGHTS_MODE};

}  // namespace sim_profiles
