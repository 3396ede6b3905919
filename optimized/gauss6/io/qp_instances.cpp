// The projection-instance reader (qp_instances.h) with nlohmann::json. Every error
// is a QpInstanceError naming the file, the key (with the instance's index and id)
// or, for a syntax error, the line.
#include "gauss6/io/qp_instances.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

namespace gauss6 {

namespace {

using nlohmann::json;

constexpr const char* kFormat = "gauss6-qp-instances";
constexpr int kVersion = 1;

// Where a value sits, for error messages "<path>: instances[<i>].<key>: <what> (id <id>)".
struct Where {
  const std::string& path;
  std::string instance;  // "instances[<i>]" inside an instance, empty at the top level
  std::string id;        // the instance's id once read

  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    const std::string at = instance.empty() ? key : key.empty() ? instance : instance + "." + key;
    throw QpInstanceError(path, /*line=*/0, at, id.empty() ? what : what + " (id " + id + ")");
  }

  const json& member(const json& obj, const char* key) const {
    auto it = obj.find(key);
    if (it == obj.end()) fail(key, "missing");
    return *it;
  }

  double number(const json& v, const std::string& key) const {
    if (!v.is_number()) fail(key, "is not a number");
    const double x = v.get<double>();
    if (!std::isfinite(x)) fail(key, "is not finite");
    return x;
  }

  // A JSON array of exactly n numbers (n < 0: any length) into out.
  Eigen::VectorXd vector(const json& v, const std::string& key, Eigen::Index n) const {
    if (!v.is_array()) fail(key, "is not an array");
    if (n >= 0 && static_cast<Eigen::Index>(v.size()) != n) {
      fail(key, "has " + std::to_string(v.size()) + " entries, expected " + std::to_string(n));
    }
    Eigen::VectorXd out(static_cast<Eigen::Index>(v.size()));
    for (std::size_t i = 0; i < v.size(); ++i) {
      out[static_cast<Eigen::Index>(i)] = number(v[i], key + "[" + std::to_string(i) + "]");
    }
    return out;
  }

  // A JSON array of rows of 6 numbers each; rows < 0: any number of rows.
  Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor> rows6(const json& v, const std::string& key,
                                                                   Eigen::Index rows) const {
    if (!v.is_array()) fail(key, "is not an array");
    if (rows >= 0 && static_cast<Eigen::Index>(v.size()) != rows) {
      fail(key, "has " + std::to_string(v.size()) + " rows, expected " + std::to_string(rows));
    }
    Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor> out(static_cast<Eigen::Index>(v.size()), 6);
    for (std::size_t r = 0; r < v.size(); ++r) {
      out.row(static_cast<Eigen::Index>(r)) = vector(v[r], key + "[" + std::to_string(r) + "]", 6).transpose();
    }
    return out;
  }

  int integer(const json& v, const std::string& key) const {
    if (!v.is_number_integer()) fail(key, "is not an integer");
    // Read as 64 bits and range-checked: get<int>() would narrow 4294967297 to 1.
    if (v.is_number_unsigned() ? v.get<uint64_t>() > static_cast<uint64_t>(INT32_MAX)
                               : (v.get<int64_t>() < INT32_MIN || v.get<int64_t>() > INT32_MAX))
      fail(key, "is out of the range of a 32-bit integer");
    return static_cast<int>(v.get<int64_t>());
  }

  std::string string(const json& v, const std::string& key) const {
    if (!v.is_string()) fail(key, "is not a string");
    return v.get<std::string>();
  }
};

// The 1-based line of a byte offset of text (JSON syntax errors report bytes).
int line_of(const std::string& text, std::size_t byte) {
  const std::size_t end = std::min(byte, text.size());
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(end), '\n'));
}

QpInstance parse_instance(const Where& file, const json& rec, std::size_t index) {
  Where at{file.path, "instances[" + std::to_string(index) + "]", {}};
  if (!rec.is_object()) at.fail("", "is not an object");
  QpInstance q;
  q.id = at.string(at.member(rec, "id"), "id");
  at.id = q.id;

  const auto M = at.rows6(at.member(rec, "M"), "M", 6);
  q.M = M;
  q.au = at.vector(at.member(rec, "au"), "au", 6);
  q.J = at.rows6(at.member(rec, "J"), "J", -1);
  q.b = at.vector(at.member(rec, "b"), "b", q.J.rows());
  q.push = at.string(at.member(rec, "push"), "push");
  if (q.push != "all" && q.push != "some" && q.push != "none") {
    at.fail("push", "'" + q.push + "' is not one of all, some, none");
  }
  q.sequence = at.integer(at.member(rec, "sequence"), "sequence");
  q.step = at.integer(at.member(rec, "step"), "step");
  return q;
}

}  // namespace

std::vector<QpInstance> read_qp_instances(const std::string& path) {
  const Where file{path, {}, {}};
  std::ifstream in(path, std::ios::binary);
  if (!in) file.fail("", "cannot open the file");
  std::stringstream text;
  text << in.rdbuf();

  const std::string content = text.str();
  json doc;
  try {
    doc = json::parse(content);
  } catch (const json::parse_error& e) {
    throw QpInstanceError(path, line_of(content, e.byte), /*key=*/"", std::string("not valid JSON: ") + e.what());
  } catch (const json::exception& e) {  // e.g. out_of_range 406: a number beyond a double
    throw QpInstanceError(path, /*line=*/0, /*key=*/"", std::string("not valid JSON: ") + e.what());
  }
  if (!doc.is_object()) file.fail("", "the top level is not a JSON object");
  const json& format = file.member(doc, "format");
  if (!format.is_string() || format.get<std::string>() != kFormat) {
    file.fail("format", std::string("is not \"") + kFormat + "\"");
  }
  const json& version = file.member(doc, "version");
  if (!version.is_number_integer() || version.get<long long>() != kVersion) {
    file.fail("version", "is " + version.dump() + ", this reader knows " + std::to_string(kVersion));
  }
  const json& instances = file.member(doc, "instances");
  if (!instances.is_array()) file.fail("instances", "is not an array");

  std::vector<QpInstance> out;
  out.reserve(instances.size());
  for (std::size_t i = 0; i < instances.size(); ++i) out.push_back(parse_instance(file, instances[i], i));
  return out;
}

}  // namespace gauss6
