// Reader of the continuous-collision query files of ../shared/data/ccd-sample-queries
// (the Tight-Inclusion CCD benchmark format), shared by the optimized and the
// exact reference CCD: only the file format is shared, never an algorithm.
//
// Format: CSV, 8 rows per query, 7 integer columns per row:
//   x numerator, x denominator, y num, y den, z num, z den, ground truth (0/1).
// Rows of one query (linear per-vertex motion from t = 0 to t = 1):
//   vertex/face: v_t0, f0_t0, f1_t0, f2_t0, v_t1, f0_t1, f1_t1, f2_t1
//   edge/edge:   a0_t0, a1_t0, b0_t0, b1_t0, a0_t1, a1_t1, b0_t1, b1_t1
// The ground truth is 1 when the primitives touch (distance exactly zero) at
// some t in [0, 1]. Numerators reach 112 bits in the sample data, beyond int64:
// values are kept as decimal strings; to_double() converts them (exactly, when
// the value is a double, which holds for every value of the sample data).
//
// Load-time code: it allocates and throws.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "gauss6/io/load_error.h"

namespace gauss6 {

// The exact rational num/den, both decimal integers without leading '+', with
// den > 0 (the reader normalises the sign onto the numerator).
struct Rational {
  std::string num = "0";
  std::string den = "1";
};

// A point with exact rational coordinates.
struct RationalPoint {
  std::array<Rational, 3> xyz;
};

struct CcdQuery {
  enum Kind { kVertexFace, kEdgeEdge };
  Kind kind = kVertexFace;
  // The 8 rows in file order (see above): points[0..3] at t = 0, points[4..7] at t = 1.
  std::array<RationalPoint, 8> points;
  bool expected = false;  // ground truth: contact at some t in [0, 1]
  int line = 0;           // 1-based line number of the query's first row in its file
};

// Reads one query file. Throws CcdQueryFileError (load_error.h) naming the file and line on:
// a file that cannot be opened, a row without exactly 7 integer columns, a zero
// denominator, a ground truth other than 0/1 or differing within a query, or a
// number of rows that is not a multiple of 8. Empty lines are skipped.
std::vector<CcdQuery> read_ccd_queries(const std::string& path, CcdQuery::Kind kind);

// One query file found under a data root.
struct CcdQueryFile {
  std::string path;
  CcdQuery::Kind kind;
};
// Every *.csv file under root in a directory named "vertex-face" or "edge-edge"
// (recursively), sorted by path. Throws CcdQueryFileError if root is not a directory.
std::vector<CcdQueryFile> list_ccd_query_files(const std::string& root);

// Nearest double to the rational (round to nearest, ties to even); *exact (if
// not null) tells whether the double equals the rational exactly. Numerator and
// denominator must fit in 127 bits: otherwise std::out_of_range is thrown.
// Results below the normal range (|x| < 2^-1022) may be rounded twice.
double to_double(const Rational& r, bool* exact = nullptr);
// The 3 coordinates; *exact is true when all three are exact.
std::array<double, 3> to_double(const RationalPoint& p, bool* exact = nullptr);

}  // namespace gauss6
