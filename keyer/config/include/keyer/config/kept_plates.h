#pragma once
// Clean plates captured on command, kept on disk so that a restarted keying process (a crash, a
// systemd restart) keys at once: with the actor on set a clean plate cannot be shot again. Used
// by the keyer node and by the capture node's in-process key (their `plate_dir`).

#include <string>
#include <string_view>

#include "core/error.h"
#include "keyer/keyer.h"

namespace studio::keyer {

class KeptPlates {
 public:
  // An empty `dir` keeps nothing (every call is a no-op).
  explicit KeptPlates(std::string dir) : dir_(std::move(dir)) {}
  bool enabled() const { return !dir_.empty(); }
  // Creates the folder. One line on failure.
  Expected<void> prepare() const;
  // DIR/<camera>.png.
  std::string path(const std::string& camera) const;
  // The kept plate of `camera` into `keyer`: true when one was loaded, false when none is kept,
  // an error when the file cannot be read (the camera then waits for a new plate).
  Expected<bool> load(const std::string& camera, Keyer& keyer) const;
  // Keeps `keyer`'s plate (atomically: written beside and renamed over).
  Expected<void> save(const std::string& camera, const Keyer& keyer) const;
  // Forgets the kept plate (KeyerPlate 0).
  void remove(const std::string& camera) const;

  // load() at a camera's start, said in the log under `log`: the plate used, or why a kept one
  // was not (the camera then waits for a new plate).
  void restore(const std::string& camera, Keyer& keyer, std::string_view log) const;
  // save() of a plate just captured; false (and a warning under `log`) when it could not be kept.
  bool keep(const std::string& camera, const Keyer& keyer, std::string_view log) const;

 private:
  std::string dir_;
};

}  // namespace studio::keyer
