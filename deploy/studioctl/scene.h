#pragma once
// studioctl scene load|play|pause|seek|speed|hash: commands to the scene server
// (studio/scene/command) confirmed by its verdict on studio/scene/state, and the server's state
// hash checked against the nodes this host receives (scene::hash_nodes).

#include <string>
#include <vector>

namespace studio::ctl {

int scene_command(const std::vector<std::string>& argv);

}  // namespace studio::ctl
