#include "core/atomic_file.h"

#include <fstream>
#include <sstream>
#include <string>
#include <system_error>
#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include "core/error.h"
#include "core/interrupt.h"

namespace parallax {
namespace fs = std::filesystem;

namespace {

// Beside the target (same file system, so rename is atomic) and unique per process.
fs::path TemporaryPathFor(const fs::path& path) {
  std::string name = ".";
  name += path.filename().string();
  name += ".tmp";
  name += std::to_string(::getpid());
  return path.parent_path() / name;
}

}  // namespace

void WriteAtomically(const fs::path& path, const std::function<void(const fs::path&)>& write) {
  std::error_code error;
  if (!path.parent_path().empty()) {
    fs::create_directories(path.parent_path(), error);
    if (error) {
      throw BadInputError("cannot create folder " + path.parent_path().string() + ": " +
                          error.message());
    }
  }
  const fs::path temporary = TemporaryPathFor(path);
  const TemporaryOutput guard(temporary);
  try {
    write(temporary);
  } catch (...) {
    // Checked before the partial file is removed, which frees its space.
    const std::string disk_full = DiskFullReason(path.parent_path());
    fs::remove(temporary, error);
    if (!disk_full.empty()) throw BadInputError("cannot write " + path.string() + ": " + disk_full);
    throw;
  }
  fs::rename(temporary, path, error);
  if (error) {
    fs::remove(temporary, error);
    throw BadInputError("cannot write " + path.string() + ": " + error.message());
  }
}

void WriteFileAtomically(const fs::path& path, std::string_view bytes) {
  WriteAtomically(path, [&](const fs::path& temporary) {
    // POSIX calls rather than a stream: their errno names the problem ("No space left on
    // device"), which a stream does not promise to keep.
    const auto fail = [&] { throw BadInputError("cannot write " + path.string() + ": " + std::strerror(errno)); };
    const int file = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (file < 0) fail();
    size_t written = 0;
    while (written < bytes.size()) {
      const ssize_t count = ::write(file, bytes.data() + written, bytes.size() - written);
      if (count < 0 && errno == EINTR) continue;
      if (count < 0) {
        const int error = errno;
        ::close(file);
        errno = error;
        fail();
      }
      written += static_cast<size_t>(count);
    }
    if (::close(file) != 0) fail();
  });
}

std::string DiskFullReason(const fs::path& path) {
  struct statvfs disk{};
  const fs::path existing = path.empty() ? fs::path(".") : path;
  if (::statvfs(existing.c_str(), &disk) != 0) return "";
  const double free_bytes = static_cast<double>(disk.f_bavail) * static_cast<double>(disk.f_frsize);
  if (free_bytes >= 1024.0 * 1024.0) return "";
  return "No space left on device (" + std::to_string(static_cast<long long>(free_bytes / 1024)) +
         " KiB free on the file system of " + existing.string() + ")";
}

void RemoveAll(const fs::path& path) {
  std::error_code error;
  fs::remove_all(path, error);
  if (error) throw BadInputError("cannot remove " + path.string() + ": " + error.message());
}

void ReplaceFolder(const fs::path& scratch, const fs::path& path) {
  // Built by appending, as TemporaryPathFor: GCC 12 warns (-Wrestrict) on "." + string.
  std::string trash_name = ".";
  trash_name += path.filename().string();
  trash_name += ".trash";
  const fs::path trash = path.parent_path() / trash_name;
  RemoveAll(trash);
  std::error_code error;
  const bool had_old = fs::exists(fs::symlink_status(path, error));
  if (had_old) {
    fs::rename(path, trash, error);
    if (error) throw BadInputError("cannot move " + path.string() + " aside: " + error.message());
  }
  fs::rename(scratch, path, error);
  if (error) {
    const std::string message = "cannot move " + scratch.string() + " to " + path.string() + ": " + error.message();
    std::error_code restore_error;
    if (had_old) fs::rename(trash, path, restore_error);
    throw BadInputError(message);
  }
  // Only the old one is left to remove: an interrupted run may remove it too.
  const TemporaryOutput old(trash);
  RemoveAll(trash);
}

std::string ReadFileBytes(const fs::path& path) {
  // A folder opens as a stream but throws on reading (found by fuzzing: an OBJ whose mtllib
  // names a folder).
  std::error_code error;
  if (fs::is_directory(path, error)) throw BadInputError(path.string() + " is a folder, not a file");
  std::ifstream file(path, std::ios::binary);
  if (!file) throw BadInputError("cannot open " + path.string());
  // Whole buffers at a time: an istreambuf_iterator copies byte by byte, ~10x slower.
  std::ostringstream bytes;
  bytes << file.rdbuf();
  if (file.bad()) throw BadInputError("cannot read " + path.string());
  return std::move(bytes).str();
}

}  // namespace parallax
