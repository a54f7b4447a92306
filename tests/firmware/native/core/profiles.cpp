#include "profiles.h"

#include <string.h>

namespace sim_profiles {

namespace {
const Profile PROFILES[] = {
    {"diffdrive-tb6612", "DiffDriveTB6612", &DIFFDRIVE_TB6612},
    {"diffdrive-bts7960", "DiffDriveBTS7960", &DIFFDRIVE_BTS7960},
    {"picar", "AckermannPiCar", &PICAR},
};
const int COUNT = static_cast<int>(sizeof PROFILES / sizeof PROFILES[0]);
}  // namespace

int count() { return COUNT; }

const Profile* at(int index) { return index >= 0 && index < COUNT ? &PROFILES[index] : 0; }

const Profile* find(const char* name) {
    if (name == 0) {
        return 0;
    }
    if (name[0] >= '0' && name[0] <= '9' && name[1] == '\0') {
        return at(name[0] - '0');  // a robot index, "0".."9"
    }
    for (int i = 0; i < COUNT; ++i) {
        if (strcmp(name, PROFILES[i].name) == 0 || strcmp(name, PROFILES[i].example) == 0) {
            return &PROFILES[i];
        }
    }
    return 0;
}

}  // namespace sim_profiles
