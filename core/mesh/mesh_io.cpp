#include "core/mesh/mesh_io.h"

#include <sys/stat.h>
#include <tbb/parallel_for.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <numeric>
#include <string>
#include <unordered_map>
#include <vector>

#include "core/common/errors.h"
#include "core/mesh/atomic_file.h"
#include "core/mesh/corner_normals.h"
#include "core/mesh/decimal_format.h"
#include "core/mesh/element_kinds.h"
#include "core/mesh/geometry_measures.h"
#include "core/mesh/gltf_writer.h"
#include "core/mesh/input_file.h"

namespace mq {
namespace {

// ---------------------------------------------------------------------------------------------
// Whole-file input and a line-aware text cursor.

std::string read_whole_file(const std::string& path) {
  std::string data = read_input_file(path, "mesh file");
  if (data.empty()) MQ_THROW(InvalidInput, path, ":1: empty file");
  return data;
}

inline bool is_blank(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v';
}
inline bool is_space(char c) { return is_blank(c) || c == '\n'; }

// Cursor over text with the current 1-based line number, for "FILE:LINE: problem" messages.
class TextCursor {
 public:
  TextCursor(const std::string& path, const char* begin, const char* end)
      : path_(path), p_(begin), end_(end) {}

  [[noreturn]] void fail(const std::string& message) const {
    throw InvalidInput(detail::printable(path_ + ":" + std::to_string(line_) + ": " + message));
  }

  bool eof() const { return p_ >= end_; }
  char peek() const { return p_ < end_ ? *p_ : '\0'; }
  char peek(int k) const { return p_ + k < end_ ? p_[k] : '\0'; }
  void advance(int k) { p_ += k; }
  int line() const { return line_; }
  const char* pos() const { return p_; }
  long long remaining() const { return static_cast<long long>(end_ - p_); }

  void skip_blanks() {
    while (p_ < end_ && is_blank(*p_)) ++p_;
  }
  // True at end of line, end of file or a '#' comment (after skip_blanks).
  bool at_eol() const { return p_ >= end_ || *p_ == '\n' || *p_ == '#'; }
  void skip_line() {
    const void* nl = std::memchr(p_, '\n', static_cast<size_t>(end_ - p_));
    if (nl) {
      p_ = static_cast<const char*>(nl) + 1;
      ++line_;
    } else {
      p_ = end_;
    }
  }
  // Skips whitespace across lines and '#' comments.
  void skip_space_and_comments() {
    while (p_ < end_) {
      if (*p_ == '\n') {
        ++line_;
        ++p_;
      } else if (is_blank(*p_)) {
        ++p_;
      } else if (*p_ == '#') {
        skip_line();
      } else {
        break;
      }
    }
  }

  // The rest of this line without surrounding blanks (a '#' starts a comment), capped at 256
  // bytes: the names of OBJ groups and materials.
  std::string rest_of_line() {
    skip_blanks();
    const char* b = p_;
    const char* e = p_;
    while (e < end_ && *e != '\n' && *e != '#') ++e;
    const char* t = e;
    while (t > b && is_blank(t[-1])) --t;
    p_ = e;
    return std::string(b, std::min<size_t>(static_cast<size_t>(t - b), 256));
  }

  // Next whitespace-delimited word on this line (empty at end of line).
  std::string word() {
    skip_blanks();
    const char* b = p_;
    while (p_ < end_ && !is_space(*p_)) ++p_;
    return std::string(b, p_);
  }

  // A number on the current line; `extra` is one more character allowed to end it (e.g. '/').
  double read_double(const char* what, char extra = '\0') {
    skip_blanks();
    if (at_eol()) fail(std::string("expected ") + what + ", found end of line");
    const char* b = p_;
    if (*b == '+' && b + 1 < end_ && b[1] != '-') ++b;
    double v = 0;
    const auto [ptr, ec] = std::from_chars(b, end_, v);
    if (ec == std::errc::result_out_of_range) {
      fail(std::string("number out of range for ") + what + ": '" + token_at(p_) + "'");
    }
    if (ec != std::errc() || !ends_token(ptr, extra))
      fail(std::string("malformed number for ") + what + ": '" + token_at(p_) + "'");
    if (!std::isfinite(v))
      fail(std::string("non-finite value for ") + what + ": '" + token_at(p_) + "'");
    p_ = ptr;
    return v;
  }

  long long read_int(const char* what, char extra = '\0') {
    skip_blanks();
    if (at_eol()) fail(std::string("expected ") + what + ", found end of line");
    const char* b = p_;
    if (*b == '+' && b + 1 < end_ && b[1] != '-') ++b;
    long long v = 0;
    const auto [ptr, ec] = std::from_chars(b, end_, v);
    if (ec == std::errc::result_out_of_range)
      fail(std::string(what) + " out of range: '" + token_at(p_) + "'");
    if (ec != std::errc() || !ends_token(ptr, extra))
      fail(std::string("malformed integer for ") + what + ": '" + token_at(p_) + "'");
    p_ = ptr;
    return v;
  }

 private:
  bool ends_token(const char* q, char extra) const {
    return q >= end_ || is_space(*q) || *q == '#' || (extra != '\0' && *q == extra);
  }
  std::string token_at(const char* q) const {
    const char* e = q;
    while (e < end_ && !is_space(*e) && e - q < 40) ++e;
    return std::string(q, e);
  }

  const std::string& path_;
  const char* p_;
  const char* end_;
  int line_ = 1;
};

TriMesh make_mesh(const std::vector<double>& V, const std::vector<int>& F) {
  TriMesh m;
  const Eigen::Index nv = static_cast<Eigen::Index>(V.size() / 3);
  const Eigen::Index nf = static_cast<Eigen::Index>(F.size() / 3);
  m.V = Eigen::Map<const MatrixX3d>(V.data(), nv, 3);
  m.F = Eigen::Map<const MatrixX3i>(F.data(), nf, 3);
  return m;
}

// ---------------------------------------------------------------------------------------------
// OBJ

// The OBJ lines a mesh needs (v, vn, f, g, o, usemtl), read line by line; everything else
// (vt, s, mtllib, l, comments) and trailing values such as the optional w or vertex colours
// are ignored.
class ObjParser {
 public:
  ObjParser(TextCursor& c, size_t bytes) : c_(c) {
    V_.reserve(bytes / 16);
    F_.reserve(bytes / 8);
  }

  void parse() {
    while (!c_.eof()) {
      c_.skip_blanks();
      const char c0 = c_.peek(), c1 = c_.peek(1);
      if (c0 == 'v' && is_blank(c1)) {
        c_.advance(1);
        for (int k = 0; k < 3; ++k) V_.push_back(c_.read_double("vertex coordinate"));
      } else if (c0 == 'v' && c1 == 'n' && is_blank(c_.peek(2))) {
        c_.advance(2);
        for (int k = 0; k < 3; ++k) N_.push_back(c_.read_double("normal coordinate"));
      } else if (c0 == 'f' && is_blank(c1)) {
        c_.advance(1);
        read_face();
      } else if ((c0 == 'g' || c0 == 'o') && is_blank(c1)) {
        c_.advance(1);
        group_ = c_.rest_of_line();
        update_kind();
      } else if (c_.remaining() > 7 && std::memcmp(c_.pos(), "usemtl", 6) == 0 &&
                 is_blank(c_.peek(6))) {
        c_.advance(6);
        material_ = c_.rest_of_line();
        if (material_ == "(null)") material_.clear();  // what some exporters write for "none"
        update_kind();
      }
      c_.skip_line();
    }
    if (F_.empty()) c_.fail("no faces");
  }

  TriMesh mesh() {
    TriMesh m = make_mesh(V_, F_);
    if (current_kind_ >= 0) {
      m.kinds = std::move(kinds_);
      m.face_kind = std::move(face_kind_);
      remove_unused_kinds(m);
    }
    attach_vertex_normals(m);
    return m;
  }

 private:
  // One corner "v", "v/t", "v//n" or "v/t/n" (indices from 1, or negative from the end):
  // its vertex and normal (-1: none).
  std::pair<int, int> read_corner(long long nv, long long nn) {
    const long long vi = c_.read_int("vertex index", '/');
    long long ni = 0;
    if (c_.peek() == '/') {
      c_.advance(1);
      if (c_.peek() != '/') {
        if (!is_space(c_.peek()) && c_.peek() != '\0') c_.read_int("texture index", '/');
      }
      if (c_.peek() == '/') {
        c_.advance(1);
        ni = c_.read_int("normal index");
      }
    }
    const long long v = vi > 0 ? vi - 1 : nv + vi;
    if (vi == 0 || v < 0 || v >= nv)
      c_.fail("vertex index " + std::to_string(vi) + " out of range (" + std::to_string(nv) +
              " vertices defined so far)");
    int n = -1;
    if (ni != 0) {
      const long long nn_idx = ni > 0 ? ni - 1 : nn + ni;
      if (nn_idx < 0 || nn_idx >= nn)
        c_.fail("normal index " + std::to_string(ni) + " out of range (" + std::to_string(nn) +
                " normals defined so far)");
      n = static_cast<int>(nn_idx);
    }
    return {static_cast<int>(v), n};
  }
  // A face, fanned into triangles of the current kind.
  void read_face() {
    corners_.clear();
    const long long nv = static_cast<long long>(V_.size() / 3);
    const long long nn = static_cast<long long>(N_.size() / 3);
    for (;;) {
      c_.skip_blanks();
      if (c_.at_eol()) break;
      corners_.push_back(read_corner(nv, nn));
    }
    if (corners_.size() < 3)
      c_.fail("face with " + std::to_string(corners_.size()) + " vertices (need at least 3)");
    for (size_t i = 1; i + 1 < corners_.size(); ++i) {
      for (size_t k : {size_t(0), i, i + 1}) {
        F_.push_back(corners_[k].first);
        FN_.push_back(corners_[k].second);
        all_corners_have_normals_ &= corners_[k].second >= 0;
      }
      if (current_kind_ >= 0) face_kind_.push_back(current_kind_);
    }
  }
  int kind_id(const std::string& name) {
    const auto [it, added] = kind_of_name_.emplace(name, static_cast<int>(kinds_.size()));
    if (added) kinds_.push_back(name);
    return it->second;
  }
  // Kinds (element_kinds.h): a face's kind is its material (usemtl), else its group (g or o);
  // faces before the first name take the default kind once one is named.
  void update_kind() {
    const std::string& name = material_.empty() ? group_ : material_;
    if (name.empty() && current_kind_ < 0) return;
    if (current_kind_ < 0) face_kind_.assign(F_.size() / 3, kind_id(kDefaultKind));
    current_kind_ = kind_id(sanitized_kind(name));
  }
  // Per-vertex normals only when each vertex is always paired with the same normal.
  void attach_vertex_normals(TriMesh& m) const {
    if (N_.empty() || !all_corners_have_normals_) return;
    std::vector<int> vertex_normal(V_.size() / 3, -1);
    bool consistent = true;
    for (size_t i = 0; i < F_.size() && consistent; ++i) {
      int& slot = vertex_normal[static_cast<size_t>(F_[i])];
      if (slot < 0) slot = FN_[i];
      consistent = slot == FN_[i];
    }
    consistent &= std::find(vertex_normal.begin(), vertex_normal.end(), -1) == vertex_normal.end();
    if (!consistent) return;
    m.N.resize(m.V.rows(), 3);
    for (Eigen::Index v = 0; v < m.V.rows(); ++v)
      for (int k = 0; k < 3; ++k)
        m.N(v, k) = N_[3 * static_cast<size_t>(vertex_normal[static_cast<size_t>(v)]) + k];
  }

  TextCursor& c_;
  std::vector<double> V_, N_;
  std::vector<int> F_, FN_;  // FN: normal index per triangle corner, -1 when absent
  std::vector<std::pair<int, int>> corners_;
  bool all_corners_have_normals_ = true;
  std::string material_, group_;
  std::vector<std::string> kinds_;
  std::unordered_map<std::string, int> kind_of_name_;
  std::vector<int> face_kind_;
  int current_kind_ = -1;  // -1: no name seen yet
};

TriMesh read_obj(const std::string& path, const std::string& data) {
  TextCursor c(path, data.data(), data.data() + data.size());
  ObjParser parser(c, data.size());
  parser.parse();
  return parser.mesh();
}

// ---------------------------------------------------------------------------------------------
// OFF

TriMesh read_off(const std::string& path, const std::string& data) {
  TextCursor c(path, data.data(), data.data() + data.size());
  c.skip_space_and_comments();
  std::string header = c.word();
  // Geomview variants: [ST][C][N][4][n]OFF; only 3D without extra dimension is supported.
  std::string h = header;
  bool has_normals = false;
  if (h.rfind("ST", 0) == 0) h = h.substr(2);
  if (h.rfind('C', 0) == 0) h = h.substr(1);
  if (h.rfind('N', 0) == 0) {
    has_normals = true;
    h = h.substr(1);
  }
  if (h != "OFF") {
    if (header.size() >= 3 && header.compare(header.size() - 3, 3, "OFF") == 0)
      c.fail("unsupported OFF variant '" + header + "'");
    c.fail("missing OFF header (found '" + header.substr(0, 40) + "')");
  }
  c.skip_space_and_comments();
  const long long nv = c.read_int("vertex count");
  c.skip_space_and_comments();
  const long long nf = c.read_int("face count");
  if (nv < 0 || nf < 0 || nv > std::numeric_limits<int>::max() ||
      nf > std::numeric_limits<int>::max())
    c.fail("invalid counts " + std::to_string(nv) + " " + std::to_string(nf));
  c.skip_blanks();
  if (!c.at_eol()) c.read_int("edge count");  // the edge count is informative only
  c.skip_line();
  if (nf == 0) c.fail("no faces");
  // Large counts are checked against the bytes left before anything is allocated: a vertex takes at
  // least 3 numbers (6 bytes with their separators), a face 4 (8 bytes).
  // Small counts go on to the parse, whose messages say where the data end.
  if (nv + nf > (1 << 16) && 6 * nv + 8 * nf > c.remaining() + 1)
    c.fail("counts " + std::to_string(nv) + " vertices and " + std::to_string(nf) +
           " faces need more data than the file's " + std::to_string(c.remaining()) +
           " remaining bytes");

  std::vector<double> V(static_cast<size_t>(3 * nv)), N;
  if (has_normals) N.resize(static_cast<size_t>(3 * nv));
  for (long long i = 0; i < nv; ++i) {
    c.skip_space_and_comments();
    if (c.eof())
      c.fail("unexpected end of file: expected " + std::to_string(nv) + " vertices, found " +
             std::to_string(i));
    for (int k = 0; k < 3; ++k)
      V[static_cast<size_t>(3 * i + k)] = c.read_double("vertex coordinate");
    if (has_normals)
      for (int k = 0; k < 3; ++k)
        N[static_cast<size_t>(3 * i + k)] = c.read_double("normal coordinate");
    c.skip_line();  // colours, texture coordinates
  }
  std::vector<int> F;
  F.reserve(static_cast<size_t>(3 * nf));
  std::vector<int> poly;
  for (long long i = 0; i < nf; ++i) {
    c.skip_space_and_comments();
    if (c.eof())
      c.fail("unexpected end of file: expected " + std::to_string(nf) + " faces, found " +
             std::to_string(i));
    const long long k = c.read_int("face vertex count");
    if (k < 3) c.fail("face with " + std::to_string(k) + " vertices (need at least 3)");
    poly.clear();
    for (long long j = 0; j < k; ++j) {
      const long long v = c.read_int("vertex index");
      if (v < 0 || v >= nv)
        c.fail("vertex index " + std::to_string(v) + " out of range (" + std::to_string(nv) +
               " vertices)");
      poly.push_back(static_cast<int>(v));
    }
    for (size_t j = 1; j + 1 < poly.size(); ++j) {
      F.push_back(poly[0]);
      F.push_back(poly[j]);
      F.push_back(poly[j + 1]);
    }
    c.skip_line();  // colour
  }
  TriMesh m = make_mesh(V, F);
  if (has_normals) m.N = Eigen::Map<const MatrixX3d>(N.data(), m.V.rows(), 3);
  return m;
}

// ---------------------------------------------------------------------------------------------
// PLY

enum class PlyType { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

bool parse_ply_type(const std::string& name, PlyType& type) {
  static constexpr struct {
    const char* name;
    PlyType type;
  } kTypes[] = {
      {"char", PlyType::Int8},      {"int8", PlyType::Int8},       {"uchar", PlyType::UInt8},
      {"uint8", PlyType::UInt8},    {"short", PlyType::Int16},     {"int16", PlyType::Int16},
      {"ushort", PlyType::UInt16},  {"uint16", PlyType::UInt16},   {"int", PlyType::Int32},
      {"int32", PlyType::Int32},    {"uint", PlyType::UInt32},     {"uint32", PlyType::UInt32},
      {"float", PlyType::Float32},  {"float32", PlyType::Float32}, {"double", PlyType::Float64},
      {"float64", PlyType::Float64}};
  for (const auto& t : kTypes)
    if (name == t.name) {
      type = t.type;
      return true;
    }
  return false;
}

int ply_size(PlyType t) {
  switch (t) {
    case PlyType::Int8:
    case PlyType::UInt8:
      return 1;
    case PlyType::Int16:
    case PlyType::UInt16:
      return 2;
    case PlyType::Int32:
    case PlyType::UInt32:
    case PlyType::Float32:
      return 4;
    case PlyType::Float64:
      return 8;
  }
  return 0;
}

bool ply_is_integer(PlyType t) { return t != PlyType::Float32 && t != PlyType::Float64; }

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::Float32;  // item type for lists
  bool is_list = false;
  PlyType count_type = PlyType::UInt8;
};

struct PlyElement {
  std::string name;
  long long count = 0;
  std::vector<PlyProperty> properties;
};

enum class PlyEncoding { Ascii, BinaryLittle, BinaryBig };

bool host_is_little_endian() {
  const std::uint16_t one = 1;
  unsigned char first = 0;
  std::memcpy(&first, &one, 1);
  return first == 1;
}

// Reads binary scalars with bounds checks; failures name the element and its index.
class PlyBinaryReader {
 public:
  PlyBinaryReader(const std::string& path, const char* begin, const char* end, bool swap)
      : path_(path), p_(begin), end_(end), swap_(swap) {}

  void set_context(const std::string* element, long long index) {
    element_ = element;
    index_ = index;
  }
  [[noreturn]] void fail(const std::string& message) const {
    throw InvalidInput(detail::printable(path_ + ": " +
                                         (element_ ? *element_ : std::string("data")) + " " +
                                         std::to_string(index_) + ": " + message));
  }

  void skip(PlyType t, long long n = 1) {
    const long long bytes = n * ply_size(t);
    if (bytes > end_ - p_) fail("unexpected end of file (truncated binary data)");
    p_ += bytes;
  }

  double read_double(PlyType t) {
    unsigned char b[8];
    take(b, ply_size(t));
    switch (t) {
      case PlyType::Float32: {
        float f;
        std::memcpy(&f, b, 4);
        return f;
      }
      case PlyType::Float64: {
        double d;
        std::memcpy(&d, b, 8);
        return d;
      }
      default:
        return static_cast<double>(as_integer(t, b));
    }
  }

  long long read_integer(PlyType t) {
    unsigned char b[8];
    take(b, ply_size(t));
    return as_integer(t, b);
  }

 private:
  void take(unsigned char* b, int n) {
    if (n > end_ - p_) fail("unexpected end of file (truncated binary data)");
    std::memcpy(b, p_, static_cast<size_t>(n));
    p_ += n;
    if (swap_) std::reverse(b, b + n);
  }
  static long long as_integer(PlyType t, const unsigned char* b) {
    switch (t) {
      case PlyType::Int8: {
        std::int8_t v;
        std::memcpy(&v, b, 1);
        return v;
      }
      case PlyType::UInt8:
        return b[0];
      case PlyType::Int16: {
        std::int16_t v;
        std::memcpy(&v, b, 2);
        return v;
      }
      case PlyType::UInt16: {
        std::uint16_t v;
        std::memcpy(&v, b, 2);
        return v;
      }
      case PlyType::Int32: {
        std::int32_t v;
        std::memcpy(&v, b, 4);
        return v;
      }
      case PlyType::UInt32: {
        std::uint32_t v;
        std::memcpy(&v, b, 4);
        return v;
      }
      default:
        return 0;  // float types never reach here: callers check ply_is_integer
    }
  }

  const std::string& path_;
  const char* p_;
  const char* end_;
  bool swap_;
  const std::string* element_ = nullptr;
  long long index_ = 0;
};

// Reads one value of a PLY body in either encoding behind a common interface.
class PlyValueSource {
 public:
  PlyValueSource(TextCursor* text, PlyBinaryReader* binary, const std::string* element)
      : text_(text), binary_(binary), element_(element) {}

  void begin_item(long long index) {
    index_ = index;
    if (binary_) binary_->set_context(element_, index);
  }
  [[noreturn]] void fail(const std::string& message) const {
    if (binary_) binary_->fail(message);
    text_->fail(*element_ + " " + std::to_string(index_) + ": " + message);
  }
  double read_double(PlyType t, const char* what) {
    if (binary_) {
      const double v = binary_->read_double(t);
      if (!std::isfinite(v)) fail(std::string("non-finite value for ") + what);
      return v;
    }
    at_value();
    return text_->read_double(what);
  }
  long long read_integer(PlyType t, const char* what) {
    if (binary_) return binary_->read_integer(t);
    (void)t;
    at_value();
    return text_->read_int(what);
  }
  void skip(PlyType t, long long n = 1) {
    if (binary_) return binary_->skip(t, n);
    for (long long i = 0; i < n; ++i) {
      at_value();
      text_->word();
    }
  }

 private:
  void at_value() {
    text_->skip_space_and_comments();
    if (text_->eof()) fail("unexpected end of file");
  }
  TextCursor* text_;
  PlyBinaryReader* binary_;
  const std::string* element_;
  long long index_ = 0;
};

// A PLY header, up to end_header.
struct PlyHeader {
  PlyEncoding encoding = PlyEncoding::Ascii;
  std::vector<PlyElement> elements;
  std::vector<std::pair<long long, std::string>> kind_names;  // "comment kind K NAME" lines
};

// A "property" line after its keyword: a scalar or a list, of the last element.
void read_ply_property(TextCursor& c, std::vector<PlyElement>& elements) {
  if (elements.empty()) c.fail("property before any element");
  PlyProperty prop;
  std::string type = c.word();
  if (type == "list") {
    prop.is_list = true;
    const std::string count_type = c.word();
    if (!parse_ply_type(count_type, prop.count_type) || !ply_is_integer(prop.count_type))
      c.fail("unsupported PLY list count type '" + count_type + "'");
    type = c.word();
  }
  if (!parse_ply_type(type, prop.type)) c.fail("unsupported PLY property type '" + type + "'");
  prop.name = c.word();
  if (prop.name.empty()) c.fail("property without a name");
  elements.back().properties.push_back(prop);
}

// The header's lines up to end_header; the cursor is left at the body.
PlyHeader read_ply_header(TextCursor& c) {
  if (c.word() != "ply") c.fail("missing 'ply' magic");
  c.skip_line();
  PlyHeader h;
  bool have_format = false;
  for (;;) {
    if (c.eof()) c.fail("unexpected end of file in header (no end_header)");
    const std::string key = c.word();
    if (key == "end_header") {
      c.skip_line();
      break;
    } else if (key == "format") {
      const std::string f = c.word();
      if (f == "ascii")
        h.encoding = PlyEncoding::Ascii;
      else if (f == "binary_little_endian")
        h.encoding = PlyEncoding::BinaryLittle;
      else if (f == "binary_big_endian")
        h.encoding = PlyEncoding::BinaryBig;
      else
        c.fail("unsupported PLY format '" + f + "'");
      have_format = true;
    } else if (key == "element") {
      PlyElement e;
      e.name = c.word();
      if (e.name.empty()) c.fail("element without a name");
      e.count = c.read_int("element count");
      if (e.count < 0 || e.count > std::numeric_limits<int>::max())
        c.fail("invalid element count " + std::to_string(e.count));
      h.elements.push_back(e);
    } else if (key == "property") {
      read_ply_property(c, h.elements);
    } else if (key == "comment") {
      if (c.word() == "kind" && h.kind_names.size() < (1 << 16)) {
        c.skip_blanks();
        if (std::isdigit(static_cast<unsigned char>(c.peek()))) {
          const long long k = c.read_int("kind number");
          h.kind_names.emplace_back(k, sanitized_kind(c.rest_of_line()));
        }
      }
    } else if (key != "obj_info" && !key.empty()) {
      c.fail("unexpected PLY header keyword '" + key + "'");
    }
    c.skip_line();
  }
  if (!have_format) c.fail("PLY header lacks a format line");
  return h;
}

// Where the mesh lies in a PLY file's elements: the (first) vertex and face elements, what
// each vertex property holds, the kind property and the face index list.
struct PlyLayout {
  const PlyElement* vertex = nullptr;
  const PlyElement* face = nullptr;
  std::vector<int> vslot;  // per vertex property: 0..2 position, 3..5 normal, -1 skipped
  bool has_normals = false;
  int kind_prop = -1;   // the vertex property `kind`, or -1
  int index_prop = -1;  // the face property vertex_indices (or vertex_index)
};

PlyLayout locate_ply_mesh(TextCursor& c, const std::vector<PlyElement>& elements) {
  PlyLayout l;
  for (const auto& e : elements) {
    if (e.name == "vertex" && !l.vertex) l.vertex = &e;
    if (e.name == "face" && !l.face) l.face = &e;
  }
  if (!l.vertex) c.fail("PLY header has no vertex element");
  if (!l.face || l.face->count == 0) c.fail("no faces");
  auto find_scalar = [&](const PlyElement& e, const char* name) {
    for (size_t i = 0; i < e.properties.size(); ++i)
      if (e.properties[i].name == name) {
        if (e.properties[i].is_list) c.fail(std::string("property '") + name + "' is a list");
        return static_cast<int>(i);
      }
    return -1;
  };
  l.vslot.assign(l.vertex->properties.size(), -1);
  const char* names[6] = {"x", "y", "z", "nx", "ny", "nz"};
  int found[6];
  for (int k = 0; k < 6; ++k) found[k] = find_scalar(*l.vertex, names[k]);
  if (found[0] < 0 || found[1] < 0 || found[2] < 0)
    c.fail("PLY vertex element lacks an x, y or z property");
  l.has_normals = found[3] >= 0 && found[4] >= 0 && found[5] >= 0;
  for (int k = 0; k < (l.has_normals ? 6 : 3); ++k) l.vslot[static_cast<size_t>(found[k])] = k;
  // Kinds (element_kinds.h): an integer vertex property `kind`; a face takes its first vertex's.
  l.kind_prop = find_scalar(*l.vertex, "kind");
  if (l.kind_prop >= 0 && !ply_is_integer(l.vertex->properties[size_t(l.kind_prop)].type))
    c.fail("vertex property 'kind' is not an integer");
  for (size_t i = 0; i < l.face->properties.size(); ++i) {
    const PlyProperty& p = l.face->properties[i];
    if (p.is_list && (p.name == "vertex_indices" || p.name == "vertex_index")) {
      if (!ply_is_integer(p.type)) c.fail("face index list has non-integer type");
      l.index_prop = static_cast<int>(i);
      break;
    }
  }
  if (l.index_prop < 0) c.fail("PLY face element lacks a vertex_indices list");
  return l;
}

// Declared counts are checked against the bytes left before anything is allocated: every
// item takes at least its scalars' and list counts' sizes in binary, 2 bytes (a digit and a
// separator) per value in ASCII. An element with no properties takes no bytes at all: it is
// not iterated (its count is meaningless).
void check_ply_counts(TextCursor& c, const PlyHeader& h, const PlyLayout& l) {
  const bool ascii = h.encoding == PlyEncoding::Ascii;
  long long needed = 0;
  for (const PlyElement& e : h.elements) {
    long long per_item = 0;
    for (const PlyProperty& p : e.properties)
      per_item += ascii ? 2 : ply_size(p.is_list ? p.count_type : p.type);
    if (&e == l.face && per_item > 0)  // at least 3 indices per face
      per_item +=
          3 * (ascii ? 2 : ply_size(l.face->properties[static_cast<size_t>(l.index_prop)].type));
    needed += per_item * e.count;  // <= 2^31 * (8 + 24) * #properties: no overflow
    // Small counts go on to the parse, whose messages say where the data end.
    if (e.count > (1 << 16) && needed > c.remaining() + 1)
      c.fail("element '" + e.name + "' count " + std::to_string(e.count) +
             " needs more data than the file's " + std::to_string(c.remaining()) +
             " remaining bytes");
  }
}

// What a PLY body holds of the mesh: positions, normals, vertex kinds (#V each, when present)
// and the faces, polygons fanned into triangles.
struct PlyBody {
  std::vector<double> V, N;
  std::vector<int> vertex_kind;
  std::vector<int> F;
  std::vector<int> poly;  // scratch: the face being read
};

// One face's index list, fanned into triangles.
void read_ply_face(PlyValueSource& src, const PlyProperty& p, long long nv, PlyBody& body) {
  const long long n = src.read_integer(p.count_type, "face vertex count");
  if (n < 3) src.fail("face with " + std::to_string(n) + " vertices (need at least 3)");
  std::vector<int>& poly = body.poly;
  poly.clear();
  for (long long j = 0; j < n; ++j) {
    const long long v = src.read_integer(p.type, "vertex index");
    if (v < 0 || v >= nv)
      src.fail("vertex index " + std::to_string(v) + " out of range (" + std::to_string(nv) +
               " vertices)");
    poly.push_back(static_cast<int>(v));
  }
  for (size_t j = 1; j + 1 < poly.size(); ++j) {
    body.F.push_back(poly[0]);
    body.F.push_back(poly[j]);
    body.F.push_back(poly[j + 1]);
  }
}

// Item i of element e: the values the mesh needs into `body`, the others skipped.
void read_ply_item(PlyValueSource& src, const PlyElement& e, long long i, const PlyLayout& l,
                   PlyBody& body) {
  const bool is_vertex = &e == l.vertex, is_face = &e == l.face;
  src.begin_item(i);
  for (size_t pi = 0; pi < e.properties.size(); ++pi) {
    const PlyProperty& p = e.properties[pi];
    if (is_vertex && l.vslot[pi] >= 0) {
      const int k = l.vslot[pi];
      const double v = src.read_double(p.type, k < 3 ? "vertex coordinate" : "normal");
      (k < 3 ? body.V : body.N)[static_cast<size_t>(3 * i + k % 3)] = v;
    } else if (is_vertex && static_cast<int>(pi) == l.kind_prop) {
      const long long k = src.read_integer(p.type, "kind");
      if (k < 0 || k >= (1 << 16)) src.fail("kind " + std::to_string(k) + " out of range");
      body.vertex_kind[static_cast<size_t>(i)] = static_cast<int>(k);
    } else if (is_face && static_cast<int>(pi) == l.index_prop) {
      read_ply_face(src, p, l.vertex->count, body);
    } else if (p.is_list) {
      const long long n = src.read_integer(p.count_type, "list count");
      if (n < 0) src.fail("negative list count");
      src.skip(p.type, n);
    } else {
      src.skip(p.type);
    }
  }
}

// Every element's items in file order, in either encoding.
PlyBody read_ply_body(TextCursor& c, const PlyHeader& h, const PlyLayout& l,
                      const std::string& path, const std::string& data) {
  const long long nv = l.vertex->count;
  PlyBody body;
  body.V.resize(static_cast<size_t>(3 * nv));
  body.vertex_kind.resize(l.kind_prop >= 0 ? static_cast<size_t>(nv) : 0);
  if (l.has_normals) body.N.resize(static_cast<size_t>(3 * nv));
  body.F.reserve(static_cast<size_t>(3 * l.face->count));
  const bool swap = h.encoding != PlyEncoding::Ascii &&
                    (h.encoding == PlyEncoding::BinaryLittle) != host_is_little_endian();
  PlyBinaryReader binary(path, c.pos(), data.data() + data.size(), swap);
  for (const PlyElement& e : h.elements) {
    PlyValueSource src(&c, h.encoding == PlyEncoding::Ascii ? nullptr : &binary, &e.name);
    if (e.properties.empty()) continue;  // no bytes to read
    for (long long i = 0; i < e.count; ++i) read_ply_item(src, e, i, l, body);
  }
  return body;
}

// The mesh of a PLY body; with vertex kinds, each face takes its first vertex's, named by the
// header's "comment kind" lines (kind_K where none names it).
TriMesh ply_mesh(const PlyBody& body, const PlyLayout& l,
                 const std::vector<std::pair<long long, std::string>>& kind_names) {
  TriMesh m = make_mesh(body.V, body.F);
  if (l.has_normals) m.N = Eigen::Map<const MatrixX3d>(body.N.data(), m.V.rows(), 3);
  if (l.kind_prop < 0) return m;
  int top = 0;
  for (const int k : body.vertex_kind) top = std::max(top, k);
  m.kinds.resize(static_cast<size_t>(top) + 1);
  for (const auto& [k, name] : kind_names)
    if (k <= top) m.kinds[static_cast<size_t>(k)] = name;
  for (size_t k = 0; k < m.kinds.size(); ++k)
    if (m.kinds[k].empty()) m.kinds[k] = "kind_" + std::to_string(k);
  m.face_kind.resize(static_cast<size_t>(m.F.rows()));
  for (Eigen::Index f = 0; f < m.F.rows(); ++f)
    m.face_kind[static_cast<size_t>(f)] = body.vertex_kind[static_cast<size_t>(m.F(f, 0))];
  remove_unused_kinds(m);
  return m;
}

TriMesh read_ply(const std::string& path, const std::string& data) {
  TextCursor c(path, data.data(), data.data() + data.size());
  const PlyHeader header = read_ply_header(c);
  const PlyLayout layout = locate_ply_mesh(c, header.elements);
  check_ply_counts(c, header, layout);
  const PlyBody body = read_ply_body(c, header, layout, path, data);
  return ply_mesh(body, layout, header.kind_names);
}

// ---------------------------------------------------------------------------------------------
// Writing

inline char* put_int(char* out, long long v) { return std::to_chars(out, out + 24, v).ptr; }

// Writes " x y z" (or "x y z" when !leading_space).
inline char* put_row(char* out, const MatrixX3d& M, Eigen::Index i, int precision,
                     bool leading_space = true) {
  for (int k = 0; k < 3; ++k) {
    if (k > 0 || leading_space) *out++ = ' ';
    out = format_decimal(out, M(i, k), precision);
  }
  return out;
}

// Normals of an OBJ file: per vertex (Nv, from the mesh) or per corner (C), or none.
struct ObjNormals {
  const MatrixX3d* Nv = nullptr;
  const CornerNormals* C = nullptr;
};

// The file name of the .mtl beside an OBJ: same stem.
std::string mtl_path_for(const std::string& obj_path) {
  return std::filesystem::path(obj_path).replace_extension(".mtl").string();
}

std::string padded(int value, int width) {
  std::string s = std::to_string(value);
  return std::string(static_cast<size_t>(std::max(0, width - static_cast<int>(s.size()))), '0') + s;
}

void write_mtl(AtomicOutputFile& out, const std::vector<std::string>& kinds) {
  out.append("# meshquilt: one material per kind of element\n");
  for (const std::string& kind : kinds) {
    const KindMaterial m = kind_material(kind);
    char buf[256];
    // Kd/Ks/Ns for any reader, Pm/Pr (the PBR extension Blender reads) for metal and roughness.
    std::snprintf(buf, sizeof buf,
                  "Kd %.4f %.4f %.4f\nKs %.4f %.4f %.4f\nNs %.1f\nPm %.3f\nPr %.3f\nd 1\nillum 2\n",
                  m.r, m.g, m.b, 0.04 + 0.96 * m.metallic * m.r, 0.04 + 0.96 * m.metallic * m.g,
                  0.04 + 0.96 * m.metallic * m.b, 900.0 * (1 - m.roughness) * (1 - m.roughness),
                  m.metallic, m.roughness);
    out.append("\nnewmtl " + kind + "\n");
    out.append(buf);
  }
}

// Appends rows [0, n) to out, row i being what format(i, p) writes at p (at most max_row
// bytes; it returns the end). Chunks of rows are formatted in parallel into their own buffers
// and appended in row order, so the bytes are those of a sequential loop whatever the thread
// count. (Number formatting is most of the writing time: 0.2 s for the 28 MB of plane +
// apple's output on one core.)
template <class Format>
void append_rows(AtomicOutputFile& out, Eigen::Index n, size_t max_row, const Format& format) {
  constexpr Eigen::Index kRowsPerChunk = 8192;
  constexpr Eigen::Index kChunksPerWindow = 8;  // bounds the buffers held at once (~8 MB)
  const Eigen::Index chunks = (n + kRowsPerChunk - 1) / kRowsPerChunk;
  std::vector<std::vector<char>> buffers(static_cast<size_t>(std::min(chunks, kChunksPerWindow)));
  std::vector<size_t> used(buffers.size());
  for (Eigen::Index w0 = 0; w0 < chunks; w0 += kChunksPerWindow) {
    const Eigen::Index w1 = std::min(chunks, w0 + kChunksPerWindow);
    tbb::parallel_for(w0, w1, [&](Eigen::Index c) {
      const size_t slot = static_cast<size_t>(c - w0);
      const Eigen::Index r0 = c * kRowsPerChunk, r1 = std::min(n, r0 + kRowsPerChunk);
      std::vector<char>& buffer = buffers[slot];
      buffer.resize(static_cast<size_t>(r1 - r0) * max_row);
      char* p = buffer.data();
      for (Eigen::Index i = r0; i < r1; ++i) p = format(i, p);
      used[slot] = static_cast<size_t>(p - buffer.data());
    });
    for (Eigen::Index c = w0; c < w1; ++c)
      out.append(buffers[static_cast<size_t>(c - w0)].data(), used[static_cast<size_t>(c - w0)]);
  }
}

// The longest line put_row's callers below write: a tag, three numbers of at most 32
// characters (to_chars of a double) or three "i//j" indices of at most 24 + 2 + 24.
constexpr size_t kMaxObjLine = 4 + 3 * (1 + 2 * 24 + 2) + 1;

// The faces in output order: grouped by element or by kind (stable), so each group is one run.
std::vector<int> obj_face_order(const TriMesh& m, const ElementLabels* labels,
                                ElementGroups groups) {
  std::vector<int> order(static_cast<size_t>(m.F.rows()));
  std::iota(order.begin(), order.end(), 0);
  if (labels && groups != ElementGroups::None) {
    const auto key = [&](int f) {
      const int e = labels->face_element[static_cast<size_t>(f)];
      return groups == ElementGroups::Element ? e : labels->element_kind[static_cast<size_t>(e)];
    };
    const auto by_key = [&](int a, int b) { return key(a) < key(b); };
    // Outputs come element after element: already in order, a check instead of a sort.
    if (!std::is_sorted(order.begin(), order.end(), by_key))
      std::stable_sort(order.begin(), order.end(), by_key);
  }
  return order;
}

// The group lines before row i of the face block when face order[i] starts a new group (an
// "o" line by element or kind, and a "usemtl" line naming its kind), decided by the face
// before it, so each chunk needs nothing but i.
char* put_obj_group_lines(char* p, Eigen::Index i, const std::vector<int>& order,
                          const ElementLabels& labels, ElementGroups groups, int width) {
  const auto element_of = [&](Eigen::Index r) {
    return r < 0 ? -1 : labels.face_element[static_cast<size_t>(order[static_cast<size_t>(r)])];
  };
  const int e = element_of(i), last_element = element_of(i - 1);
  const int k = labels.element_kind[static_cast<size_t>(e)];
  const int last_kind =
      last_element < 0 ? -1 : labels.element_kind[static_cast<size_t>(last_element)];
  const std::string& kind = labels.kinds[static_cast<size_t>(k)];
  const auto put = [&](std::string_view text) {
    std::memcpy(p, text.data(), text.size());
    p += text.size();
  };
  if (groups == ElementGroups::Element && e != last_element) {
    put("o ");
    put(kind);
    put("_");
    put(padded(e, width));
    put("\n");
  } else if (groups == ElementGroups::Kind && k != last_kind) {
    put("o ");
    put(kind);
    put("\n");
  }
  if (k != last_kind || (groups == ElementGroups::Element && e != last_element)) {
    put("usemtl ");
    put(kind);
    put("\n");
  }
  return p;
}

void write_obj(AtomicOutputFile& out, const TriMesh& m, const ObjNormals& normals, int precision,
               const ElementLabels* labels, ElementGroups groups, const std::string& mtl_name) {
  if (labels) {
    out.append("# meshquilt: " + std::to_string(labels->count) + " elements of " +
               std::to_string(labels->kinds.size()) + " kinds\n");
    out.append("mtllib " + mtl_name + "\n");
  }
  append_rows(out, m.V.rows(), kMaxObjLine, [&](Eigen::Index i, char* p) {
    *p++ = 'v';
    p = put_row(p, m.V, i, precision);
    *p++ = '\n';
    return p;
  });
  const MatrixX3d* N = normals.C ? &normals.C->N : normals.Nv;
  if (N)
    append_rows(out, N->rows(), kMaxObjLine, [&](Eigen::Index i, char* p) {
      *p++ = 'v';
      *p++ = 'n';
      p = put_row(p, *N, i, precision);
      *p++ = '\n';
      return p;
    });
  const std::vector<int> order = obj_face_order(m, labels, groups);
  const int width =
      labels ? static_cast<int>(std::to_string(std::max(0, labels->count - 1)).size()) : 0;
  // A face line may follow an "o" and a "usemtl" line naming its kind.
  size_t longest_kind = 0;
  if (labels)
    for (const std::string& kind : labels->kinds)
      longest_kind = std::max(longest_kind, kind.size());
  const size_t max_row = kMaxObjLine + 2 * (longest_kind + static_cast<size_t>(width) + 16);
  append_rows(out, static_cast<Eigen::Index>(order.size()), max_row, [&](Eigen::Index i, char* p) {
    const int f = order[static_cast<size_t>(i)];
    if (labels) p = put_obj_group_lines(p, i, order, *labels, groups, width);
    *p++ = 'f';
    for (int k = 0; k < 3; ++k) {
      *p++ = ' ';
      p = put_int(p, m.F(f, k) + 1LL);
      if (N) {
        *p++ = '/';
        *p++ = '/';
        p = put_int(p, (normals.C ? normals.C->FN(f, k) : m.F(f, k)) + 1LL);
      }
    }
    *p++ = '\n';
    return p;
  });
}

void write_off(AtomicOutputFile& out, const TriMesh& m, const MatrixX3d* N, int precision) {
  out.append(std::string(N ? "NOFF\n" : "OFF\n") + std::to_string(m.V.rows()) + " " +
             std::to_string(m.F.rows()) + " 0\n");
  for (Eigen::Index i = 0; i < m.V.rows(); ++i) {
    char* p = put_row(out.cursor(), m.V, i, precision, false);
    if (N) p = put_row(p, *N, i, precision);
    *p++ = '\n';
    out.commit_bytes(p);
  }
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
    char* p = out.cursor();
    *p++ = '3';
    for (int k = 0; k < 3; ++k) {
      *p++ = ' ';
      p = put_int(p, m.F(f, k));
    }
    *p++ = '\n';
    out.commit_bytes(p);
  }
}

template <typename T>
inline char* put_le(char* out, T v) {
  std::memcpy(out, &v, sizeof(T));
  if (!host_is_little_endian()) std::reverse(out, out + sizeof(T));
  return out + sizeof(T);
}

void write_ply(AtomicOutputFile& out, const TriMesh& m, const MatrixX3d* N, bool binary,
               int precision, const ElementLabels* labels) {
  std::string header = "ply\nformat ";
  header += binary ? "binary_little_endian 1.0\n" : "ascii 1.0\n";
  if (labels) {
    header += "comment meshquilt: " + std::to_string(labels->count) + " elements\n";
    for (size_t k = 0; k < labels->kinds.size(); ++k) {
      header += "comment kind " + std::to_string(k) + " " + labels->kinds[k] + "\n";
      // The look other tools give the kind (kind_material): r g b metallic roughness.
      const KindMaterial m = kind_material(labels->kinds[k]);
      char buf[160];
      std::snprintf(buf, sizeof buf, "comment kind_material %zu %.4f %.4f %.4f %.3f %.3f\n", k, m.r,
                    m.g, m.b, m.metallic, m.roughness);
      header += buf;
    }
  }
  header += "element vertex " + std::to_string(m.V.rows()) + "\n";
  header += "property double x\nproperty double y\nproperty double z\n";
  if (N) header += "property double nx\nproperty double ny\nproperty double nz\n";
  if (labels) header += "property int element_id\nproperty int kind\n";
  header += "element face " + std::to_string(m.F.rows()) + "\n";
  header += "property list uchar int vertex_indices\nend_header\n";
  out.append(header);
  for (Eigen::Index i = 0; i < m.V.rows(); ++i) {
    char* p = out.cursor();
    const int e = labels ? labels->vertex_element[static_cast<size_t>(i)] : 0;
    const int kind = labels ? labels->element_kind[static_cast<size_t>(e)] : 0;
    if (binary) {
      for (int k = 0; k < 3; ++k) p = put_le(p, m.V(i, k));
      if (N)
        for (int k = 0; k < 3; ++k) p = put_le(p, (*N)(i, k));
      if (labels) {
        p = put_le(p, static_cast<std::int32_t>(e));
        p = put_le(p, static_cast<std::int32_t>(kind));
      }
    } else {
      p = put_row(p, m.V, i, precision, false);
      if (N) p = put_row(p, *N, i, precision);
      if (labels) {
        *p++ = ' ';
        p = put_int(p, e);
        *p++ = ' ';
        p = put_int(p, kind);
      }
      *p++ = '\n';
    }
    out.commit_bytes(p);
  }
  for (Eigen::Index f = 0; f < m.F.rows(); ++f) {
    char* p = out.cursor();
    if (binary) {
      *p++ = 3;
      for (int k = 0; k < 3; ++k) p = put_le(p, static_cast<std::int32_t>(m.F(f, k)));
    } else {
      *p++ = '3';
      for (int k = 0; k < 3; ++k) {
        *p++ = ' ';
        p = put_int(p, m.F(f, k));
      }
      *p++ = '\n';
    }
    out.commit_bytes(p);
  }
}

std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& ch : ext) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  return ext;
}

}  // namespace

MeshFormat mesh_format_from_path(const std::string& path) {
  const std::string ext = lower_extension(path);
  if (ext == ".obj") return MeshFormat::Obj;
  if (ext == ".ply") return MeshFormat::Ply;
  if (ext == ".off") return MeshFormat::Off;
  if (ext == ".glb") return MeshFormat::Glb;
  // A directory has no extension to judge: say what it is rather than "unknown format ''".
  std::error_code error;
  if (std::filesystem::is_directory(path, error))
    MQ_THROW(InvalidInput, path,
             ": is a directory, not a mesh file (expected a name ending in .obj, .ply, .off or, "
             "for output, .glb)");
  MQ_THROW(InvalidInput, path, ": unknown mesh format '", ext,
           "' (expected .obj, .ply, .off or, for output, .glb)");
}

TriMesh read_mesh(const std::string& path) {
  const MeshFormat format = mesh_format_from_path(path);
  return read_mesh_data(read_whole_file(path), format, path);
}

TriMesh read_mesh_data(const std::string& data, MeshFormat format, const std::string& path) {
  if (data.empty()) MQ_THROW(InvalidInput, path, ":1: empty file");
  switch (format) {
    case MeshFormat::Obj:
      return read_obj(path, data);
    case MeshFormat::Off:
      return read_off(path, data);
    case MeshFormat::Ply:
      return read_ply(path, data);
    case MeshFormat::Glb:
      MQ_THROW(InvalidInput, path, ": glTF is an output format here; read OBJ, PLY or OFF");
  }
  throw InternalError(path + ": unhandled mesh format");
}

void write_mesh(const std::string& path, const TriMesh& mesh, const WriteOptions& options) {
  const MeshFormat format = mesh_format_from_path(path);
  // Validate everything before touching the file system.
  for (Eigen::Index i = 0; i < mesh.V.rows(); ++i)
    if (!mesh.V.row(i).allFinite())
      MQ_THROW(InvalidInput, path, ": cannot write mesh: vertex ", i,
               " has a non-finite coordinate");
  const Eigen::Index nv = mesh.V.rows();
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      if (mesh.F(f, k) < 0 || mesh.F(f, k) >= nv)
        MQ_THROW(InvalidInput, path, ": cannot write mesh: face ", f, " has vertex index ",
                 mesh.F(f, k), " out of range (", nv, " vertices)");
  if (!mesh.kinds.empty()) {
    try {
      check_kinds(mesh);
    } catch (const InvalidInput& e) {
      MQ_THROW(InvalidInput, path, ": cannot write mesh: ", e.what());
    }
  }
  if (format == MeshFormat::Glb) {
    write_glb(path, mesh, options);
    return;
  }
  const bool per_vertex_file = mesh.N.rows() == nv && nv > 0;
  MatrixX3d computed;
  CornerNormals corners;
  const MatrixX3d* N = nullptr;
  ObjNormals obj_normals;
  if (options.write_normals) {
    if (per_vertex_file) {
      N = &mesh.N;
      obj_normals.Nv = N;
    } else if (format == MeshFormat::Obj) {
      corners = corner_normals(mesh.V, mesh.F, options.crease_degrees);
      obj_normals.C = &corners;
      N = &corners.N;
    } else {
      computed = vertex_normals(mesh.V, mesh.F);
      N = &computed;
    }
    for (Eigen::Index i = 0; i < N->rows(); ++i)
      if (!N->row(i).allFinite())
        MQ_THROW(InvalidInput, path, ": cannot write mesh: normal ", i, " is not finite");
  }
  ElementLabels labels;
  const bool elements = options.write_elements && format != MeshFormat::Off;
  if (elements) {
    labels = element_labels(mesh);
    labels.kinds = unique_kind_names(labels.kinds);
  }

  AtomicOutputFile out(path);
  switch (format) {
    case MeshFormat::Obj: {
      const std::string mtl = mtl_path_for(path);
      write_obj(out, mesh, obj_normals, options.precision, elements ? &labels : nullptr,
                options.groups, std::filesystem::path(mtl).filename().string());
      if (elements) {
        // The pair lands together (the .mtl's rename first): the OBJ never names a material
        // file that is not there, or one of another run's kinds (issue 28).
        AtomicOutputFile materials(mtl);
        write_mtl(materials, labels.kinds);
        commit_with(out, options.companion_path, options.companion_bytes, &materials);
        return;
      }
      break;
    }
    case MeshFormat::Off:
      write_off(out, mesh, N, options.precision);
      break;
    case MeshFormat::Ply:
      write_ply(out, mesh, N, options.binary, options.precision, elements ? &labels : nullptr);
      break;
    case MeshFormat::Glb:
      break;
  }
  commit_with(out, options.companion_path, options.companion_bytes);
}

}  // namespace mq
