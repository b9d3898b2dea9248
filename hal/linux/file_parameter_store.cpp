#include "hal/linux/file_parameter_store.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <optional>
#include <vector>

#include "hal/storage/stored_slot.hpp"

namespace imd::hal {
namespace {

std::optional<std::vector<uint8_t>> read_file(const std::string& path, std::string& error) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    error = path + ": " + std::strerror(errno);
    return std::nullopt;
  }
  std::vector<uint8_t> bytes;
  uint8_t chunk[4096];
  for (;;) {
    const ssize_t n = ::read(fd, chunk, sizeof chunk);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      error = path + ": " + std::strerror(errno);
      ::close(fd);
      return std::nullopt;
    }
    if (n == 0) break;
    bytes.insert(bytes.end(), chunk, chunk + n);
    if (bytes.size() > 1u << 20) break;  // not a record file
  }
  ::close(fd);
  return bytes;
}

bool write_all(int fd, std::span<const uint8_t> bytes) {
  while (!bytes.empty()) {
    const ssize_t n = ::write(fd, bytes.data(), bytes.size());
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    bytes = bytes.subspan(static_cast<std::size_t>(n));
  }
  return true;
}

std::string directory_of(const std::string& path) {
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? "." : (slash == 0 ? "/" : path.substr(0, slash));
}

}  // namespace

std::size_t FileParameterStore::load(std::span<uint8_t> out) noexcept {
  error_.clear();
  const auto bytes = read_file(path_, error_);
  if (!bytes) return 0;
  const auto slot = decode_slot(*bytes);
  if (!slot) {
    error_ = path_ + ": not a whole parameter record (bad magic, length, CRC or commit word)";
    return 0;
  }
  if (slot->data.size() > out.size()) {
    error_ = path_ + ": record larger than this firmware's";
    return 0;
  }
  std::memcpy(out.data(), slot->data.data(), slot->data.size());
  return slot->data.size();
}

bool FileParameterStore::save(std::span<const uint8_t> record) noexcept {
  error_.clear();
  uint32_t sequence = 1;
  std::string ignored;
  if (const auto old = read_file(path_, ignored)) {
    if (const auto slot = decode_slot(*old)) sequence = slot->sequence + 1;
  }
  std::vector<uint8_t> copy(slot_bytes(record.size()));
  const std::size_t body = encode_slot_body(sequence, record, copy);
  const auto commit = slot_commit_unit();
  std::memcpy(copy.data() + body, commit.data(), commit.size());

  const std::string tmp = path_ + ".tmp";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) {
    error_ = tmp + ": " + std::strerror(errno);
    return false;
  }
  const bool written = body != 0 && write_all(fd, copy) && ::fsync(fd) == 0;
  const int saved_errno = errno;
  ::close(fd);
  if (!written) {
    error_ = tmp + ": write failed: " + std::strerror(saved_errno);
    ::unlink(tmp.c_str());
    return false;
  }
  if (::rename(tmp.c_str(), path_.c_str()) != 0) {
    error_ = path_ + ": rename failed: " + std::strerror(errno);
    ::unlink(tmp.c_str());
    return false;
  }
  // The rename is durable once the directory entry is on the disk.
  const int dir = ::open(directory_of(path_).c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir >= 0) {
    ::fsync(dir);
    ::close(dir);
  }
  return true;
}

}  // namespace imd::hal
