// The reference robots, built from each example's generated robot_profile.h (one translation unit
// per profile, because every profile header defines the same namespace robot_profile).
#ifndef ROVERLINK_TESTS_CORE_PROFILES_H
#define ROVERLINK_TESTS_CORE_PROFILES_H

#include <RoverLink.h>

namespace sim_profiles {

struct Profile {
    const char* name;     // emulator / SDK profile name, e.g. "diffdrive-tb6612"
    const char* example;  // firmware example (sketch folder), e.g. "DiffDriveTB6612"
    const roverlink::Robot* robot;
};

extern const roverlink::Robot DIFFDRIVE_TB6612;
extern const roverlink::Robot DIFFDRIVE_BTS7960;
extern const roverlink::Robot PICAR;

int count();
const Profile* at(int index);                // 0 <= index < count(), else null
const Profile* find(const char* name);       // by profile name, example name or index ("0"), else null

}  // namespace sim_profiles

#endif  // ROVERLINK_TESTS_CORE_PROFILES_H
