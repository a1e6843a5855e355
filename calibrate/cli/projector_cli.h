#pragma once
// studio-calibrate projector (projector_cli.cc): args[0] is "projector". Returns the exit code.
#include <string>
#include <vector>

namespace studio::calibrate {
int run_projector(const std::vector<std::string>& args);
}  // namespace studio::calibrate
