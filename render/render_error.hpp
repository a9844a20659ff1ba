// The renderer's error type: bad render settings, a GL or shader failure, an unreadable or unwritable image.
#pragma once

#include <stdexcept>

namespace aortasph {

struct RenderError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace aortasph
