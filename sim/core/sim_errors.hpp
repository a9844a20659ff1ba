// Errors the simulation raises. The app maps SetupError to exit code 2 (the scene asks for something
// impossible) and InstabilityError to exit code 3 (SPEC.md section 1).
#pragma once

#include <stdexcept>

namespace aortasph {

struct SetupError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct InstabilityError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace aortasph
