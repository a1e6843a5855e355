#pragma once
// studioctl topic list | info | hz | echo (see usage text in topics.cc).

#include <string>
#include <vector>

namespace studio::ctl {

int topic_command(const std::vector<std::string>& argv);
extern const char kTopicHelp[];

}  // namespace studio::ctl
