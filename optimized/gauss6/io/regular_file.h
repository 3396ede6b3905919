// Load time: what a path is, checked before a reader opens it, so that a FIFO (a hang) or a device
// (/dev/zero: read until memory runs out) is never read as a scene, a hand script or a height map.
// Header-only (the harness uses it too).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <system_error>

namespace gauss6 {

// "" when path is a regular file (symbolic links followed) of at most max_bytes bytes, else the
// problem ("the file is a FIFO, not a regular file").
inline std::string regular_file_problem(const std::string& path, std::uintmax_t max_bytes) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (ec || !fs::exists(st)) return "no such file";
  if (!fs::is_regular_file(st)) {
    const char* kind = fs::is_directory(st)        ? "a directory"
                       : fs::is_fifo(st)           ? "a FIFO"
                       : fs::is_character_file(st) ? "a character device"
                       : fs::is_block_file(st)     ? "a block device"
                       : fs::is_socket(st)         ? "a socket"
                                                   : "not a regular file";
    return std::string("the file is ") + kind + ", not a regular file";
  }
  const std::uintmax_t size = fs::file_size(path, ec);
  if (!ec && size > max_bytes)
    return "the file has " + std::to_string(size) + " bytes, more than the " + std::to_string(max_bytes) +
           " this kind of file may have";
  return "";
}

}  // namespace gauss6
