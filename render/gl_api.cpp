#include "gl_api.hpp"

#include <dlfcn.h>

#include <mutex>
#include <string>

#include "render_error.hpp"

namespace aortasph::gl {

#define AORTASPH_GL_DEFINE(name) decltype(p_##name) p_##name = nullptr;
AORTASPH_GL_FUNCTIONS(AORTASPH_GL_DEFINE)
#undef AORTASPH_GL_DEFINE

namespace {

// AORTASPH_OSMESA_SONAME ("libOSMesa.so.8") and AORTASPH_OSMESA_PATH (the library CMake found) come from
// render/CMakeLists.txt.
std::string open_and_resolve() {
  void* lib = dlopen(AORTASPH_OSMESA_SONAME, RTLD_NOW | RTLD_LOCAL);
  std::string why;
  if (!lib) {
    why = dlerror();
    lib = dlopen(AORTASPH_OSMESA_PATH, RTLD_NOW | RTLD_LOCAL);
  }
  if (!lib)
    return std::string("cannot load the OSMesa library (" AORTASPH_OSMESA_SONAME
                       ", needed to draw frames; "
                       "install Mesa's libosmesa or run with --no-render): ") +
           why;
  // The library stays loaded to the end of the process (never dlclose'd): the context and its framebuffer
  // live in it, and LeakSanitizer's suppression (gl_context.cpp) needs its name at exit.
  const auto osmesa_get_proc =
      reinterpret_cast<OSMESAproc (*)(const char*)>(dlsym(lib, "OSMesaGetProcAddress"));
  std::string missing;
  const auto resolve = [&](const char* name) -> void* {
    void* f = dlsym(lib, name);
    if (!f && osmesa_get_proc) f = reinterpret_cast<void*>(osmesa_get_proc(name));
    if (!f) missing += std::string(missing.empty() ? "" : ", ") + name;
    return f;
  };
#define AORTASPH_GL_RESOLVE(name) p_##name = reinterpret_cast<decltype(p_##name)>(resolve(#name));
  AORTASPH_GL_FUNCTIONS(AORTASPH_GL_RESOLVE)
#undef AORTASPH_GL_RESOLVE
  if (!missing.empty()) return "the OSMesa library " AORTASPH_OSMESA_SONAME " lacks " + missing;
  return {};
}

}  // namespace

void load() {
  static std::once_flag once;
  static std::string error;
  std::call_once(once, [] { error = open_and_resolve(); });
  if (!error.empty()) throw RenderError(error);
}

}  // namespace aortasph::gl
