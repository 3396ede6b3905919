// Reader of the CCD query files (Tight-Inclusion benchmark format) and exact
// rational -> double conversion. See gauss6/io/ccd_queries.h.
#include "gauss6/io/ccd_queries.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace gauss6 {
namespace {

using u128 = unsigned __int128;

std::string trim(const std::string& s) {
  const auto first = s.find_first_not_of(" \t\r");
  if (first == std::string::npos) return {};
  const auto last = s.find_last_not_of(" \t\r");
  return s.substr(first, last - first + 1);
}

// Canonical decimal integer: optional '-', no leading zeros, "0" for zero.
// Returns false if s is not an integer.
bool canonical_integer(const std::string& s, std::string* out) {
  size_t i = 0;
  bool negative = false;
  if (i < s.size() && (s[i] == '-' || s[i] == '+')) negative = s[i++] == '-';
  if (i == s.size()) return false;
  for (size_t k = i; k < s.size(); ++k)
    if (s[k] < '0' || s[k] > '9') return false;
  while (i + 1 < s.size() && s[i] == '0') ++i;
  const std::string digits = s.substr(i);
  *out = (negative && digits != "0") ? "-" + digits : digits;
  return true;
}

std::string negate(const std::string& canonical) {
  if (canonical == "0") return canonical;
  return canonical[0] == '-' ? canonical.substr(1) : "-" + canonical;
}

[[noreturn]] void fail(const std::string& path, int line, const std::string& what) {
  throw CcdQueryFileError(path, line, /*key=*/"", what);
}

// |value| of a canonical decimal integer as u128; throws beyond 127 bits.
u128 parse_magnitude(const std::string& s, bool* negative) {
  *negative = !s.empty() && s[0] == '-';
  u128 v = 0;
  const u128 limit = (~u128(0)) >> 1;  // 2^127 - 1
  for (size_t k = *negative ? 1 : 0; k < s.size(); ++k) {
    const unsigned digit = unsigned(s[k] - '0');
    if (v > (limit - digit) / 10) throw std::out_of_range("to_double: integer beyond 127 bits: " + s);
    v = v * 10 + digit;
  }
  return v;
}

u128 gcd(u128 a, u128 b) {
  while (b != 0) {
    const u128 t = a % b;
    a = b;
    b = t;
  }
  return a;
}

int bit_length(u128 v) {
  int n = 0;
  while (v != 0) {
    v >>= 1;
    ++n;
  }
  return n;
}

}  // namespace

std::vector<CcdQuery> read_ccd_queries(const std::string& path, CcdQuery::Kind kind) {
  std::ifstream in(path);
  if (!in) throw CcdQueryFileError(path, "cannot open");
  std::vector<CcdQuery> queries;
  CcdQuery current;
  current.kind = kind;
  int row = 0;  // rows of the current query read so far
  int line_number = 0;
  std::string line;
  while (std::getline(in, line)) {
    ++line_number;
    line = trim(line);
    if (line.empty()) continue;
    // Split into the 7 columns.
    std::vector<std::string> fields;
    size_t start = 0;
    while (true) {
      const size_t comma = line.find(',', start);
      fields.push_back(trim(line.substr(start, comma == std::string::npos ? std::string::npos : comma - start)));
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
    if (fields.size() != 7)
      fail(path, line_number, "expected 7 columns, found " + std::to_string(fields.size()));
    std::array<std::string, 7> value;
    for (int c = 0; c < 7; ++c)
      if (!canonical_integer(fields[c], &value[c]))
        fail(path, line_number, "column " + std::to_string(c + 1) + " is not an integer: '" + fields[c] + "'");
    if (value[6] != "0" && value[6] != "1")
      fail(path, line_number, "ground truth must be 0 or 1, found " + value[6]);
    const bool truth = value[6] == "1";
    if (row == 0) {
      current.expected = truth;
      current.line = line_number;
    } else if (truth != current.expected) {
      fail(path, line_number, "ground truth differs from the query's first row (line " +
                                  std::to_string(current.line) + ")");
    }
    RationalPoint& p = current.points[row];
    for (int c = 0; c < 3; ++c) {
      std::string num = value[2 * c], den = value[2 * c + 1];
      if (den == "0") fail(path, line_number, "zero denominator in column " + std::to_string(2 * c + 2));
      if (den[0] == '-') {  // keep the sign on the numerator
        den = negate(den);
        num = negate(num);
      }
      // to_double() reads integers of up to 127 bits: refuse wider ones here, by line.
      for (const std::string* v : {&num, &den})
        if (v->size() - ((*v)[0] == '-') > 38 ||
            (v->size() - ((*v)[0] == '-') == 38 && v->substr((*v)[0] == '-') > "170141183460469231731687303715884105727"))
          fail(path, line_number, "column " + std::to_string(2 * c + (v == &num ? 1 : 2)) +
                                      ": integer wider than 127 bits");
      p.xyz[c] = {num, den};
    }
    if (++row == 8) {
      queries.push_back(current);
      row = 0;
    }
  }
  if (row != 0)
    fail(path, line_number, "the number of rows is not a multiple of 8 (last query has " +
                                std::to_string(row) + " rows)");
  return queries;
}

std::vector<CcdQueryFile> list_ccd_query_files(const std::string& root) {
  namespace fs = std::filesystem;
  if (!fs::is_directory(root)) throw CcdQueryFileError(root, "not a directory");
  std::vector<CcdQueryFile> files;
  for (const auto& entry : fs::recursive_directory_iterator(root)) {
    if (!entry.is_regular_file() || entry.path().extension() != ".csv") continue;
    const std::string folder = entry.path().parent_path().filename().string();
    if (folder == "vertex-face") files.push_back({entry.path().string(), CcdQuery::kVertexFace});
    if (folder == "edge-edge") files.push_back({entry.path().string(), CcdQuery::kEdgeEdge});
  }
  std::sort(files.begin(), files.end(),
            [](const CcdQueryFile& a, const CcdQueryFile& b) { return a.path < b.path; });
  return files;
}

double to_double(const Rational& r, bool* exact) {
  bool num_negative = false, den_negative = false;
  u128 n = parse_magnitude(r.num, &num_negative);
  u128 d = parse_magnitude(r.den, &den_negative);
  if (d == 0) throw std::domain_error("to_double: zero denominator");
  if (n == 0) {
    if (exact) *exact = true;
    return 0.0;
  }
  const u128 g = gcd(n, d);
  n /= g;
  d /= g;
  // Binary long division: m = the 64 leading bits of n/d, value = (m + rest) 2^e,
  // sticky = whether rest != 0.
  u128 q = n / d, rem = n % d;
  uint64_t m = 0;
  int e = 0;
  bool sticky = false;
  if (bit_length(q) > 64) {
    const int shift = bit_length(q) - 64;
    m = uint64_t(q >> shift);
    sticky = (q & ((u128(1) << shift) - 1)) != 0 || rem != 0;
    e = shift;
  } else {
    m = uint64_t(q);
    while (m < (uint64_t(1) << 63)) {  // next quotient bit; rem < d < 2^127 so 2 rem fits
      rem <<= 1;
      const bool bit = rem >= d;
      if (bit) rem -= d;
      m = (m << 1) | uint64_t(bit);
      --e;
    }
    sticky = rem != 0;
  }
  // Round the 64-bit m to 53 bits, to nearest, ties to even.
  const uint64_t low = m & 0x7FF, half = 0x400;
  uint64_t m53 = m >> 11;
  if (low > half || (low == half && (sticky || (m53 & 1)))) ++m53;
  if (exact) *exact = low == 0 && !sticky;
  const double magnitude = std::ldexp(double(m53), e + 11);
  return (num_negative != den_negative) ? -magnitude : magnitude;
}

std::array<double, 3> to_double(const RationalPoint& p, bool* exact) {
  std::array<double, 3> out;
  bool all_exact = true;
  for (int c = 0; c < 3; ++c) {
    bool e = false;
    out[c] = to_double(p.xyz[c], &e);
    all_exact = all_exact && e;
  }
  if (exact) *exact = all_exact;
  return out;
}

}  // namespace gauss6
