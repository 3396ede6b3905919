// Tests of the projection-instance reader (qp_instances.h) on the committed families of
// datasets_generated/qp/: sizes, symmetric positive definite M, finite rows, true push
// labels; bit-exact reading of 17-digit doubles; malformed files rejected by name.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string>

#include <unistd.h>

#include <Eigen/Cholesky>

#include "gauss6/io/qp_instances.h"

using namespace gauss6;
namespace fs = std::filesystem;

namespace {

const fs::path kQpDir = fs::path(GAUSS6_SOURCE_DIR) / "datasets_generated" / "qp";

// Family -> number of instances, as documented in datasets_generated/qp/README.md.
const std::map<std::string, std::size_t> kFamilySizes = {
    {"box", 300},       {"peg", 300},     {"bunny", 300},   {"m50", 80},
    {"redundant", 240}, {"inertia", 200}, {"offsets", 200}, {"warm", 1000}};

// A fresh directory for this test's files, removed at scope exit.
struct TempDir {
  fs::path path;
  TempDir() {
    path = fs::temp_directory_path() / ("gauss6_qpdata_" + std::to_string(::getpid()));
    fs::create_directories(path);
  }
  ~TempDir() { fs::remove_all(path); }
  std::string write(const std::string& name, const std::string& text) const {
    const fs::path p = path / name;
    std::ofstream(p, std::ios::binary) << text;
    return p.string();
  }
};

// One instance record with the given fields spliced in (defaults: a valid 1-row instance).
std::string instance(const std::string& M = "[[2,0,0,0,0,0],[0,2,0,0,0,0],[0,0,2,0,0,0],"
                                            "[0,0,0,1,0,0],[0,0,0,0,1,0],[0,0,0,0,0,1]]",
                     const std::string& au = "[0,0,-1e-3,0,0,0]", const std::string& J = "[[0,0,1,0,0,0]]",
                     const std::string& b = "[0.0]", const std::string& push = "\"all\"") {
  return R"({"id":"t-0","M":)" + M + R"(,"au":)" + au + R"(,"J":)" + J + R"(,"b":)" + b +
         R"(,"push":)" + push + R"(,"sequence":-1,"step":-1})";
}

std::string family_file(const std::string& instances, const std::string& format = "\"gauss6-qp-instances\"",
                        const std::string& version = "1") {
  return R"({"format":)" + format + R"(,"version":)" + version + R"(,"family":"t","instances":[)" + instances +
         "]}";
}

}  // namespace

TEST_CASE("every committed family reads with consistent, valid instances", "[qpdata]") {
  for (const auto& [family, size] : kFamilySizes) {
    const fs::path path = kQpDir / (family + ".json");
    INFO(path.string());
    REQUIRE(fs::exists(path));
    const auto instances = read_qp_instances(path.string());
    CHECK(instances.size() == size);

    std::set<std::string> ids;
    for (const QpInstance& q : instances) {
      INFO(q.id);
      CHECK(ids.insert(q.id).second);
      REQUIRE(q.b.size() == q.J.rows());
      // The generator writes M exactly symmetric (it averages R I R^T with its transpose).
      CHECK(q.M == q.M.transpose());
      CHECK(Eigen::LLT<Mat6>(q.M).info() == Eigen::Success);
      CHECK(q.au.allFinite());
      CHECK(q.J.allFinite());
      CHECK(q.b.allFinite());
      for (Eigen::Index k = 0; k < q.J.rows(); ++k) CHECK(q.J.row(k).norm() > 0);

      // Push labels: the generator keeps every |J_k au| above 1e-9 sum_i |J_ki au_i|, far
      // beyond the rounding of a 6-term dot product (~1e-15), so any summation order agrees.
      const Eigen::VectorXd d = q.J * q.au;
      const Eigen::Index neg = (d.array() < 0).count();
      if (q.push == "all") CHECK(neg == d.size());
      if (q.push == "none") CHECK(neg == 0);
      if (q.push == "some") CHECK((neg > 0 && neg < d.size()));

      if (family == "warm") {
        CHECK((q.sequence >= 0 && q.sequence < 20 && q.step >= 0 && q.step < 50));
      } else {
        CHECK((q.sequence == -1 && q.step == -1));
      }
      if (family != "offsets") CHECK(q.b.isZero(0.0));
      if (family == "m50") CHECK(q.J.rows() == 50);
    }
  }
}

TEST_CASE("numbers are read bit-exactly, and an empty J is allowed", "[qpdata]") {
  TempDir dir;
  // 0.1 + 0.2 = 0.30000000000000004: its shortest repr has 17 significant digits, and
  // 0.30000000000000004 != 0.3, so a reader that rounds through 16 digits fails here.
  const double x = 0.1 + 0.2;
  REQUIRE(x != 0.3);
  const std::string path =
      dir.write("exact.json", family_file(instance(
                                  "[[0.30000000000000004,0,0,0,0,0],[0,2,0,0,0,0],[0,0,2,0,0,0],"
                                  "[0,0,0,1,0,0],[0,0,0,0,1,0],[0,0,0,0,0,1]]",
                                  "[1e+23,5e-324,-0.0,0,0,0.30000000000000004]", "[]", "[]", "\"none\"")));
  const auto q = read_qp_instances(path);
  REQUIRE(q.size() == 1);
  CHECK(std::memcmp(&q[0].M(0, 0), &x, sizeof x) == 0);
  CHECK(std::memcmp(&q[0].au[5], &x, sizeof x) == 0);
  CHECK(q[0].au[0] == 1e23);      // the double nearest 10^23 (a classic strtod test)
  CHECK(q[0].au[1] == 5e-324);    // the smallest subnormal
  CHECK(std::signbit(q[0].au[2]));  // -0.0 keeps its sign
  CHECK(q[0].J.rows() == 0);
  CHECK(q[0].b.size() == 0);
}

TEST_CASE("malformed instance files are rejected with the file name", "[qpdata]") {
  TempDir dir;
  const std::map<std::string, std::string> bad = {
      {"not_json.json", "{\"format\": "},
      {"top_level.json", "[1, 2]"},
      {"format.json", family_file(instance(), "\"gauss6-scene\"")},
      {"version.json", family_file(instance(), "\"gauss6-qp-instances\"", "2")},
      {"no_instances.json", R"({"format":"gauss6-qp-instances","version":1})"},
      {"M_rows.json", family_file(instance("[[1,0,0,0,0,0]]"))},
      {"au_size.json", family_file(instance(
                           "[[2,0,0,0,0,0],[0,2,0,0,0,0],[0,0,2,0,0,0],[0,0,0,1,0,0],[0,0,0,0,1,0],[0,0,0,0,0,1]]",
                           "[0,0,-1e-3,0,0]"))},
      {"J_row.json", family_file(instance(
                         "[[2,0,0,0,0,0],[0,2,0,0,0,0],[0,0,2,0,0,0],[0,0,0,1,0,0],[0,0,0,0,1,0],[0,0,0,0,0,1]]",
                         "[0,0,-1e-3,0,0,0]", "[[0,0,1,0,0]]"))},
      {"J_string.json", family_file(instance(
                            "[[2,0,0,0,0,0],[0,2,0,0,0,0],[0,0,2,0,0,0],[0,0,0,1,0,0],[0,0,0,0,1,0],[0,0,0,0,0,1]]",
                            "[0,0,-1e-3,0,0,0]", "[[0,0,\"1\",0,0,0]]"))},
      {"b_size.json", family_file(instance(
                          "[[2,0,0,0,0,0],[0,2,0,0,0,0],[0,0,2,0,0,0],[0,0,0,1,0,0],[0,0,0,0,1,0],[0,0,0,0,0,1]]",
                          "[0,0,-1e-3,0,0,0]", "[[0,0,1,0,0,0]]", "[0.0, 0.0]"))},
      {"push.json", family_file(instance(
                        "[[2,0,0,0,0,0],[0,2,0,0,0,0],[0,0,2,0,0,0],[0,0,0,1,0,0],[0,0,0,0,1,0],[0,0,0,0,0,1]]",
                        "[0,0,-1e-3,0,0,0]", "[[0,0,1,0,0,0]]", "[0.0]", "\"most\""))},
      {"missing_key.json", family_file(R"({"id":"t-0","M":[]})")},
  };
  // Sanity: the defaults make a valid file, so each rejection above is due to its one defect.
  REQUIRE(read_qp_instances(dir.write("valid.json", family_file(instance()))).size() == 1);
  for (const auto& [name, text] : bad) {
    INFO(name);
    const std::string path = dir.write(name, text);
    CHECK_THROWS_WITH(read_qp_instances(path), Catch::Contains(path));
  }
  CHECK_THROWS_WITH(read_qp_instances((dir.path / "absent.json").string()), Catch::Contains("absent.json"));
}
