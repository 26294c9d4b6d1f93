#include "core/shell/saved_quilt.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <type_traits>
#include <vector>

#include "core/common/errors.h"
#include "core/common/fnv1a.h"
#include "core/mesh/atomic_file.h"
#include "core/mesh/input_file.h"

namespace mq {
namespace {

// The format is little-endian; so is every machine the tool is built for (x86-64, arm64).
static_assert(sizeof(double) == 8 && std::numeric_limits<double>::is_iec559);
constexpr char kMagic[8] = {'M', 'Q', 'Q', 'U', 'I', 'L', 'T', '\0'};

bool little_endian() {
  const std::uint32_t one = 1;
  unsigned char b;
  std::memcpy(&b, &one, 1);
  return b == 1;
}

class Writer {
 public:
  template <class T>
  void put(T v) {
    static_assert(std::is_arithmetic_v<T>);
    char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    bytes.append(b, sizeof(T));
  }
  void put_string(const std::string& s) {
    put(static_cast<std::uint32_t>(s.size()));
    bytes += s;
  }
  void put_count(Eigen::Index n) { put(static_cast<std::int32_t>(n)); }
  void put_faces(const MatrixX3i& F) {
    put_count(F.rows());
    for (Eigen::Index f = 0; f < F.rows(); ++f)
      for (int k = 0; k < 3; ++k) put(static_cast<std::int32_t>(F(f, k)));
  }
  void put_rows(const MatrixX3d& X) {  // #rows known to the reader
    for (Eigen::Index r = 0; r < X.rows(); ++r)
      for (int k = 0; k < 3; ++k) put(X(r, k));
  }
  std::string bytes;
};

class Reader {
 public:
  Reader(std::string_view bytes, const std::string& name) : bytes_(bytes), name_(name) {}

  template <class T>
  T get() {
    need(sizeof(T), "");
    T v;
    std::memcpy(&v, bytes_.data() + at_, sizeof(T));
    at_ += sizeof(T);
    return v;
  }
  double get_finite(const char* what) {
    const double v = get<double>();
    if (!std::isfinite(v)) fail(what, " is not finite");
    return v;
  }
  // A count of items of `item_bytes` each, checked against the bytes left before anything is
  // allocated for them.
  int get_count(std::size_t item_bytes, const char* what) {
    const std::int32_t n = get<std::int32_t>();
    if (n < 0) fail("negative count of ", what);
    need(static_cast<std::size_t>(n) * item_bytes, what);
    return n;
  }
  int get_index(int end, const char* what) {
    const std::int32_t i = get<std::int32_t>();
    if (i < 0 || i >= end) fail(what, " ", i, " out of range [0, ", end, ")");
    return i;
  }
  std::string get_string(const char* what) {
    const auto n = get<std::uint32_t>();
    need(n, what);
    std::string s(bytes_.substr(at_, n));
    at_ += n;
    return s;
  }
  MatrixX3i get_faces(int vertices, const char* what) {
    const int n = get_count(12, what);
    MatrixX3i F(n, 3);
    for (int f = 0; f < n; ++f)
      for (int k = 0; k < 3; ++k) F(f, k) = get_index(vertices, what);
    return F;
  }
  MatrixX3d get_rows(int n, const char* what) {
    need(static_cast<std::size_t>(n) * 24, what);
    MatrixX3d X(n, 3);
    for (int r = 0; r < n; ++r)
      for (int k = 0; k < 3; ++k) X(r, k) = get_finite(what);
    return X;
  }
  bool at_end() const { return at_ == bytes_.size(); }
  std::size_t position() const { return at_; }

  template <class... Args>
  [[noreturn]] void fail(const Args&... args) const {
    MQ_THROW(InvalidInput, name_, ": not a valid saved quilt: ", args..., " (at byte ", at_, ")");
  }

 private:
  void need(std::size_t n, const char* what) const {
    if (n > bytes_.size() - at_)
      MQ_THROW(InvalidInput, name_, ": saved quilt truncated", *what ? " in " : "", what,
               " (at byte ", at_, " of ", bytes_.size(), ")");
  }
  std::string_view bytes_;
  const std::string& name_;
  std::size_t at_ = 0;
};

std::uint64_t checksum(std::string_view bytes) {
  std::uint64_t h = kFnv1aOffset;
  fnv1a(h, bytes.data(), bytes.size());
  return h;
}

}  // namespace

BaseFingerprint fingerprint(const TriMesh& base) {
  BaseFingerprint fp;
  fp.vertices = base.num_vertices();
  fp.faces = base.num_faces();
  std::uint64_t h = kFnv1aOffset;
  for (Eigen::Index f = 0; f < base.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const auto i = static_cast<std::int32_t>(base.F(f, k));
      fnv1a(h, &i, sizeof i);
    }
  fp.connectivity = h;
  return fp;
}

std::string serialize_saved_quilt(const SavedQuilt& saved) {
  MQ_CHECK(little_endian(), InternalError, "saved quilts are written on little-endian machines");
  const SavedQuiltHeader& h = saved.header;
  Writer w;
  w.bytes.append(kMagic, sizeof kMagic);
  w.put(kSavedQuiltVersion);
  w.put(h.base.vertices);
  w.put(h.base.faces);
  w.put(h.base.connectivity);
  w.put(h.shell_height);
  w.put_string(h.origin);
  // The welded base: its vertices as vertices of the base given, at rest; its faces.
  w.put_count(static_cast<Eigen::Index>(saved.input_vertex.size()));
  for (const int v : saved.input_vertex) w.put(static_cast<std::int32_t>(v));
  w.put_rows(saved.base.V);
  w.put_faces(saved.base.F);
  // The output at rest, its kinds, and each vertex's prism coordinates.
  w.put_count(saved.output.V.rows());
  w.put_rows(saved.output.V);
  w.put_faces(saved.output.F);
  w.put_count(static_cast<Eigen::Index>(saved.output.kinds.size()));
  for (const std::string& k : saved.output.kinds) w.put_string(k);
  w.put_count(static_cast<Eigen::Index>(saved.output.face_kind.size()));
  for (const int k : saved.output.face_kind) w.put(static_cast<std::int32_t>(k));
  for (int v = 0; v < saved.coords.size(); ++v) {
    w.put(static_cast<std::int32_t>(saved.coords.face(v)));
    for (int k = 0; k < 3; ++k) w.put(saved.coords.bary(v, k));
    w.put(saved.coords.height(v));
  }
  w.put(checksum(w.bytes));
  return std::move(w.bytes);
}

SavedQuilt parse_saved_quilt(std::string_view bytes, const std::string& name) {
  MQ_CHECK(little_endian(), InternalError, "saved quilts are read on little-endian machines");
  MQ_CHECK(bytes.size() >= sizeof kMagic && std::memcmp(bytes.data(), kMagic, sizeof kMagic) == 0,
           InvalidInput, name, ": not a saved quilt (no MQQUILT header)");
  Reader r(bytes, name);
  r.get<std::uint64_t>();  // the magic
  const auto version = r.get<std::uint32_t>();
  MQ_CHECK(version == kSavedQuiltVersion, InvalidInput, name, ": saved quilt of format version ",
           version, "; this meshquilt reads version ", kSavedQuiltVersion);
  MQ_CHECK(bytes.size() >= r.position() + 8, InvalidInput, name, ": saved quilt truncated (",
           bytes.size(), " bytes)");
  std::uint64_t stored;
  std::memcpy(&stored, bytes.data() + bytes.size() - 8, 8);
  MQ_CHECK(stored == checksum(bytes.substr(0, bytes.size() - 8)), InvalidInput, name,
           ": saved quilt truncated or corrupted (its checksum does not match)");
  Reader in(bytes.substr(0, bytes.size() - 8), name);
  in.get<std::uint64_t>();
  in.get<std::uint32_t>();

  SavedQuilt saved;
  SavedQuiltHeader& h = saved.header;
  h.base.vertices = in.get<std::int64_t>();
  h.base.faces = in.get<std::int64_t>();
  h.base.connectivity = in.get<std::uint64_t>();
  if (h.base.vertices < 3 || h.base.vertices > std::numeric_limits<int>::max() ||
      h.base.faces < 1 || h.base.faces > std::numeric_limits<int>::max())
    in.fail("a base of ", h.base.vertices, " vertices and ", h.base.faces, " faces");
  h.shell_height = in.get_finite("shell height");
  if (!(h.shell_height > 0)) in.fail("shell height ", h.shell_height);
  h.origin = in.get_string("origin");

  const int welded = in.get_count(28, "welded base vertices");
  if (welded < 3) in.fail("a welded base of ", welded, " vertices");
  saved.input_vertex.resize(static_cast<size_t>(welded));
  for (int& v : saved.input_vertex)
    v = in.get_index(static_cast<int>(h.base.vertices), "base vertex");
  saved.base.V = in.get_rows(welded, "welded base position");
  saved.base.F = in.get_faces(welded, "welded base face");
  const int base_faces = saved.base.num_faces();
  if (base_faces < 1 || base_faces > h.base.faces) in.fail(base_faces, " welded base faces");

  const int nv = in.get_count(24 + 36, "output vertices");
  saved.output.V = in.get_rows(nv, "output position");
  saved.output.F = in.get_faces(nv, "output face");
  const int kinds = in.get_count(4, "kind names");
  for (int k = 0; k < kinds; ++k) saved.output.kinds.push_back(in.get_string("kind name"));
  const int face_kinds = in.get_count(4, "face kinds");
  if (face_kinds != 0 && face_kinds != saved.output.num_faces())
    in.fail(face_kinds, " face kinds for ", saved.output.num_faces(), " faces");
  saved.output.face_kind.resize(static_cast<size_t>(face_kinds));
  for (int& k : saved.output.face_kind) k = in.get_index(std::max(kinds, 1), "face kind");
  saved.coords.face.resize(nv);
  saved.coords.bary.resize(nv, 3);
  saved.coords.height.resize(nv);
  for (int v = 0; v < nv; ++v) {
    saved.coords.face(v) = in.get_index(base_faces, "base face");
    for (int k = 0; k < 3; ++k) saved.coords.bary(v, k) = in.get_finite("barycentric coordinate");
    saved.coords.height(v) = in.get_finite("height");
  }
  if (!in.at_end()) in.fail("bytes after the last vertex");
  return saved;
}

void write_saved_quilt(const std::string& path, const SavedQuilt& saved) {
  write_file_atomically(path, serialize_saved_quilt(saved));
}

SavedQuilt read_saved_quilt(const std::string& path) {
  return parse_saved_quilt(read_input_file(path, "saved quilt"), path);
}

MatrixX3d welded_positions(const SavedQuilt& saved, const TriMesh& base) {
  const BaseFingerprint got = fingerprint(base), expected = saved.header.base;
  MQ_CHECK(got.vertices == expected.vertices && got.faces == expected.faces, InvalidInput,
           "the base has ", got.vertices, " vertices and ", got.faces,
           " faces; the quilt was made on one of ", expected.vertices, " and ", expected.faces,
           " (embed needs the same mesh, its vertices moved)");
  MQ_CHECK(got.connectivity == expected.connectivity, InvalidInput,
           "the base's faces are not those the quilt was made on (same counts, other "
           "connectivity); embed needs the same mesh, its vertices moved");
  MQ_CHECK(base.V.allFinite(), InvalidInput, "the base has a vertex position that is not finite");
  MatrixX3d V(static_cast<Eigen::Index>(saved.input_vertex.size()), 3);
  for (size_t v = 0; v < saved.input_vertex.size(); ++v)
    V.row(static_cast<Eigen::Index>(v)) = base.V.row(saved.input_vertex[v]);
  return V;
}

}  // namespace mq
