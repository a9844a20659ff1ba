// Error kinds that map to the exit codes of SPEC.md section 1.
#pragma once

#include <stdexcept>
#include <string>

namespace aortasph {

// Bad input: scene file, arguments, paths, unwritable output. Exit code 2. The message names the problem,
// for scene values by JSON path: "bodies[2].shape.box.max: expected 3 numbers, got 2".
struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace aortasph
