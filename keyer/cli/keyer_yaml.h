#pragma once
// keyer.yaml -> KeyerOptions (the CLI's and the node's reader; the pure library has no YAML).
// The keys are those of keyer/keyer.example.yaml, either at the top level or under `keyer:`.
// Unknown keys, wrong types and values that fail KeyerOptions::validate() are errors of one line
// naming the file, the line and the key.

#include <string>

#include "core/error.h"
#include "keyer/keyer_options.h"

namespace studio::keyer {

Expected<KeyerOptions> load_keyer_options(const std::string& path);
Expected<KeyerOptions> parse_keyer_options(const std::string& text, const std::string& name);

}  // namespace studio::keyer
