#include "core/atomic_file.h"

#include <fstream>
#include <string>
#include <system_error>
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
    fs::remove(temporary, error);
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
    std::ofstream file(temporary, std::ios::binary);
    file.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    file.close();
    if (!file) throw BadInputError("cannot write " + path.string());
  });
}

std::string ReadFileBytes(const fs::path& path) {
  // A folder opens as a stream but throws on reading (found by fuzzing: an OBJ whose mtllib
  // names a folder).
  std::error_code error;
  if (fs::is_directory(path, error)) throw BadInputError(path.string() + " is a folder, not a file");
  std::ifstream file(path, std::ios::binary);
  if (!file) throw BadInputError("cannot open " + path.string());
  std::string bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  if (file.bad()) throw BadInputError("cannot read " + path.string());
  return bytes;
}

}  // namespace parallax
