// Structural checks of OFF, PLY and STL files before CGAL reads them
// (mesh_file_checks.h): headers checked, every count and list length bounded by
// what the file still holds. Linear in the file's size, no allocation beyond a
// few tokens.
#include "mesh_file_checks.h"

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "gauss6/io/load_error.h"

namespace gauss6::detail {
namespace {

[[noreturn]] void fail(const std::string& path, const std::string& what) { throw MeshFileError(path, what); }

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v'; }

// The whitespace-separated tokens of one line.
std::vector<std::string_view> tokens_of(std::string_view line) {
  std::vector<std::string_view> out;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && is_space(line[i])) ++i;
    const size_t start = i;
    while (i < line.size() && !is_space(line[i])) ++i;
    if (i > start) out.push_back(line.substr(start, i - start));
  }
  return out;
}

// A non-negative decimal integer that fits in 63 bits; false otherwise.
bool parse_count(std::string_view s, uint64_t* out) {
  if (s.empty() || s.size() > 18) return false;  // 18 digits < 2^63
  uint64_t v = 0;
  for (char c : s) {
    if (c < '0' || c > '9') return false;
    v = v * 10 + static_cast<uint64_t>(c - '0');
  }
  *out = v;
  return true;
}

// Lines of text with '#' comments removed and blank lines skipped.
class LineCursor {
 public:
  explicit LineCursor(std::string_view text) : text_(text) {}
  // The next non-blank line's tokens; false at the end.
  bool next(std::vector<std::string_view>* toks) {
    while (pos_ < text_.size()) {
      size_t end = text_.find('\n', pos_);
      if (end == std::string_view::npos) end = text_.size();
      std::string_view line = text_.substr(pos_, end - pos_);
      pos_ = end + 1;
      ++line_;
      if (const size_t hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
      *toks = tokens_of(line);
      if (!toks->empty()) return true;
    }
    return false;
  }
  int line() const { return line_; }

 private:
  std::string_view text_;
  size_t pos_ = 0;
  int line_ = 0;
};

}  // namespace

// Plain ASCII OFF, one record a line: "OFF" (or "NOFF", 6 numbers a vertex), then "nv nf ne", nv vertex lines of at
// least 3 numbers, nf face lines "k i1 ... ik" (extra values, e.g. colours, allowed).
void check_off_structure(const std::string& path, const std::string& bytes) {
  LineCursor lines(bytes);
  std::vector<std::string_view> t;
  if (!lines.next(&t)) fail(path, "cannot parse as OFF: no header");
  // NOFF: each vertex line carries its normal after the coordinates (6 numbers).
  const bool with_normals = t[0] == "NOFF";
  if (t[0] != "OFF" && !with_normals) {
    if (t[0].size() >= 3 && t[0].substr(t[0].size() - 3) == "OFF")
      fail(path, "cannot parse as OFF: the variant '" + std::string(t[0]) + "' is not read (only OFF and NOFF)");
    fail(path, "cannot parse as OFF: the file does not start with 'OFF'");
  }
  // CGAL 5.5's header reader takes the character after the keyword as a separator,
  // whatever it is: "OFF#c 9 9 9" hides the comment's '#' from it, so it would read
  // counts from inside the comment. A comment there must be set apart by a space.
  // (The cursor cut the line at the '#': the keyword's token then ends right before it.)
  {
    const char* after_keyword = t[0].data() + t[0].size();
    if (after_keyword < bytes.data() + bytes.size() && *after_keyword == '#')
      fail(path, "cannot parse as OFF: line " + std::to_string(lines.line()) + ": a comment right after '" +
                     std::string(t[0]) + "' (put a space before the '#')");
  }
  // Counts may follow on the same line or come on the next one.
  std::vector<std::string_view> counts(t.begin() + 1, t.end());
  if (!counts.empty() && counts[0] == "BINARY") fail(path, "cannot parse as OFF: binary OFF is not read (only plain ASCII OFF)");
  if (counts.empty() && !lines.next(&counts)) fail(path, "cannot parse as OFF: no vertex and face counts after the header");
  uint64_t nv = 0, nf = 0, ne = 0;
  if (counts.size() != 3 || !parse_count(counts[0], &nv) || !parse_count(counts[1], &nf) ||
      !parse_count(counts[2], &ne))
    fail(path, "cannot parse as OFF: line " + std::to_string(lines.line()) +
                   ": expected three non-negative integer counts (vertices, faces, edges)");
  // CGAL 5.5 reads the edge count into an int and doubles it (its guess of the
  // half-edges), overflowing beyond 2^30 - 1; nothing else uses it.
  if (ne > (uint64_t{1} << 30) - 1)
    fail(path, "cannot parse as OFF: line " + std::to_string(lines.line()) + ": the edge count " + std::to_string(ne) +
                   " is over 1073741823 (2^30 - 1)");
  // Each vertex takes at least 6 bytes and each face at least 2: a count beyond that is a lie.
  if (nv > bytes.size() / 6 || nf > bytes.size() / 2)
    fail(path, "cannot parse as OFF: the header states " + std::to_string(nv) + " vertices and " + std::to_string(nf) +
                   " faces, more than a file of " + std::to_string(bytes.size()) + " bytes can hold");
  for (uint64_t v = 0; v < nv; ++v) {
    if (!lines.next(&t))
      fail(path, "cannot parse as OFF: the header states " + std::to_string(nv) + " vertices, the file holds " + std::to_string(v));
    if (t.size() < 3) fail(path, "cannot parse as OFF: line " + std::to_string(lines.line()) + ": a vertex needs 3 coordinates");
    if (with_normals && t.size() < 6)
      fail(path, "cannot parse as OFF: line " + std::to_string(lines.line()) + ": a NOFF vertex needs 3 coordinates and 3 normal components");
  }
  for (uint64_t f = 0; f < nf; ++f) {
    if (!lines.next(&t))
      fail(path, "cannot parse as OFF: the header states " + std::to_string(nf) + " faces, the file holds " + std::to_string(f));
    uint64_t k = 0;
    if (!parse_count(t[0], &k) || k > t.size() - 1)
      fail(path, "cannot parse as OFF: line " + std::to_string(lines.line()) + ": face " + std::to_string(f) +
                     " states more corners than the line holds (or a bad corner count '" + std::string(t[0]) + "')");
    // CGAL 5.5 reads indices as doubles and casts them to size_t (undefined beyond
    // its range): each must be a vertex number here.
    for (uint64_t c = 1; c <= k; ++c) {
      uint64_t index = 0;
      if (!parse_count(t[c], &index) || index >= nv)
        fail(path, "cannot parse as OFF: line " + std::to_string(lines.line()) + ": face " + std::to_string(f) +
                       " has corner '" + std::string(t[c]) + "', not a vertex number below " + std::to_string(nv));
    }
  }
  // A file holding more than its header states (CGAL stops at the counts and
  // would drop the rest silently).
  if (lines.next(&t))
    fail(path, "cannot parse as OFF: line " + std::to_string(lines.line()) + ": more records than the header states (" +
                   std::to_string(nv) + " vertices, " + std::to_string(nf) + " faces)");
}

namespace {

// Size in bytes of a PLY scalar type; 0 for an unknown name.
int ply_type_size(std::string_view type) {
  if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
  if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
  if (type == "int" || type == "uint" || type == "int32" || type == "uint32" || type == "float" ||
      type == "float32")
    return 4;
  if (type == "double" || type == "float64") return 8;
  return 0;
}
bool ply_type_signed(std::string_view type) {
  return type == "char" || type == "int8" || type == "short" || type == "int16" || type == "int" || type == "int32";
}
bool ply_type_floating(std::string_view type) {
  return type == "float" || type == "float32" || type == "double" || type == "float64";
}

// An ASCII PLY value that is one whole number of its type, as CGAL 5.5's reader
// (stream >> value) takes it: for an integer type an optional sign ('-' only for
// signed types) and decimal digits; for a floating type a decimal number, the
// whole token. The reader stops inside a token it cannot read whole and takes
// the rest as the next value: "0-4000" was z = 0 and then a list length of
// -4000, read as 2^32 - 4000 (a 17 GB allocation).
bool ply_ascii_value(std::string_view tok, std::string_view type) {
  if (!tok.empty() && (tok[0] == '+' || (tok[0] == '-' && (ply_type_signed(type) || ply_type_floating(type)))))
    tok.remove_prefix(1);
  if (tok.empty()) return false;
  size_t i = 0;
  // The decimal digits from i on, skipped; how many.
  const auto skip_digits = [&] {
    const size_t start = i;
    while (i < tok.size() && tok[i] >= '0' && tok[i] <= '9') ++i;
    return i - start;
  };
  if (!ply_type_floating(type)) return skip_digits() == tok.size();
  // Digits with at most one '.', then an optional exponent e[+-]digits.
  size_t digits = skip_digits();
  if (i < tok.size() && tok[i] == '.') {
    ++i;
    digits += skip_digits();
  }
  if (digits == 0) return false;
  if (i < tok.size() && (tok[i] == 'e' || tok[i] == 'E')) {
    ++i;
    if (i < tok.size() && (tok[i] == '+' || tok[i] == '-')) ++i;
    if (skip_digits() == 0) return false;
  }
  return i == tok.size();
}

struct PlyProperty {
  std::string_view name;
  std::string_view type;        // scalar: its type; list: an item's type
  bool is_list = false;
  std::string_view count_type;  // lists only
  int count_size = 0;           // lists only
  int value_size = 0;           // scalar: its size; list: an item's size
};
struct PlyElement {
  std::string name;
  uint64_t count = 0;
  std::vector<PlyProperty> properties;
};

// A list length read from binary data in the file's byte order; false if negative.
bool read_binary_count(const unsigned char* p, const PlyProperty& prop, bool big_endian, uint64_t* out) {
  uint64_t v = 0;
  for (int i = 0; i < prop.count_size; ++i) {
    const int b = big_endian ? i : prop.count_size - 1 - i;
    v = (v << 8) | p[b];
  }
  if (ply_type_signed(prop.count_type) && (v >> (8 * prop.count_size - 1)) & 1) return false;
  if (prop.count_type == "float" || prop.count_type == "float32" || prop.count_type == "double" ||
      prop.count_type == "float64")
    return false;  // a list length must be an integer type
  *out = v;
  return true;
}

// Where a PLY header ends: the offset of its end_header line, and of the body
// after that line.
struct PlyHeaderEnd {
  size_t end_tag;
  size_t body;
};
PlyHeaderEnd find_ply_header_end(const std::string& path, std::string_view all) {
  // The header ends at the first line whose first word is end_header, as CGAL reads
  // it (a mere substring, e.g. inside a comment, does not end it).
  for (size_t line = 0; line < all.size();) {
    size_t eol = all.find('\n', line);
    if (eol == std::string_view::npos) eol = all.size();
    const std::vector<std::string_view> words = tokens_of(all.substr(line, eol - line));
    if (!words.empty() && words[0] == "end_header") return {line, std::min(eol + 1, all.size())};
    line = eol + 1;
  }
  fail(path, "cannot parse as PLY: no 'end_header' line");
}

// A PLY header: its format ("ascii", "binary_little_endian" or
// "binary_big_endian") and its elements in order.
struct PlyHeader {
  std::string format;
  std::vector<PlyElement> elements;
};

// Reads the header's lines (before end_header): format, elements and their
// properties, each line checked; a format given, and properties for every
// element that has items.
PlyHeader read_ply_header(const std::string& path, std::string_view header) {
  PlyHeader h;
  LineCursor lines(header);
  std::vector<std::string_view> t;
  lines.next(&t);  // "ply"
  while (lines.next(&t)) {
    const std::string at = "cannot parse as PLY: header line " + std::to_string(lines.line()) + ": ";
    if (t[0] == "comment" || t[0] == "obj_info") continue;
    if (t[0] == "format") {
      if (t.size() != 3 || (t[1] != "ascii" && t[1] != "binary_little_endian" && t[1] != "binary_big_endian"))
        fail(path, at + "expected 'format ascii|binary_little_endian|binary_big_endian 1.0'");
      h.format = std::string(t[1]);
    } else if (t[0] == "element") {
      PlyElement e;
      if (t.size() != 3 || !parse_count(t[2], &e.count)) fail(path, at + "expected 'element NAME COUNT'");
      e.name = std::string(t[1]);
      h.elements.push_back(std::move(e));
    } else if (t[0] == "property") {
      if (h.elements.empty()) fail(path, at + "a 'property' line before any 'element' line");
      PlyProperty p;
      if (t.size() == 5 && t[1] == "list") {
        p.is_list = true;
        p.name = t[4];
        p.type = t[3];
        p.count_type = t[2];
        p.count_size = ply_type_size(t[2]);
        p.value_size = ply_type_size(t[3]);
        if (!p.count_size || !p.value_size) fail(path, at + "unknown type in 'property list'");
      } else if (t.size() == 3) {
        p.name = t[2];
        p.type = t[1];
        p.value_size = ply_type_size(t[1]);
        if (!p.value_size) fail(path, at + "unknown property type '" + std::string(t[1]) + "'");
      } else {
        fail(path, at + "expected 'property TYPE NAME' or 'property list COUNT_TYPE TYPE NAME'");
      }
      h.elements.back().properties.push_back(p);
    } else {
      fail(path, at + "unknown header keyword '" + std::string(t[0]) + "'");
    }
  }
  if (h.format.empty()) fail(path, "cannot parse as PLY: no 'format' line");
  for (const PlyElement& e : h.elements)
    if (e.count > 0 && e.properties.empty())
      fail(path, "cannot parse as PLY: element '" + e.name + "' has " + std::to_string(e.count) + " items but no properties");
  return h;
}

// The types CGAL 5.5's reader assumes without checking (it dereferences a failed
// cast otherwise): vertex coordinates float or double, all three of one type (the
// reader takes y's and z's from x's), face indices 32-bit integers.
void check_ply_types(const std::string& path, const std::vector<PlyElement>& elements) {
  for (const PlyElement& e : elements) {
    std::string_view coordinate_type;
    for (const PlyProperty& p : e.properties) {
      const bool real = p.type == "float" || p.type == "float32" || p.type == "double" || p.type == "float64";
      const bool int32 = p.type == "int" || p.type == "int32" || p.type == "uint" || p.type == "uint32";
      const bool coordinate = e.name == "vertex" && (p.name == "x" || p.name == "y" || p.name == "z");
      if (coordinate && (p.is_list || !real))
        fail(path, "cannot parse as PLY: vertex coordinate '" + std::string(p.name) + "' must be float or double");
      if (coordinate && !coordinate_type.empty() && p.type != coordinate_type)
        fail(path, "cannot parse as PLY: vertex coordinates x, y, z must share one type ('" + std::string(p.name) +
                       "' is " + std::string(p.type) + ", not " + std::string(coordinate_type) + ")");
      if (coordinate) coordinate_type = p.type;
      if (e.name == "face" && (p.name == "vertex_indices" || p.name == "vertex_index") && (!p.is_list || !int32))
        fail(path, "cannot parse as PLY: face property '" + std::string(p.name) +
                       "' must be a list of 32-bit integers (int or uint)");
    }
  }
}

// An ASCII body from offset body on: every item of every element, each value
// of its type, each count bounded by the bytes left, nothing after the last.
void check_ply_ascii_body(const std::string& path, std::string_view all, size_t body,
                          const std::vector<PlyElement>& elements) {
  const size_t size = all.size();
  // Tokens, whitespace-separated; each takes at least 2 bytes but the last.
  size_t pos = body;
  auto next_token = [&](std::string_view* tok) {
    while (pos < size && is_space(all[pos])) ++pos;
    const size_t start = pos;
    while (pos < size && !is_space(all[pos])) ++pos;
    *tok = all.substr(start, pos - start);
    return pos > start;
  };
  for (const PlyElement& e : elements) {
    if (e.count == 0) continue;
    if (e.count > (size - body) / (2 * e.properties.size()) + 1)
      fail(path, "cannot parse as PLY: element '" + e.name + "' states " + std::to_string(e.count) +
                     " items, more than the file can hold");
    for (uint64_t i = 0; i < e.count; ++i)
      for (const PlyProperty& p : e.properties) {
        std::string_view tok;
        if (!next_token(&tok))
          fail(path, "cannot parse as PLY: element '" + e.name + "' ends after " + std::to_string(i) + " of " +
                         std::to_string(e.count) + " items");
        const auto check_value = [&](std::string_view type) {
          if (!ply_ascii_value(tok, type))
            fail(path, "cannot parse as PLY: element '" + e.name + "' item " + std::to_string(i) + ": '" +
                           std::string(tok) + "' is not a value of type " + std::string(type));
        };
        if (!p.is_list) {
          check_value(p.type);
          continue;
        }
        uint64_t n = 0;
        if (!parse_count(tok, &n) || n > (size - pos) / 2 + 1)
          fail(path, "cannot parse as PLY: element '" + e.name + "' item " + std::to_string(i) + ": bad list length '" +
                         std::string(tok) + "' (not a count, or more values than the file holds)");
        for (uint64_t k = 0; k < n; ++k) {
          if (!next_token(&tok)) fail(path, "cannot parse as PLY: element '" + e.name + "': the file ends inside a list");
          check_value(p.type);
        }
      }
  }
  // A file holding more than its header states (the reader stops at the counts).
  if (std::string_view extra; next_token(&extra))
    fail(path, "cannot parse as PLY: line " + std::to_string(1 + std::count(all.begin(), all.begin() + pos, '\n')) +
                   ": more values than the header's elements state ('" + std::string(extra.substr(0, 32)) + "')");
}

// A binary body from offset body on, in the file's byte order: every item of
// every element within the bytes left, list lengths non-negative integers,
// nothing after the last item but white space.
void check_ply_binary_body(const std::string& path, std::string_view all, size_t body,
                           const std::vector<PlyElement>& elements, bool big_endian) {
  const size_t size = all.size();
  const auto* data = reinterpret_cast<const unsigned char*>(all.data());
  size_t pos = body;
  for (const PlyElement& e : elements) {
    if (e.count == 0) continue;
    uint64_t min_item = 0;
    for (const PlyProperty& p : e.properties) min_item += p.is_list ? p.count_size : p.value_size;
    if (e.count > (size - pos) / min_item)
      fail(path, "cannot parse as PLY: element '" + e.name + "' states " + std::to_string(e.count) +
                     " items, more than the file can hold");
    for (uint64_t i = 0; i < e.count; ++i)
      for (const PlyProperty& p : e.properties) {
        const uint64_t head = p.is_list ? p.count_size : p.value_size;
        if (size - pos < head) fail(path, "cannot parse as PLY: element '" + e.name + "': the file ends inside an item");
        if (!p.is_list) {
          pos += head;
          continue;
        }
        uint64_t n = 0;
        if (!read_binary_count(data + pos, p, big_endian, &n))
          fail(path, "cannot parse as PLY: element '" + e.name + "' item " + std::to_string(i) + ": negative or non-integer list length");
        pos += head;
        if (n > (size - pos) / static_cast<uint64_t>(p.value_size))
          fail(path, "cannot parse as PLY: element '" + e.name + "' item " + std::to_string(i) + ": a list of " +
                         std::to_string(n) + " values, more than the file holds");
        pos += n * static_cast<uint64_t>(p.value_size);
      }
  }
  // A file holding more than its header states; trailing white space (a
  // writer's final newline) is no record.
  while (pos < size && is_space(all[pos])) ++pos;
  if (pos < size)
    fail(path, "cannot parse as PLY: " + std::to_string(size - pos) +
                   " bytes after the header's elements (the file holds more than it states)");
}

}  // namespace

// The header, then the body: every item of every element, each count bounded by
// the bytes left.
void check_ply_structure(const std::string& path, const std::string& bytes) {
  const std::string_view all(bytes);
  if (all.substr(0, 3) != "ply") fail(path, "cannot parse as PLY: the file does not start with 'ply'");
  const PlyHeaderEnd end = find_ply_header_end(path, all);
  const PlyHeader header = read_ply_header(path, all.substr(0, end.end_tag));
  check_ply_types(path, header.elements);
  if (header.format == "ascii") check_ply_ascii_body(path, all, end.body, header.elements);
  else check_ply_binary_body(path, all, end.body, header.elements, header.format == "binary_big_endian");
}

// Binary STL: an 80-byte header, a 32-bit facet count, 50 bytes a facet. ASCII STL
// (starting with "solid" and not of the binary size) has no counts.
void check_stl_structure(const std::string& path, const std::string& bytes) {
  if (bytes.size() < 84) return;  // ASCII, or too short to state a count: nothing to bound
  uint32_t n = 0;
  std::memcpy(&n, bytes.data() + 80, 4);  // little-endian (checked by the trace writer's build too)
  const bool binary_size = bytes.size() == 84 + 50 * static_cast<uint64_t>(n);
  if (bytes.compare(0, 5, "solid") == 0 && !binary_size) return;  // ASCII
  // The facets the file holds must be those it states: fewer cannot be read, and
  // more would be dropped silently (a trailing part of a facet is no facet).
  if (static_cast<uint64_t>(n) != (bytes.size() - 84) / 50)
    fail(path, "cannot parse as STL: the header states " + std::to_string(n) + " facets, the file holds " +
                   std::to_string((bytes.size() - 84) / 50));
}

}  // namespace gauss6::detail
