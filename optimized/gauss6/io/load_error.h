// Load-time errors: one exception hierarchy for every file the library reads
// (scenes, mesh files, CCD query files, projection-instance files). Each error
// carries the file, the line (and column) where the format has lines, and the
// key or field where it has keys, and what() says them in one format:
//   FILE:LINE:COLUMN: KEY: problem
// with the parts that do not apply left out ("box.obj: the file is empty",
// "vf.csv:12: zero denominator in column 4", "scene.toml:14:1: gains.kh: must be > 0").
// Thrown at load time only, never from a real-time loop. The Python bindings turn
// every LoadError into gauss6.LoadError (a ValueError) with the same message.
// Header-only: the exact reference compiles the CCD query reader on its own.
#pragma once

#include <stdexcept>
#include <string>
#include <utility>

namespace gauss6 {

class LoadError : public std::runtime_error {
 public:
  // line and column are 1-based, 0 when none applies; key is empty when none applies.
  LoadError(std::string file, int line, std::string key, std::string problem, int column = 0)
      : std::runtime_error(format(file, line, key, problem, column)),
        file_(std::move(file)),
        line_(line),
        column_(column),
        key_(std::move(key)),
        problem_(std::move(problem)) {}
  // An error about a whole file: "FILE: problem".
  LoadError(std::string file, std::string problem) : LoadError(std::move(file), 0, {}, std::move(problem)) {}

  const std::string& file() const noexcept { return file_; }
  int line() const noexcept { return line_; }
  int column() const noexcept { return column_; }
  const std::string& key() const noexcept { return key_; }
  const std::string& problem() const noexcept { return problem_; }

  // The what() text of an error with these parts.
  static std::string format(const std::string& file, int line, const std::string& key, const std::string& problem,
                            int column = 0) {
    std::string s = file;
    if (line > 0) s += ":" + std::to_string(line);
    if (line > 0 && column > 0) s += ":" + std::to_string(column);
    s += ": ";
    if (!key.empty()) s += key + ": ";
    return s + problem;
  }

 private:
  std::string file_;
  int line_ = 0;
  int column_ = 0;
  std::string key_;
  std::string problem_;
};

// One subclass per reader, so that a caller can tell which kind of file failed.
class SceneError : public LoadError {         // scene.h (TOML): file, line, column, dotted key
 public:
  using LoadError::LoadError;
};
class MeshFileError : public LoadError {      // mesh_io.h (OBJ, OFF, PLY, STL): file only
 public:
  using LoadError::LoadError;
};
class CcdQueryFileError : public LoadError {  // ccd_queries.h (CSV): file and line
 public:
  using LoadError::LoadError;
};
class QpInstanceError : public LoadError {    // qp_instances.h (JSON): file, line of a syntax error, key
 public:
  using LoadError::LoadError;
};

}  // namespace gauss6
