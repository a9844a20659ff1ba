#include "gl_context.hpp"

#include <algorithm>
#include <cctype>
#include <sstream>
#include <vector>

#include "gl_api.hpp"  // GL and OSMesa, loaded at the first GlContext (not linked)

namespace aortasph {

GlContext::GlContext() {
  gl::load();  // opens libOSMesa on the first context: a run that draws nothing never maps llvmpipe
  const int attribs[] = {OSMESA_FORMAT,
                         OSMESA_RGBA,
                         OSMESA_DEPTH_BITS,
                         0,
                         OSMESA_PROFILE,
                         OSMESA_CORE_PROFILE,
                         OSMESA_CONTEXT_MAJOR_VERSION,
                         3,
                         OSMESA_CONTEXT_MINOR_VERSION,
                         3,
                         0};
  context_ = OSMesaCreateContextAttribs(attribs, nullptr);
  if (!context_)
    throw RenderError("OSMesa: could not create an OpenGL 3.3 core context (is llvmpipe available?)");
  make_current();
}

GlContext::~GlContext() {
  if (context_) OSMesaDestroyContext(static_cast<OSMesaContext>(context_));
}

void GlContext::make_current() {
  if (!OSMesaMakeCurrent(static_cast<OSMesaContext>(context_), dummy_, GL_UNSIGNED_BYTE, 2, 2))
    throw RenderError("OSMesa: could not make the context current");
}

std::string GlContext::renderer_name() const {
  const GLubyte* name = glGetString(GL_RENDERER);
  return name ? reinterpret_cast<const char*>(name) : "unknown";
}

void check_gl(const char* what) {
  const GLenum err = glGetError();
  if (err != GL_NO_ERROR) {
    std::ostringstream msg;
    msg << "OpenGL error 0x" << std::hex << err << " in " << what;
    throw RenderError(msg.str());
  }
}

namespace {

// Mesa logs "0:12(5): error: ..." (source string 0, line 12, column 5). Reads that prefix, if present.
bool parse_mesa_location(const std::string& line, std::string& row, std::string& col, std::string& rest) {
  size_t k = 0;
  while (k < line.size() && std::isspace(static_cast<unsigned char>(line[k]))) ++k;
  const auto digits = [&](std::string& out) {
    const size_t start = k;
    while (k < line.size() && std::isdigit(static_cast<unsigned char>(line[k]))) ++k;
    out = line.substr(start, k - start);
    return !out.empty();
  };
  std::string source;
  if (!digits(source) || k >= line.size() || line[k++] != ':' || !digits(row)) return false;
  if (k >= line.size() || line[k++] != '(' || !digits(col)) return false;
  if (line.compare(k, 2, "):") != 0) return false;
  k += 2;
  while (k < line.size() && line[k] == ' ') ++k;
  rest = line.substr(k);
  return true;
}

// Rewrites each log line to the usual "file:line:column: message", so the failing source line is found
// directly.
std::string rewrite_log(std::string_view name, const std::string& log) {
  std::istringstream in(log);
  std::ostringstream out;
  std::string line, row, col, rest;
  bool any = false;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    if (parse_mesa_location(line, row, col, rest))
      out << "\n  " << name << ':' << row << ':' << col << ": " << rest;
    else
      out << "\n  " << name << ": " << line;
    any = true;
  }
  if (!any) out << "\n  " << name << ": (no log)";
  return out.str();
}

GLuint compile(GLenum type, std::string_view name, std::string_view source) {
  const GLuint shader = glCreateShader(type);
  const GLchar* text = source.data();
  const GLint length = static_cast<GLint>(source.size());
  glShaderSource(shader, 1, &text, &length);
  glCompileShader(shader);
  GLint ok = GL_FALSE;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (ok != GL_TRUE) {
    GLint log_length = 0;
    glGetShaderiv(shader, GL_INFO_LOG_LENGTH, &log_length);
    std::string log(static_cast<size_t>(std::max(log_length, 1)), '\0');
    glGetShaderInfoLog(shader, log_length, nullptr, log.data());
    log.resize(log.find('\0') == std::string::npos ? log.size() : log.find('\0'));
    glDeleteShader(shader);
    throw RenderError("shader " + std::string(name) + " failed to compile:" + rewrite_log(name, log));
  }
  return shader;
}

}  // namespace

unsigned build_program(std::string_view vert_name, std::string_view vert_source, std::string_view frag_name,
                       std::string_view frag_source) {
  const GLuint vert = compile(GL_VERTEX_SHADER, vert_name, vert_source);
  GLuint frag = 0;
  try {
    frag = compile(GL_FRAGMENT_SHADER, frag_name, frag_source);
  } catch (...) {
    glDeleteShader(vert);
    throw;
  }
  const GLuint program = glCreateProgram();
  glAttachShader(program, vert);
  glAttachShader(program, frag);
  glLinkProgram(program);
  glDeleteShader(vert);
  glDeleteShader(frag);
  GLint ok = GL_FALSE;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (ok != GL_TRUE) {
    GLint log_length = 0;
    glGetProgramiv(program, GL_INFO_LOG_LENGTH, &log_length);
    std::string log(static_cast<size_t>(std::max(log_length, 1)), '\0');
    glGetProgramInfoLog(program, log_length, nullptr, log.data());
    glDeleteProgram(program);
    throw RenderError("shaders " + std::string(vert_name) + " + " + std::string(frag_name) +
                      " failed to link: " + log.c_str());
  }
  return program;
}

}  // namespace aortasph

// libOSMesa (Mesa 22) never frees the framebuffer it allocates in OSMesaMakeCurrent, even after
// OSMesaDestroyContext. LeakSanitizer (the project's ASan test build runs with detect_leaks=1) would fail
// every test binary that renders; this hook, read by LSan at exit, suppresses leaks allocated inside
// libOSMesa only. It is an unused function in builds without the sanitizer.
extern "C" const char* __lsan_default_suppressions() {
  return "leak:libOSMesa.so\n";
}
