#include "image.hpp"

#include <png.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <string>
#include <system_error>

namespace aortasph {

Image::Image(int width, int height, uint8_t r, uint8_t g, uint8_t b)
    : w(width), h(height), rgb(static_cast<size_t>(width) * height * 3) {
  for (size_t k = 0; k < rgb.size(); k += 3) {
    rgb[k] = r;
    rgb[k + 1] = g;
    rgb[k + 2] = b;
  }
}

namespace {

struct PngSink {
  FILE* file = nullptr;                    // write to a file, or
  std::vector<uint8_t>* memory = nullptr;  // to memory
  char error[256] = {0};
};

void on_png_error(png_structp png, png_const_charp message) {
  auto* sink = static_cast<PngSink*>(png_get_error_ptr(png));
  std::snprintf(sink->error, sizeof sink->error, "%s", message);
  png_longjmp(png, 1);
}

void on_png_warning(png_structp, png_const_charp) {}

void write_to_memory(png_structp png, png_bytep data, png_size_t length) {
  auto* sink = static_cast<PngSink*>(png_get_io_ptr(png));
  sink->memory->insert(sink->memory->end(), data, data + length);
}

void write_to_file(png_structp png, png_bytep data, png_size_t length) {
  auto* sink = static_cast<PngSink*>(png_get_io_ptr(png));
  if (std::fwrite(data, 1, length, sink->file) != length) png_error(png, std::strerror(errno));
}

void flush_nothing(png_structp) {}

// libpng reports errors by longjmp: this function keeps only trivially destructible locals between setjmp
// and the libpng calls, and turns the jump into a false return with the message in sink.error.
bool encode(PngSink& sink, const Image& image) {
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &sink, on_png_error, on_png_warning);
  if (!png) {
    std::snprintf(sink.error, sizeof sink.error, "out of memory");
    return false;
  }
  png_infop info = png_create_info_struct(png);
  if (!info || setjmp(png_jmpbuf(png))) {
    if (!sink.error[0]) std::snprintf(sink.error, sizeof sink.error, "libpng failure");
    png_destroy_write_struct(&png, info ? &info : nullptr);
    return false;
  }
  png_set_write_fn(png, &sink, sink.file ? write_to_file : write_to_memory, flush_nothing);
  png_set_compression_level(png, 1);
  png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
  png_set_IHDR(png, info, static_cast<png_uint_32>(image.w), static_cast<png_uint_32>(image.h), 8,
               PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_BASE, PNG_FILTER_TYPE_BASE);
  png_write_info(png, info);
  for (int y = 0; y < image.h; ++y) png_write_row(png, const_cast<png_bytep>(image.at(0, y)));
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return true;
}

void check_image(const Image& image) {
  if (image.w <= 0 || image.h <= 0 || image.rgb.size() != static_cast<size_t>(image.w) * image.h * 3)
    throw RenderError("cannot encode an empty or inconsistent image");
}

}  // namespace

std::vector<uint8_t> encode_png(const Image& image) {
  check_image(image);
  std::vector<uint8_t> out;
  PngSink sink;
  sink.memory = &out;
  if (!encode(sink, image)) throw RenderError(std::string("PNG encoding failed: ") + sink.error);
  return out;
}

void write_png(const std::filesystem::path& path, const Image& image) {
  check_image(image);
  std::filesystem::path tmp = path;
  tmp += ".tmp";
  PngSink sink;
  sink.file = std::fopen(tmp.c_str(), "wb");
  if (!sink.file) throw RenderError("cannot write " + tmp.string() + ": " + std::strerror(errno));
  bool ok = encode(sink, image);
  std::string error = sink.error;
  if (std::fflush(sink.file) != 0 && ok) {
    ok = false;
    error = std::strerror(errno);
  }
  if (std::fclose(sink.file) != 0 && ok) {
    ok = false;
    error = std::strerror(errno);
  }
  std::error_code ec;
  if (ok) {
    std::filesystem::rename(tmp, path, ec);
    if (ec) {
      ok = false;
      error = "rename failed: " + ec.message();
    }
  }
  if (!ok) {
    std::filesystem::remove(tmp, ec);
    throw RenderError("cannot write " + path.string() + ": " + error);
  }
}

Image read_png(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw RenderError(path.string() + ": no such image file");
  png_image png;
  std::memset(&png, 0, sizeof png);
  png.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&png, path.c_str()))
    throw RenderError(path.string() + ": not a readable PNG (" + png.message + ")");
  png.format = PNG_FORMAT_RGB;
  Image image;
  image.w = static_cast<int>(png.width);
  image.h = static_cast<int>(png.height);
  image.rgb.resize(PNG_IMAGE_SIZE(png));
  const png_color black = {0, 0, 0};
  if (!png_image_finish_read(&png, &black, image.rgb.data(), 0, nullptr)) {
    const std::string message = png.message;
    png_image_free(&png);
    throw RenderError(path.string() + ": corrupt PNG (" + message + ")");
  }
  return image;
}

Image resize(const Image& image, int w, int h) {
  if (w == image.w && h == image.h) return image;
  Image out(w, h);
  const double sx = static_cast<double>(image.w) / w;
  const double sy = static_cast<double>(image.h) / h;
  for (int y = 0; y < h; ++y) {
    const double y0 = y * sy, y1 = (y + 1) * sy;
    for (int x = 0; x < w; ++x) {
      const double x0 = x * sx, x1 = (x + 1) * sx;
      double acc[3] = {0, 0, 0}, weight = 0;
      // Each source pixel weighs by its overlap with the destination pixel's footprint.
      for (int v = static_cast<int>(y0); v < std::min(image.h, static_cast<int>(std::ceil(y1))); ++v) {
        const double wy = std::min(y1, v + 1.0) - std::max(y0, static_cast<double>(v));
        for (int u = static_cast<int>(x0); u < std::min(image.w, static_cast<int>(std::ceil(x1))); ++u) {
          const double wx = std::min(x1, u + 1.0) - std::max(x0, static_cast<double>(u));
          const uint8_t* p = image.at(u, v);
          for (int c = 0; c < 3; ++c) acc[c] += wx * wy * p[c];
          weight += wx * wy;
        }
      }
      for (int c = 0; c < 3; ++c) out.at(x, y)[c] = static_cast<uint8_t>(std::lround(acc[c] / weight));
    }
  }
  return out;
}

}  // namespace aortasph
