#pragma once
// keyer.yaml -> KeyerOptions (the keyer CLI's, the keyer node's, the capture node's and the hull
// CLI's reader; the pure library has no YAML). The keys are those of keyer/keyer.example.yaml,
// read through core/yaml's schema: unknown keys, wrong types and values that fail
// KeyerOptions::validate() are one line naming the file, the line and the key
// ("keyer.yaml:3: keyer.clip_whit: unknown key 'clip_whit'").

#include <string>

#include "core/error.h"
#include "keyer/keyer_options.h"
#include "yaml_io/node.h"

namespace studio::keyer {

// The keyer keys of one mapping (e.g. the `keyer:` section of a service config); null = the
// defaults.
Expected<KeyerOptions> read_keyer_options(const yaml::Node& section);

// A keyer.yaml: the options under its `keyer:` key (other top-level keys belong to whoever else
// reads that file, e.g. a keyer node config), else the whole file as keyer keys.
Expected<KeyerOptions> load_keyer_options(const std::string& path);

}  // namespace studio::keyer
