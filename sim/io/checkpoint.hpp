// Checkpoint files: a small binary container of named, versioned sections, so that a run can be stopped and
// resumed with bitwise identical results (issue 7).
//
// File layout (little endian, as the machine writes it; a checkpoint is resumed on the machine kind that
// wrote it):
//   magic "AORTASPH-CKPT\n" (14 bytes), format version (u32), section count (u32),
//   per section: name (u32 length + bytes), version (u32), payload size (u64), payload,
//   FNV-1a 64 checksum of everything before it (u64).
// Sections are independent: a reader asks for a section by name and gets the version it was written with, so
// new state can be added as a new section without touching the others.
//
// To add state of your own (a new model's per-particle arrays, counters): write a section in
// World::save_state() with StateWriter::section("yourname", version) and read it in World::load_state() with
// StateReader::section("yourname"). Per-particle arrays of Particles need nothing: they are listed once in
// Particles::for_each_array().
#pragma once

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <map>
#include <string>
#include <type_traits>
#include <vector>

#include "scene.hpp"

namespace aortasph {

// FNV-1a 64-bit hash (checksums, scene fingerprints).
uint64_t fnv1a64(const void* data, std::size_t size, uint64_t h = 0xcbf29ce484222325ull);

// Bytes of one section, written field by field.
class SectionWriter {
 public:
  template <class T>
  void value(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>, "value(): plain data only");
    raw(&v, sizeof v);
  }
  void vec3(const Vec3& v) { raw(v.data(), 3 * sizeof(double)); }
  void string(const std::string& s) {
    value(static_cast<uint64_t>(s.size()));
    raw(s.data(), s.size());
  }
  // A per-particle (or any) array: its length, then its elements.
  template <class T>
  void array(const std::vector<T>& a) {
    value(static_cast<uint64_t>(a.size()));
    if constexpr (std::is_same_v<T, Vec3>) {
      for (const Vec3& v : a) vec3(v);
    } else {
      static_assert(std::is_trivially_copyable_v<T>, "array(): plain data only");
      raw(a.data(), a.size() * sizeof(T));
    }
  }
  void raw(const void* p, std::size_t n) {
    const std::size_t at = bytes_.size();
    bytes_.resize(at + n);
    if (n) std::memcpy(bytes_.data() + at, p, n);
  }
  const std::vector<char>& bytes() const { return bytes_; }

 private:
  std::vector<char> bytes_;
};

// Reads a section back; every read checks the bounds and throws SetupError on a short or corrupt section.
class SectionReader {
 public:
  SectionReader(std::string name, uint32_t version, const char* data, std::size_t size)
      : name_(std::move(name)), version_(version), data_(data), size_(size) {}
  uint32_t version() const { return version_; }
  const std::string& name() const { return name_; }

  template <class T>
  T value() {
    static_assert(std::is_trivially_copyable_v<T>, "value(): plain data only");
    T v;
    raw(&v, sizeof v);
    return v;
  }
  Vec3 vec3() {
    Vec3 v;
    raw(v.data(), 3 * sizeof(double));
    return v;
  }
  std::string string() {
    const uint64_t n = length(1);
    std::string s(n, '\0');
    raw(s.data(), n);
    return s;
  }
  // Reads an array; expected_size, when given, must match (a checkpoint of another scene is refused).
  template <class T>
  void array(std::vector<T>& a, const char* what, std::size_t expected_size = SIZE_MAX) {
    const uint64_t n = length(std::is_same_v<T, Vec3> ? 3 * sizeof(double) : sizeof(T));
    if (expected_size != SIZE_MAX && n != expected_size) mismatch(what, n, expected_size);
    a.resize(n);
    if constexpr (std::is_same_v<T, Vec3>) {
      for (Vec3& v : a) v = vec3();
    } else {
      static_assert(std::is_trivially_copyable_v<T>, "array(): plain data only");
      raw(a.data(), n * sizeof(T));
    }
  }
  void raw(void* p, std::size_t n);
  // Throws unless the whole section was read (a section longer than its reader expects is another layout).
  void done() const;
  [[noreturn]] void mismatch(const char* what, uint64_t got, uint64_t expected) const;

 private:
  uint64_t length(std::size_t element_size);
  std::string name_;
  uint32_t version_;
  const char* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
};

class StateWriter {
 public:
  // Starts a new section; the returned writer stays valid until the next call.
  SectionWriter& section(const std::string& name, uint32_t version);
  // The whole file's bytes (header, sections, checksum).
  std::vector<char> bytes() const;
  // Writes the file atomically: to PATH.tmp, flushed to disk, then renamed over PATH. Throws SetupError
  // naming the path on any write error (a full disk), leaving PATH as it was.
  void write_file(const std::filesystem::path& path) const;

 private:
  std::vector<std::pair<std::string, uint32_t>> names_;
  std::vector<SectionWriter> sections_;
};

class StateReader {
 public:
  // Parses and verifies a file (magic, format version, checksum); throws SetupError naming the problem.
  static StateReader from_file(const std::filesystem::path& path);
  explicit StateReader(std::vector<char> bytes, const std::string& what = "checkpoint");

  bool has(const std::string& name) const { return sections_.count(name) > 0; }
  // The named section; throws SetupError when the checkpoint has none.
  SectionReader section(const std::string& name) const;

 private:
  struct Entry {
    uint32_t version;
    std::size_t offset, size;
  };
  std::string what_;
  std::vector<char> bytes_;
  std::map<std::string, Entry> sections_;
};

}  // namespace aortasph
