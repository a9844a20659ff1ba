// The OpenGL and OSMesa entry points the renderer calls, loaded from libOSMesa at run time (dlopen) instead
// of linked: libOSMesa pulls in llvmpipe and libLLVM (about 40 MiB resident on the 100k bench, 441 B per
// fluid particle), which a run that draws no frame should not carry (docs/performance.md, "Memory"). Render
// code includes this header instead of <GL/osmesa.h>: each name below is a macro for a function pointer that
// gl::load() fills, which GlContext's constructor calls first, so every GL user holds a GlContext first.
#pragma once

#include <GL/osmesa.h>  // also brings gl.h and glext.h (GL_GLEXT_PROTOTYPES): the prototypes give the types

// Every entry point the renderer uses, OSMesa's first. The binary no longer links libOSMesa, so a GL call
// missing from this list fails the link (undefined reference) instead of silently loading the library.
#define AORTASPH_GL_FUNCTIONS(X)      \
  X(OSMesaCreateContextAttribs)       \
  X(OSMesaMakeCurrent)                \
  X(OSMesaDestroyContext)             \
  X(glAttachShader)                   \
  X(glBindBuffer)                     \
  X(glBindFramebuffer)                \
  X(glBindRenderbuffer)               \
  X(glBindVertexArray)                \
  X(glBlendFunc)                      \
  X(glBlitFramebuffer)                \
  X(glBufferData)                     \
  X(glCheckFramebufferStatus)         \
  X(glClear)                          \
  X(glClearColor)                     \
  X(glClearDepth)                     \
  X(glCompileShader)                  \
  X(glCreateProgram)                  \
  X(glCreateShader)                   \
  X(glDeleteBuffers)                  \
  X(glDeleteFramebuffers)             \
  X(glDeleteProgram)                  \
  X(glDeleteRenderbuffers)            \
  X(glDeleteShader)                   \
  X(glDeleteVertexArrays)             \
  X(glDepthFunc)                      \
  X(glDepthMask)                      \
  X(glDisable)                        \
  X(glDrawArrays)                     \
  X(glDrawElements)                   \
  X(glEnable)                         \
  X(glEnableVertexAttribArray)        \
  X(glFramebufferRenderbuffer)        \
  X(glGenBuffers)                     \
  X(glGenFramebuffers)                \
  X(glGenRenderbuffers)               \
  X(glGenVertexArrays)                \
  X(glGetError)                       \
  X(glGetFloatv)                      \
  X(glGetIntegerv)                    \
  X(glGetProgramInfoLog)              \
  X(glGetProgramiv)                   \
  X(glGetShaderInfoLog)               \
  X(glGetShaderiv)                    \
  X(glGetString)                      \
  X(glGetUniformLocation)             \
  X(glLinkProgram)                    \
  X(glPixelStorei)                    \
  X(glReadPixels)                     \
  X(glRenderbufferStorage)            \
  X(glRenderbufferStorageMultisample) \
  X(glShaderSource)                   \
  X(glUniform1f)                      \
  X(glUniform2f)                      \
  X(glUniform3f)                      \
  X(glUniform3fv)                     \
  X(glUniform4fv)                     \
  X(glUniformMatrix4fv)               \
  X(glUseProgram)                     \
  X(glVertexAttribPointer)            \
  X(glViewport)

namespace aortasph::gl {

#define AORTASPH_GL_DECLARE(name) extern decltype(&::name) p_##name;
AORTASPH_GL_FUNCTIONS(AORTASPH_GL_DECLARE)
#undef AORTASPH_GL_DECLARE

// Opens libOSMesa (its soname, then the path CMake found at build time) and resolves every entry point above,
// once per process (thread-safe). Throws RenderError naming the library and the loader's message if the
// library or a symbol cannot be found; the command line reports it as a render error (exit code 2).
void load();

}  // namespace aortasph::gl

// The calls in render/*.cpp go through the loaded pointers.
#define OSMesaCreateContextAttribs ::aortasph::gl::p_OSMesaCreateContextAttribs
#define OSMesaMakeCurrent ::aortasph::gl::p_OSMesaMakeCurrent
#define OSMesaDestroyContext ::aortasph::gl::p_OSMesaDestroyContext
#define glAttachShader ::aortasph::gl::p_glAttachShader
#define glBindBuffer ::aortasph::gl::p_glBindBuffer
#define glBindFramebuffer ::aortasph::gl::p_glBindFramebuffer
#define glBindRenderbuffer ::aortasph::gl::p_glBindRenderbuffer
#define glBindVertexArray ::aortasph::gl::p_glBindVertexArray
#define glBlendFunc ::aortasph::gl::p_glBlendFunc
#define glBlitFramebuffer ::aortasph::gl::p_glBlitFramebuffer
#define glBufferData ::aortasph::gl::p_glBufferData
#define glCheckFramebufferStatus ::aortasph::gl::p_glCheckFramebufferStatus
#define glClear ::aortasph::gl::p_glClear
#define glClearColor ::aortasph::gl::p_glClearColor
#define glClearDepth ::aortasph::gl::p_glClearDepth
#define glCompileShader ::aortasph::gl::p_glCompileShader
#define glCreateProgram ::aortasph::gl::p_glCreateProgram
#define glCreateShader ::aortasph::gl::p_glCreateShader
#define glDeleteBuffers ::aortasph::gl::p_glDeleteBuffers
#define glDeleteFramebuffers ::aortasph::gl::p_glDeleteFramebuffers
#define glDeleteProgram ::aortasph::gl::p_glDeleteProgram
#define glDeleteRenderbuffers ::aortasph::gl::p_glDeleteRenderbuffers
#define glDeleteShader ::aortasph::gl::p_glDeleteShader
#define glDeleteVertexArrays ::aortasph::gl::p_glDeleteVertexArrays
#define glDepthFunc ::aortasph::gl::p_glDepthFunc
#define glDepthMask ::aortasph::gl::p_glDepthMask
#define glDisable ::aortasph::gl::p_glDisable
#define glDrawArrays ::aortasph::gl::p_glDrawArrays
#define glDrawElements ::aortasph::gl::p_glDrawElements
#define glEnable ::aortasph::gl::p_glEnable
#define glEnableVertexAttribArray ::aortasph::gl::p_glEnableVertexAttribArray
#define glFramebufferRenderbuffer ::aortasph::gl::p_glFramebufferRenderbuffer
#define glGenBuffers ::aortasph::gl::p_glGenBuffers
#define glGenFramebuffers ::aortasph::gl::p_glGenFramebuffers
#define glGenRenderbuffers ::aortasph::gl::p_glGenRenderbuffers
#define glGenVertexArrays ::aortasph::gl::p_glGenVertexArrays
#define glGetError ::aortasph::gl::p_glGetError
#define glGetFloatv ::aortasph::gl::p_glGetFloatv
#define glGetIntegerv ::aortasph::gl::p_glGetIntegerv
#define glGetProgramInfoLog ::aortasph::gl::p_glGetProgramInfoLog
#define glGetProgramiv ::aortasph::gl::p_glGetProgramiv
#define glGetShaderInfoLog ::aortasph::gl::p_glGetShaderInfoLog
#define glGetShaderiv ::aortasph::gl::p_glGetShaderiv
#define glGetString ::aortasph::gl::p_glGetString
#define glGetUniformLocation ::aortasph::gl::p_glGetUniformLocation
#define glLinkProgram ::aortasph::gl::p_glLinkProgram
#define glPixelStorei ::aortasph::gl::p_glPixelStorei
#define glReadPixels ::aortasph::gl::p_glReadPixels
#define glRenderbufferStorage ::aortasph::gl::p_glRenderbufferStorage
#define glRenderbufferStorageMultisample ::aortasph::gl::p_glRenderbufferStorageMultisample
#define glShaderSource ::aortasph::gl::p_glShaderSource
#define glUniform1f ::aortasph::gl::p_glUniform1f
#define glUniform2f ::aortasph::gl::p_glUniform2f
#define glUniform3f ::aortasph::gl::p_glUniform3f
#define glUniform3fv ::aortasph::gl::p_glUniform3fv
#define glUniform4fv ::aortasph::gl::p_glUniform4fv
#define glUniformMatrix4fv ::aortasph::gl::p_glUniformMatrix4fv
#define glUseProgram ::aortasph::gl::p_glUseProgram
#define glVertexAttribPointer ::aortasph::gl::p_glVertexAttribPointer
#define glViewport ::aortasph::gl::p_glViewport
