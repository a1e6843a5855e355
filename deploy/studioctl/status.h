#pragma once
// studioctl status: the live services of the domain (studio/service/status).

#include <string>
#include <vector>

namespace studio::ctl {

int status_command(const std::vector<std::string>& argv);
extern const char kStatusHelp[];

}  // namespace studio::ctl
