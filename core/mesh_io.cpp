#include "core/mesh_io.h"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "core/errors.h"

namespace mq {
namespace {

// ---------------------------------------------------------------------------------------------
// Whole-file input and a line-aware text cursor.

std::string read_whole_file(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    MQ_THROW(InvalidInput, path, ": cannot read mesh: is a directory");
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) MQ_THROW(InvalidInput, path, ": cannot open mesh file: ", std::strerror(errno));
  std::string data;
  char chunk[1 << 16];
  if (std::fseek(f, 0, SEEK_END) == 0) {
    const long size = std::ftell(f);
    if (size > 0) data.reserve(static_cast<size_t>(size));
    std::fseek(f, 0, SEEK_SET);
  }
  size_t n = 0;
  while ((n = std::fread(chunk, 1, sizeof(chunk), f)) > 0) data.append(chunk, n);
  const bool failed = std::ferror(f) != 0;
  std::fclose(f);
  if (failed) MQ_THROW(InvalidInput, path, ": cannot read mesh file");
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
    throw InvalidInput(path_ + ":" + std::to_string(line_) + ": " + message);
  }

  bool eof() const { return p_ >= end_; }
  char peek() const { return p_ < end_ ? *p_ : '\0'; }
  char peek(int k) const { return p_ + k < end_ ? p_[k] : '\0'; }
  void advance(int k) { p_ += k; }
  int line() const { return line_; }

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

TriMesh read_obj(const std::string& path, const std::string& data) {
  TextCursor c(path, data.data(), data.data() + data.size());
  std::vector<double> V, N;
  std::vector<int> F, FN;  // FN: normal index per triangle corner, -1 when absent
  std::vector<std::pair<int, int>> corners;
  V.reserve(data.size() / 16);
  F.reserve(data.size() / 8);
  bool all_corners_have_normals = true;

  while (!c.eof()) {
    c.skip_blanks();
    const char c0 = c.peek(), c1 = c.peek(1);
    if (c0 == 'v' && is_blank(c1)) {
      c.advance(1);
      for (int k = 0; k < 3; ++k) V.push_back(c.read_double("vertex coordinate"));
    } else if (c0 == 'v' && c1 == 'n' && is_blank(c.peek(2))) {
      c.advance(2);
      for (int k = 0; k < 3; ++k) N.push_back(c.read_double("normal coordinate"));
    } else if (c0 == 'f' && is_blank(c1)) {
      c.advance(1);
      corners.clear();
      const long long nv = static_cast<long long>(V.size() / 3);
      const long long nn = static_cast<long long>(N.size() / 3);
      for (;;) {
        c.skip_blanks();
        if (c.at_eol()) break;
        const long long vi = c.read_int("vertex index", '/');
        long long ni = 0;
        if (c.peek() == '/') {
          c.advance(1);
          if (c.peek() != '/') {
            if (!is_space(c.peek()) && c.peek() != '\0') c.read_int("texture index", '/');
          }
          if (c.peek() == '/') {
            c.advance(1);
            ni = c.read_int("normal index");
          }
        }
        const long long v = vi > 0 ? vi - 1 : nv + vi;
        if (vi == 0 || v < 0 || v >= nv)
          c.fail("vertex index " + std::to_string(vi) + " out of range (" + std::to_string(nv) +
                 " vertices defined so far)");
        int n = -1;
        if (ni != 0) {
          const long long nn_idx = ni > 0 ? ni - 1 : nn + ni;
          if (nn_idx < 0 || nn_idx >= nn)
            c.fail("normal index " + std::to_string(ni) + " out of range (" + std::to_string(nn) +
                   " normals defined so far)");
          n = static_cast<int>(nn_idx);
        }
        corners.emplace_back(static_cast<int>(v), n);
      }
      if (corners.size() < 3)
        c.fail("face with " + std::to_string(corners.size()) + " vertices (need at least 3)");
      for (size_t i = 1; i + 1 < corners.size(); ++i) {
        for (size_t k : {size_t(0), i, i + 1}) {
          F.push_back(corners[k].first);
          FN.push_back(corners[k].second);
          all_corners_have_normals &= corners[k].second >= 0;
        }
      }
    }
    // Everything else (vt, g, o, s, usemtl, mtllib, l, comments) and trailing values such as
    // the optional w or vertex colours are ignored.
    c.skip_line();
  }
  if (F.empty()) c.fail("no faces");

  TriMesh m = make_mesh(V, F);
  // Per-vertex normals only when each vertex is always paired with the same normal.
  if (!N.empty() && all_corners_have_normals) {
    std::vector<int> vertex_normal(V.size() / 3, -1);
    bool consistent = true;
    for (size_t i = 0; i < F.size() && consistent; ++i) {
      int& slot = vertex_normal[static_cast<size_t>(F[i])];
      if (slot < 0) slot = FN[i];
      consistent = slot == FN[i];
    }
    consistent &= std::find(vertex_normal.begin(), vertex_normal.end(), -1) == vertex_normal.end();
    if (consistent) {
      m.N.resize(m.V.rows(), 3);
      for (Eigen::Index v = 0; v < m.V.rows(); ++v)
        for (int k = 0; k < 3; ++k)
          m.N(v, k) = N[3 * static_cast<size_t>(vertex_normal[static_cast<size_t>(v)]) + k];
    }
  }
  return m;
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
  if (h.rfind("C", 0) == 0) h = h.substr(1);
  if (h.rfind("N", 0) == 0) {
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
  MQ_THROW(InvalidInput, path, ": unknown mesh format '", ext, "' (expected .obj, .ply or .off)");
}

TriMesh read_mesh(const std::string& path) {
  const MeshFormat format = mesh_format_from_path(path);
  const std::string data = read_whole_file(path);
  switch (format) {
    case MeshFormat::Obj:
      return read_obj(path, data);
    case MeshFormat::Off:
      return read_off(path, data);
    case MeshFormat::Ply:
      break;
  }
  MQ_THROW(InvalidInput, path, ": PLY reading not implemented yet");
}

void write_mesh(const std::string& path, const TriMesh&, const WriteOptions&) {
  mesh_format_from_path(path);
  MQ_THROW(InternalError, path, ": writing not implemented yet");
}

}  // namespace mq
