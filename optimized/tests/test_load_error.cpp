// Tests of the load-time error hierarchy (load_error.h): one message format,
// the parts kept apart for callers, and every reader's error caught as a LoadError.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include "gauss6/io/ccd_queries.h"
#include "gauss6/io/load_error.h"
#include "gauss6/io/mesh_io.h"
#include "gauss6/io/qp_instances.h"
#include "gauss6/io/scene.h"

using namespace gauss6;
namespace fs = std::filesystem;

TEST_CASE("load errors say FILE:LINE:COLUMN: KEY: problem, leaving out what does not apply", "[load_error]") {
  CHECK(std::string(LoadError("a.toml", 14, "gains.kh", "must be > 0", 3).what()) == "a.toml:14:3: gains.kh: must be > 0");
  CHECK(std::string(LoadError("a.csv", 12, "", "zero denominator").what()) == "a.csv:12: zero denominator");
  CHECK(std::string(LoadError("a.json", 0, "instances[2].M", "is not an array").what()) ==
        "a.json: instances[2].M: is not an array");
  CHECK(std::string(LoadError("a.obj", "the file is empty").what()) == "a.obj: the file is empty");
  const SceneError e("s.toml", 7, "device.kind", "must be \"simulated\"", 1);
  CHECK(e.file() == "s.toml");
  CHECK(e.line() == 7);
  CHECK(e.column() == 1);
  CHECK(e.key() == "device.kind");
  CHECK(e.problem() == "must be \"simulated\"");
}

TEST_CASE("every reader's errors are LoadErrors naming the file", "[load_error]") {
  const fs::path dir = fs::temp_directory_path() / ("gauss6_load_error_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream((dir / name).string()) << text;
    return (dir / name).string();
  };
  auto error_of = [](auto&& read) -> std::string {
    try {
      read();
    } catch (const LoadError& e) {
      return e.what();
    }
    return "no LoadError";
  };
  const std::string csv = write("q.csv", "0,0,1,1,0,1,1\n");
  CHECK(error_of([&] { read_ccd_queries(csv, CcdQuery::kVertexFace); }) == csv + ":1: zero denominator in column 2");
  const std::string obj = write("empty.obj", "");
  CHECK(error_of([&] { read_mesh(obj); }) == obj + ": the file is empty");
  const std::string json = write("bad.json", "{\n\"format\": ");
  CHECK_THAT(error_of([&] { read_qp_instances(json); }), Catch::StartsWith(json + ":2: not valid JSON"));
  const std::string toml = write("s.toml", "format = \"gauss6-scene\"\nversion = 1\nname = \"x\"\nbogus = 1\n");
  CHECK_THAT(error_of([&] { load_scene(toml); }), Catch::StartsWith(toml + ":4:1: bogus: unknown key"));
  std::error_code ignored;
  fs::remove_all(dir, ignored);
}
