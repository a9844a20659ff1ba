// aortasph movie: see render_commands.hpp.
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>

#include "render_commands.hpp"

extern char** environ;

namespace aortasph {

namespace fs = std::filesystem;

namespace {

int usage_error(const std::string& message) {
  std::fprintf(stderr, "aortasph movie: error: %s\nusage: aortasph movie DIR [--fps N]\n", message.c_str());
  return 2;
}

// ffmpeg on PATH ($AORTASPH_FFMPEG overrides), or empty.
std::string find_ffmpeg() {
  if (const char* env = std::getenv("AORTASPH_FFMPEG"); env && *env) return access(env, X_OK) == 0 ? env : "";
  const char* path = std::getenv("PATH");
  std::istringstream dirs(path ? path : "");
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    const fs::path candidate = fs::path(dir.empty() ? "." : dir) / "ffmpeg";
    if (access(candidate.c_str(), X_OK) == 0) return candidate;
  }
  return "";
}

// Runs a program without a shell (no quoting problems with odd folder names); returns its exit status.
int run_program(const std::vector<std::string>& argv) {
  std::vector<char*> cargs;
  for (const auto& a : argv) cargs.push_back(const_cast<char*>(a.c_str()));
  cargs.push_back(nullptr);
  pid_t pid = 0;
  if (posix_spawn(&pid, cargs[0], nullptr, nullptr, cargs.data(), environ) != 0) return 127;
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128;
}

struct FrameFolder {
  fs::path dir;
  std::vector<int> frames;  // sorted frame numbers
};

}  // namespace

int cmd_movie(const std::vector<std::string>& args) {
  std::string dir_arg;
  int fps = 30;
  for (size_t k = 0; k < args.size(); ++k) {
    if (args[k] == "--fps") {
      if (k + 1 >= args.size()) return usage_error("--fps: missing the value");
      const std::string& v = args[++k];
      size_t used = 0;
      try {
        fps = std::stoi(v, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != v.size() || fps < 1 || fps > 1000)
        return usage_error("--fps: expected an integer 1..1000, got " + v);
    } else if (args[k].size() > 1 && args[k][0] == '-') {
      return usage_error(args[k] + ": unknown option");
    } else if (dir_arg.empty()) {
      dir_arg = args[k];
    } else {
      return usage_error(args[k] + ": unexpected argument");
    }
  }
  if (dir_arg.empty()) return usage_error("missing DIR");
  const fs::path root = dir_arg;
  std::error_code ec;
  if (!fs::is_directory(root, ec)) return usage_error(dir_arg + ": no such folder");

  // frame_NNNNN.png with exactly five digits, as the run writes them and ffmpeg's %05d reads them.
  const auto frame_number = [](const std::string& name) {
    if (name.size() != 15 || name.compare(0, 6, "frame_") != 0 || name.compare(11, 4, ".png") != 0) return -1;
    for (size_t k = 6; k < 11; ++k)
      if (!std::isdigit(static_cast<unsigned char>(name[k]))) return -1;
    return std::stoi(name.substr(6, 5));
  };
  std::vector<FrameFolder> folders;
  auto scan = [&](const fs::path& dir) {
    FrameFolder f{dir, {}};
    for (const auto& e : fs::directory_iterator(dir, ec)) {
      const int number = frame_number(e.path().filename().string());
      if (number >= 0 && e.is_regular_file()) f.frames.push_back(number);
    }
    if (!f.frames.empty()) {
      std::sort(f.frames.begin(), f.frames.end());
      folders.push_back(std::move(f));
    }
  };
  scan(root);
  for (auto it = fs::recursive_directory_iterator(root, ec); !ec && it != fs::recursive_directory_iterator();
       it.increment(ec))
    if (it->is_directory()) scan(it->path());
  if (folders.empty()) return usage_error("no frame_NNNNN.png files under " + dir_arg);
  std::sort(folders.begin(), folders.end(), [](const auto& x, const auto& y) { return x.dir < y.dir; });

  const std::string ffmpeg = find_ffmpeg();
  if (ffmpeg.empty())
    return usage_error(
        "ffmpeg not found on PATH (install it, e.g. apt-get install ffmpeg); the equivalent command is\n"
        "  ffmpeg -framerate 30 -i frame_%05d.png -c:v libx264 -crf 20 -pix_fmt yuv420p movie.mp4");

  int failures = 0;
  for (const FrameFolder& f : folders) {
    const fs::path dir = fs::weakly_canonical(f.dir, ec);
    const fs::path movie = dir.parent_path() / (dir.filename().string() + ".mp4");
    // ffmpeg's image sequence stops at the first missing number: say so rather than silently cut the movie.
    const int expected = f.frames.back() - f.frames.front() + 1;
    if (static_cast<int>(f.frames.size()) != expected)
      std::fprintf(stderr,
                   "aortasph movie: warning: %s: frame numbers have gaps; the movie stops at the first\n",
                   f.dir.string().c_str());
    const int status =
        run_program({ffmpeg, "-y", "-loglevel", "error", "-framerate", std::to_string(fps), "-start_number",
                     std::to_string(f.frames.front()), "-i", (dir / "frame_%05d.png").string(), "-c:v",
                     "libx264", "-crf", "20", "-pix_fmt", "yuv420p", movie.string()});
    if (status != 0) {
      std::fprintf(stderr, "aortasph movie: error: ffmpeg failed (exit %d) for %s\n", status,
                   f.dir.string().c_str());
      ++failures;
      continue;
    }
    std::printf("%s: %zu frames at %d fps\n", movie.string().c_str(), f.frames.size(), fps);
  }
  return failures ? 1 : 0;
}

}  // namespace aortasph
