#pragma once
// studioctl doctor: checks this host against what the studio's DDS profile asks of it and says
// what to fix (see kDoctorHelp in doctor.cc).

#include <string>
#include <vector>

namespace studio::ctl {

int doctor_command(const std::vector<std::string>& argv);
extern const char kDoctorHelp[];

}  // namespace studio::ctl
