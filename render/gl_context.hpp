// OSMesa (llvmpipe) offscreen OpenGL 3.3+ core context and GLSL program building.
// A context is current on one thread at a time; whoever draws calls make_current() on its own thread first.
#pragma once

#include <string>
#include <string_view>

#include "render_error.hpp"

namespace aortasph {

class GlContext {
 public:
  // Creates a core-profile context (throws RenderError if OSMesa cannot) and makes it current.
  GlContext();
  ~GlContext();
  GlContext(const GlContext&) = delete;
  GlContext& operator=(const GlContext&) = delete;

  void make_current();
  std::string renderer_name() const;  // e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"

 private:
  void* context_ = nullptr;       // OSMesaContext
  unsigned char dummy_[4 * 4]{};  // OSMesa needs a default framebuffer; all drawing goes to our own FBOs
};

// Compiles and links a vertex + fragment program. The names are the shader files (e.g.
// "shaders/splat.vert.glsl"); a compile error throws RenderError with "file:line:column: message" lines taken
// from the GLSL log.
unsigned build_program(std::string_view vert_name, std::string_view vert_source, std::string_view frag_name,
                       std::string_view frag_source);

// Throws RenderError naming `what` if glGetError() reports an error.
void check_gl(const char* what);

}  // namespace aortasph
