#include "io/checkpoint.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <fstream>
#include <string_view>

#include "core/sim_errors.hpp"

namespace aortasph {

namespace {

constexpr std::string_view kMagic = "AORTASPH-CKPT\n";
constexpr std::size_t kMagicSize = kMagic.size();
constexpr uint32_t kFormatVersion = 1;

template <class T>
void put(std::vector<char>& out, const T& v) {
  // resize + memcpy rather than insert(): GCC 12 reports a false -Warray-bounds on the inlined insert.
  const std::size_t at = out.size();
  out.resize(at + sizeof v);
  std::memcpy(out.data() + at, &v, sizeof v);
}

}  // namespace

uint64_t fnv1a64(const void* data, std::size_t size, uint64_t h) {
  const auto* c = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < size; ++i) {
    h ^= c[i];
    h *= 0x100000001b3ull;
  }
  return h;
}

void SectionReader::raw(void* p, std::size_t n) {
  if (n > size_ - pos_)
    throw SetupError("checkpoint section '" + name_ +
                     "' is shorter than expected (corrupt or another layout)");
  std::memcpy(p, data_ + pos_, n);
  pos_ += n;
}

uint64_t SectionReader::length(std::size_t element_size) {
  const uint64_t n = value<uint64_t>();
  if (element_size && n > (size_ - pos_) / element_size)
    throw SetupError("checkpoint section '" + name_ + "': an array length of " + std::to_string(n) +
                     " runs past the end of the section (corrupt)");
  return n;
}

void SectionReader::done() const {
  if (pos_ != size_)
    throw SetupError("checkpoint section '" + name_ + "' (version " + std::to_string(version_) + ") has " +
                     std::to_string(size_ - pos_) + " unread bytes: written by another layout");
}

void SectionReader::mismatch(const char* what, uint64_t got, uint64_t expected) const {
  throw SetupError("checkpoint section '" + name_ + "': " + what + " has " + std::to_string(got) +
                   " entries, this scene has " + std::to_string(expected) +
                   " (the checkpoint belongs to another scene)");
}

SectionWriter& StateWriter::section(const std::string& name, uint32_t version) {
  for (const auto& [n, v] : names_)
    if (n == name) throw SetupError("checkpoint: section '" + name + "' written twice");
  names_.emplace_back(name, version);
  sections_.emplace_back();
  return sections_.back();
}

std::vector<char> StateWriter::bytes() const {
  std::vector<char> out(kMagic.begin(), kMagic.end());
  put(out, kFormatVersion);
  put(out, static_cast<uint32_t>(sections_.size()));
  for (std::size_t s = 0; s < sections_.size(); ++s) {
    put(out, static_cast<uint32_t>(names_[s].first.size()));
    out.insert(out.end(), names_[s].first.begin(), names_[s].first.end());
    put(out, names_[s].second);
    const std::vector<char>& payload = sections_[s].bytes();
    put(out, static_cast<uint64_t>(payload.size()));
    out.insert(out.end(), payload.begin(), payload.end());
  }
  put(out, fnv1a64(out.data(), out.size()));
  return out;
}

void StateWriter::write_file(const std::filesystem::path& path) const {
  const std::vector<char> data = bytes();
  std::filesystem::path tmp = path;
  tmp += ".tmp";
  auto fail = [&](const std::string& what) {
    const std::string reason = std::strerror(errno);
    std::error_code ec;
    std::filesystem::remove(tmp, ec);
    throw SetupError("cannot write the checkpoint " + path.string() + ": " + what + ": " + reason);
  };
  // POSIX I/O so the data can be fsync'ed before the rename: after a crash the file is the old or the new
  // checkpoint, never a torn one.
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) fail("open");
  std::size_t done = 0;
  while (done < data.size()) {
    const ssize_t n = ::write(fd, data.data() + done, data.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      ::close(fd);
      fail("write");
    }
    done += static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0) {
    ::close(fd);
    fail("fsync");
  }
  if (::close(fd) != 0) fail("close");
  if (std::rename(tmp.c_str(), path.c_str()) != 0) fail("rename");
}

StateReader StateReader::from_file(const std::filesystem::path& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw SetupError(path.string() + ": no checkpoint (cannot open)");
  std::vector<char> bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  if (f.bad()) throw SetupError(path.string() + ": read error");
  return StateReader(std::move(bytes), path.string());
}

StateReader::StateReader(std::vector<char> bytes, const std::string& what)
    : what_(what), bytes_(std::move(bytes)) {
  auto corrupt = [&](const std::string& why) {
    throw SetupError(what_ + ": not a valid checkpoint: " + why);
  };
  if (bytes_.size() < kMagicSize + 8 + 8 || std::memcmp(bytes_.data(), kMagic.data(), kMagicSize) != 0)
    corrupt("no aortasph checkpoint header");
  uint64_t stored = 0;
  std::memcpy(&stored, bytes_.data() + bytes_.size() - 8, 8);
  if (stored != fnv1a64(bytes_.data(), bytes_.size() - 8))
    corrupt("checksum mismatch (truncated or damaged)");
  const std::size_t end = bytes_.size() - 8;
  std::size_t pos = kMagicSize;
  auto take = [&](void* p, std::size_t n) {
    if (n > end - pos) corrupt("truncated section table");
    std::memcpy(p, bytes_.data() + pos, n);
    pos += n;
  };
  uint32_t format = 0, count = 0;
  take(&format, 4);
  if (format != kFormatVersion)
    corrupt("format version " + std::to_string(format) + ", this program reads version " +
            std::to_string(kFormatVersion));
  take(&count, 4);
  for (uint32_t s = 0; s < count; ++s) {
    uint32_t name_size = 0;
    take(&name_size, 4);
    if (name_size > end - pos) corrupt("truncated section name");
    std::string name(bytes_.data() + pos, name_size);
    pos += name_size;
    Entry e{};
    uint64_t size = 0;
    take(&e.version, 4);
    take(&size, 8);
    if (size > end - pos) corrupt("section '" + name + "' runs past the end of the file");
    e.offset = pos;
    e.size = static_cast<std::size_t>(size);
    pos += e.size;
    sections_[name] = e;
  }
  if (pos != end) corrupt("trailing bytes after the last section");
}

SectionReader StateReader::section(const std::string& name) const {
  const auto it = sections_.find(name);
  if (it == sections_.end())
    throw SetupError(what_ + ": the checkpoint has no section '" + name +
                     "' (written by a version without it)");
  return SectionReader(name, it->second.version, bytes_.data() + it->second.offset, it->second.size);
}

}  // namespace aortasph
