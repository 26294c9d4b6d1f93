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
#include "core/mesh/longest_edge_bisection.h"

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
  void put_local(const std::vector<int>& face, const MatrixX3d& bary,
                 const Eigen::VectorXd& height) {
    for (const int f : face) put(static_cast<std::int32_t>(f));
    put_rows(bary);
    for (Eigen::Index v = 0; v < height.size(); ++v) put(height(v));
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
  void get_local(int n, int faces, std::vector<int>& face, MatrixX3d& bary,
                 Eigen::VectorXd& height) {
    need(static_cast<std::size_t>(n) * 36, "local coordinates");
    face.resize(static_cast<std::size_t>(n));
    for (int& f : face) f = get_index(faces, "base face");
    bary = get_rows(n, "barycentric coordinate");
    height.resize(n);
    for (int v = 0; v < n; ++v) height(v) = get_finite("height");
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
  const SurfaceQuilt& q = saved.quilt;
  MQ_CHECK(static_cast<Eigen::Index>(q.input_vertex.size()) == q.input_base.V.rows() &&
               !q.input_vertex.empty(),
           InvalidInput,
           "the quilt cannot be saved: its base was simplified to a proxy (a base of over "
           "200,000 faces), whose vertices do not follow the base's; use --no-proxy");
  Writer w;
  w.bytes.append(kMagic, sizeof kMagic);
  w.put(kSavedQuiltVersion);
  w.put(saved.base.vertices);
  w.put(saved.base.faces);
  w.put(saved.base.connectivity);
  w.put(saved.min_coverage);
  w.put(saved.swatch_coverage);
  w.put_string(saved.origin);
  const QuiltEmbeddingOptions& e = saved.embedding;
  for (const bool b :
       {e.shell_map, e.optimize_stretch, e.remove_intersecting, e.shrink_to_fit, e.separate_rings})
    w.put(static_cast<std::uint8_t>(b));
  w.put(static_cast<std::uint64_t>(e.seed));
  w.put(q.shell_height);
  w.put_count(static_cast<Eigen::Index>(q.kinds.size()));
  for (const std::string& k : q.kinds) w.put_string(k);
  // The welded base: its vertices as vertices of the base given, its faces.
  w.put_count(static_cast<Eigen::Index>(q.input_vertex.size()));
  for (const int v : q.input_vertex) w.put(static_cast<std::int32_t>(v));
  w.put_faces(q.input_base.F);
  // The refinement (core/mesh/longest_edge_bisection): parents, corners, midpoints in order.
  w.put_count(static_cast<Eigen::Index>(q.refinement.parent.size()));
  for (size_t f = 0; f < q.refinement.parent.size(); ++f) {
    w.put(static_cast<std::int32_t>(q.refinement.parent[f]));
    for (int k = 0; k < 9; ++k) w.put(q.refinement.corners(static_cast<Eigen::Index>(f), k));
  }
  w.put_count(static_cast<Eigen::Index>(q.refinement.midpoints.size()));
  for (const auto& [a, b] : q.refinement.midpoints) {
    w.put(static_cast<std::int32_t>(a));
    w.put(static_cast<std::int32_t>(b));
  }
  w.put_count(q.base.V.rows());
  w.put_faces(q.base.F);
  w.put_count(static_cast<Eigen::Index>(q.elements.size()));
  for (const SurfaceElement& el : q.elements) {
    w.put(static_cast<std::int32_t>(el.kind));
    w.put_count(static_cast<Eigen::Index>(el.face.size()));
    w.put_faces(el.F);
    w.put_local(el.face, el.barycentric, el.height);
    w.put(static_cast<std::uint8_t>(el.flat.rows() > 0));
    w.put_rows(el.flat);
    w.put(static_cast<std::uint8_t>(!el.through_layout.face.empty()));
    w.put_local(el.through_layout.face, el.through_layout.barycentric, el.through_layout.height);
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

  SavedQuilt s;
  s.base.vertices = in.get<std::int64_t>();
  s.base.faces = in.get<std::int64_t>();
  s.base.connectivity = in.get<std::uint64_t>();
  if (s.base.vertices < 3 || s.base.vertices > std::numeric_limits<int>::max() ||
      s.base.faces < 1 || s.base.faces > std::numeric_limits<int>::max())
    in.fail("base of ", s.base.vertices, " vertices and ", s.base.faces, " faces");
  s.min_coverage = in.get_finite("coverage");
  s.swatch_coverage = in.get_finite("coverage");
  s.origin = in.get_string("origin");
  QuiltEmbeddingOptions& e = s.embedding;
  for (bool* b : {&e.shell_map, &e.optimize_stretch, &e.remove_intersecting, &e.shrink_to_fit,
                  &e.separate_rings}) {
    const auto v = in.get<std::uint8_t>();
    if (v > 1) in.fail("an option flag of ", int{v});
    *b = v == 1;
  }
  e.seed = in.get<std::uint64_t>();
  SurfaceQuilt& q = s.quilt;
  q.shell_height = in.get_finite("shell height");
  if (!(q.shell_height > 0)) in.fail("shell height ", q.shell_height);
  const int kinds = in.get_count(4, "kind names");
  for (int k = 0; k < kinds; ++k) q.kinds.push_back(in.get_string("kind name"));

  const int welded = in.get_count(4, "welded base vertices");
  if (welded < 3) in.fail("a welded base of ", welded, " vertices");
  q.input_vertex.resize(static_cast<size_t>(welded));
  for (int& v : q.input_vertex) v = in.get_index(static_cast<int>(s.base.vertices), "base vertex");
  q.input_base.F = in.get_faces(welded, "welded base face");
  const int input_faces = q.input_base.num_faces();
  if (input_faces < 1 || input_faces > s.base.faces) in.fail(input_faces, " welded base faces");

  Refinement& ref = q.refinement;
  const int refined_faces = in.get_count(76, "refined faces");
  ref.parent.resize(static_cast<size_t>(refined_faces));
  ref.corners.resize(refined_faces, 9);
  for (int f = 0; f < refined_faces; ++f) {
    ref.parent[static_cast<size_t>(f)] = in.get_index(input_faces, "parent face");
    for (int k = 0; k < 9; ++k) ref.corners(f, k) = in.get_finite("corner coordinate");
  }
  const int added = in.get_count(8, "midpoints");
  ref.midpoints.resize(static_cast<size_t>(added));
  for (int i = 0; i < added; ++i)
    for (int& v : ref.midpoints[static_cast<size_t>(i)])
      v = in.get_index(welded + i, "midpoint end");
  const int refined_vertices = in.get<std::int32_t>();
  if (refined_vertices != welded + added)
    in.fail(refined_vertices, " refined vertices for ", welded, " welded and ", added, " added");
  q.base.F = in.get_faces(refined_vertices, "refined face");
  const int base_faces = q.base.num_faces();
  if (refined_faces != 0 ? refined_faces != base_faces : (added != 0 || q.base.F != q.input_base.F))
    in.fail("the refinement does not match the refined base (", refined_faces, " and ", base_faces,
            " faces)");

  const int elements = in.get_count(14, "elements");
  q.elements.resize(static_cast<size_t>(elements));
  const int kind_end = std::max(kinds, 1);
  for (SurfaceElement& el : q.elements) {
    el.kind = in.get_index(kind_end, "element kind");
    const int nv = in.get_count(36, "element vertices");
    el.F = in.get_faces(nv, "element face");
    in.get_local(nv, base_faces, el.face, el.barycentric, el.height);
    const auto has_flat = in.get<std::uint8_t>();
    if (has_flat > 1) in.fail("a flag of ", int{has_flat});
    if (has_flat) el.flat = in.get_rows(nv, "flat shape");
    const auto has_layout = in.get<std::uint8_t>();
    if (has_layout > 1) in.fail("a flag of ", int{has_layout});
    if (has_layout)
      in.get_local(nv, base_faces, el.through_layout.face, el.through_layout.barycentric,
                   el.through_layout.height);
  }
  if (!in.at_end()) in.fail("bytes after the last element");
  return s;
}

void write_saved_quilt(const std::string& path, const SavedQuilt& saved) {
  write_file_atomically(path, serialize_saved_quilt(saved));
}

SavedQuilt read_saved_quilt(const std::string& path) {
  return parse_saved_quilt(read_input_file(path, "saved quilt"), path);
}

void place_on_base(SurfaceQuilt& quilt, const BaseFingerprint& expected, const TriMesh& base) {
  const BaseFingerprint got = fingerprint(base);
  MQ_CHECK(got.vertices == expected.vertices && got.faces == expected.faces, InvalidInput,
           "the base has ", got.vertices, " vertices and ", got.faces,
           " faces; the quilt was made on one of ", expected.vertices, " and ", expected.faces,
           " (embed needs the same mesh, its vertices moved)");
  MQ_CHECK(got.connectivity == expected.connectivity, InvalidInput,
           "the base's faces are not those the quilt was made on (same counts, other "
           "connectivity); embed needs the same mesh, its vertices moved");
  MQ_CHECK(base.V.allFinite(), InvalidInput, "the base has a vertex position that is not finite");
  MatrixX3d V(static_cast<Eigen::Index>(quilt.input_vertex.size()), 3);
  for (size_t v = 0; v < quilt.input_vertex.size(); ++v)
    V.row(static_cast<Eigen::Index>(v)) = base.V.row(quilt.input_vertex[v]);
  const auto refined =
      static_cast<int>(quilt.input_vertex.size() + quilt.refinement.midpoints.size());
  quilt.base.V = refine_positions(quilt.refinement, V, refined);
  quilt.input_base.V = std::move(V);
}

}  // namespace mq
