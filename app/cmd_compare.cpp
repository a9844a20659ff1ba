// aortasph compare: see render_commands.hpp. The comparison itself lives in render/image_compare so that the
// golden-image tests decide exactly as this command does.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iterator>

#include "image_compare.hpp"
#include "render_commands.hpp"

namespace aortasph {

namespace fs = std::filesystem;

namespace {

int usage_error(const std::string& message) {
  std::fprintf(stderr,
               "aortasph compare: error: %s\nusage: aortasph compare A B [--diff DIFF.png] [--tolerance T]\n",
               message.c_str());
  return 2;
}

std::string join_some(const std::vector<std::string>& names) {
  std::string s;
  for (size_t k = 0; k < names.size() && k < 5; ++k) s += (k ? ", " : "") + names[k];
  if (names.size() > 5) s += ", ... (" + std::to_string(names.size()) + " in all)";
  return s;
}

}  // namespace

int cmd_compare(const std::vector<std::string>& args) {
  std::vector<std::string> paths;
  std::string diff_path;
  int tolerance = 0;
  for (size_t k = 0; k < args.size(); ++k) {
    if (args[k] == "--diff") {
      if (k + 1 >= args.size()) return usage_error("--diff: missing the output path");
      diff_path = args[++k];
    } else if (args[k] == "--tolerance") {
      if (k + 1 >= args.size()) return usage_error("--tolerance: missing the value");
      const std::string& v = args[++k];
      size_t used = 0;
      try {
        tolerance = std::stoi(v, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != v.size() || tolerance < 0 || tolerance > 255)
        return usage_error(
            "--tolerance: expected an integer 0..255 (largest allowed channel difference), got " + v);
    } else if (args[k].size() > 1 && args[k][0] == '-') {
      return usage_error(args[k] + ": unknown option");
    } else {
      paths.push_back(args[k]);
    }
  }
  if (paths.size() != 2)
    return usage_error("expected two images or two folders, got " + std::to_string(paths.size()));
  const fs::path a = paths[0], b = paths[1];
  std::error_code ec;
  for (const fs::path& p : {a, b})
    if (!fs::exists(p, ec)) return usage_error(p.string() + ": no such file or folder");
  const bool dir_a = fs::is_directory(a, ec), dir_b = fs::is_directory(b, ec);
  if (dir_a != dir_b) return usage_error("compare a file with a file or a folder with a folder");

  std::vector<std::string> names;
  if (dir_a) {
    const auto na = png_names(a), nb = png_names(b);
    if (na != nb) {
      std::vector<std::string> only_a, only_b;
      std::set_difference(na.begin(), na.end(), nb.begin(), nb.end(), std::back_inserter(only_a));
      std::set_difference(nb.begin(), nb.end(), na.begin(), na.end(), std::back_inserter(only_b));
      std::string msg = "the folders hold different PNG files:";
      if (!only_a.empty()) msg += "\n  only in " + a.string() + ": " + join_some(only_a);
      if (!only_b.empty()) msg += "\n  only in " + b.string() + ": " + join_some(only_b);
      return usage_error(msg);
    }
    if (na.empty()) return usage_error("no PNG files in " + a.string() + " and " + b.string());
    names = na;
    if (!diff_path.empty()) {
      fs::create_directories(diff_path, ec);
      if (ec) return usage_error("cannot create the diff folder " + diff_path + ": " + ec.message());
    }
  }

  // Read and check everything first, so that bad input (exit 2) is never mixed with a partial verdict.
  struct Pair {
    std::string name;
    Image ia, ib;
  };
  std::vector<Pair> pairs;
  try {
    if (dir_a) {
      for (const auto& n : names) pairs.push_back({n, read_png(a / n), read_png(b / n)});
    } else {
      pairs.push_back({a.filename().string(), read_png(a), read_png(b)});
    }
    for (const Pair& p : pairs)
      if (p.ia.w != p.ib.w || p.ia.h != p.ib.h)
        return usage_error(p.name + ": image sizes differ: " + std::to_string(p.ia.w) + "x" +
                           std::to_string(p.ia.h) + " in A vs " + std::to_string(p.ib.w) + "x" +
                           std::to_string(p.ib.h) +
                           " in B (render both with the same render.width and render.height)");
  } catch (const RenderError& e) {
    return usage_error(e.what());
  }

  int beyond = 0;
  for (const Pair& p : pairs) {
    const ImageDiff d = compare_images(p.ia, p.ib);
    const bool ok = d.within(tolerance);
    beyond += !ok;
    std::printf("%s%s\n", describe(p.name, d).c_str(), ok ? "" : "  BEYOND TOLERANCE");
    if (!diff_path.empty() && (!dir_a || d.max_channel_diff > 0)) {
      const fs::path out = dir_a ? fs::path(diff_path) / p.name : fs::path(diff_path);
      try {
        write_png(out, diff_image(p.ia, p.ib, tolerance));
      } catch (const RenderError& e) {
        return usage_error(e.what());
      }
    }
  }
  std::printf("%zu image(s) compared, %d beyond tolerance %d (largest allowed channel difference)\n",
              pairs.size(), beyond, tolerance);
  return beyond ? 1 : 0;
}

}  // namespace aortasph
