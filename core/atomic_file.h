#pragma once
// Writes that never leave a half-written file under the final name: write to a temporary
// name beside the target, then rename (atomic within one file system). Folders are built under
// a scratch name and swapped in the same way (ReplaceFolder).
#include <filesystem>
#include <functional>
#include <string_view>

namespace parallax {

// Calls `write(temporary_path)`, then renames the temporary file to `path`. Creates the parent
// folder. If `write` throws, the temporary file is removed and the exception propagates; an
// existing file at `path` is left untouched. Throws BadInputError if the folder is not
// writable, or, naming `path` and DiskFullReason, if `write` failed on a full disk.
void WriteAtomically(const std::filesystem::path& path,
                     const std::function<void(const std::filesystem::path&)>& write);

// Writes `bytes` to `path` atomically.
void WriteFileAtomically(const std::filesystem::path& path, std::string_view bytes);

// "No space left on device (N KiB free on the file system of `path`)" when that file system
// has under 1 MiB left, else "": what a failed write by a library or a tool (whose own
// message may name only a temporary file, or none) most likely ran into.
std::string DiskFullReason(const std::filesystem::path& path);

// Removes `path` (a file or a folder with everything in it); nothing to do when it does not
// exist. Throws BadInputError naming `path` if it cannot be removed.
void RemoveAll(const std::filesystem::path& path);

// Moves the folder (or file) `scratch` to `path`, replacing what was there, so that the old
// one is never lost before the new one is in place: the old is renamed aside (a hidden
// ".<name>.trash" beside it), `scratch` renamed to `path`, then the old removed. Where the
// second rename fails the old is put back. A trash folder left by a run stopped between the
// renames is removed first. Throws BadInputError naming the paths if a rename or a removal
// fails.
void ReplaceFolder(const std::filesystem::path& scratch, const std::filesystem::path& path);

// Whole file as bytes; throws BadInputError naming the file if it cannot be read.
std::string ReadFileBytes(const std::filesystem::path& path);

}  // namespace parallax
