#pragma once
// Errors the caller must handle travel as studio::Expected<T> (std::expected, C++23). Exceptions
// are kept for programming errors, caught at main. An Error message is one line, meant for a
// person: it names the file, the field and the line where that is known.

#include <expected>
#include <string>
#include <utility>

namespace studio {

struct Error {
  std::string message;
};

template <class T>
using Expected = std::expected<T, Error>;

// return studio::fail("rig.yaml:12: cameras[0].K: expected 9 numbers, got 8");
inline std::unexpected<Error> fail(std::string message) {
  return std::unexpected<Error>(Error{std::move(message)});
}

}  // namespace studio
