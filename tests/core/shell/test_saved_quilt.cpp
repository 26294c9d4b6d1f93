// The saved-quilt format (issue 25): what is written reads back equal, and a truncated,
// corrupted or mismatched file is refused in one line, never read into something unsafe.
#include <gtest/gtest.h>

#include "core/common/errors.h"
#include "core/shell/saved_quilt.h"
#include "tests/test_support.h"

namespace mq {
namespace {

// A small quilt by hand: a 3 x 3 grid base, two tetrahedra over it.
SavedQuilt small_quilt() {
  SavedQuilt q;
  const TriMesh grid = test::plane_grid(1.0, 1.0, 3, 3);
  q.header.base = fingerprint(grid);
  q.header.shell_height = 0.1;
  q.header.origin = "a test";
  for (int v = 0; v < grid.num_vertices(); ++v) q.input_vertex.push_back(v);
  q.base.V = grid.V;
  q.base.F = grid.F;
  q.output.V.resize(8, 3);
  q.output.F.resize(8, 3);
  for (int e = 0; e < 2; ++e) {
    const double x = 0.25 + 0.5 * e;
    q.output.V.middleRows(4 * e, 4) << x, 0.5, 0.01, x + 0.1, 0.5, 0.01, x, 0.6, 0.01, x, 0.5, 0.08;
    q.output.F.middleRows(4 * e, 4) << 0, 2, 1, 0, 1, 3, 1, 2, 3, 0, 3, 2;
    q.output.F.middleRows(4 * e, 4).array() += 4 * e;
  }
  q.output.kinds = {"ring", "leaf"};
  q.output.face_kind = {0, 0, 0, 0, 1, 1, 1, 1};
  q.coords.face = Eigen::VectorXi::Constant(8, 4);
  q.coords.bary = MatrixX3d::Constant(8, 3, 1.0 / 3);
  q.coords.height = Eigen::VectorXd::Constant(8, 0.02);
  return q;
}

TEST(SavedQuilt, ReadsBackWhatWasWritten) {
  const SavedQuilt q = small_quilt();
  const std::string bytes = serialize_saved_quilt(q);
  const SavedQuilt r = parse_saved_quilt(bytes, "q.mqq");
  EXPECT_EQ(r.header.base, q.header.base);
  EXPECT_EQ(r.header.shell_height, q.header.shell_height);
  EXPECT_EQ(r.header.origin, q.header.origin);
  EXPECT_EQ(r.input_vertex, q.input_vertex);
  EXPECT_EQ(r.base.V, q.base.V);
  EXPECT_EQ(r.base.F, q.base.F);
  EXPECT_EQ(r.output.V, q.output.V);
  EXPECT_EQ(r.output.F, q.output.F);
  EXPECT_EQ(r.output.kinds, q.output.kinds);
  EXPECT_EQ(r.output.face_kind, q.output.face_kind);
  EXPECT_EQ(r.coords.face, q.coords.face);
  EXPECT_EQ(r.coords.bary, q.coords.bary);
  EXPECT_EQ(r.coords.height, q.coords.height);
  EXPECT_EQ(serialize_saved_quilt(r), bytes);
}

TEST(SavedQuilt, TruncatedOrCorruptedFilesAreRefusedInOneLine) {
  const std::string bytes = serialize_saved_quilt(small_quilt());
  for (size_t n = 0; n < bytes.size(); n += 7) {
    try {
      parse_saved_quilt(bytes.substr(0, n), "q.mqq");
      ADD_FAILURE() << "a quilt cut at byte " << n << " was read";
    } catch (const InvalidInput& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.find('\n'), std::string::npos);
      EXPECT_EQ(what.rfind("q.mqq: ", 0), 0u) << what;
    }
  }
  for (size_t at = 0; at < bytes.size(); at += 5) {
    std::string bad = bytes;
    bad[at] = static_cast<char>(bad[at] ^ 0x40);
    EXPECT_THROW(parse_saved_quilt(bad, "q.mqq"), InvalidInput) << "byte " << at;
  }
  EXPECT_THROW(parse_saved_quilt(bytes + "x", "q.mqq"), InvalidInput);
  EXPECT_THROW(parse_saved_quilt("OFF\n3 1 0\n", "q.mqq"), InvalidInput);
}

TEST(SavedQuilt, OnlyTheSameBaseMovedIsAccepted) {
  const SavedQuilt q = small_quilt();
  TriMesh base = test::plane_grid(1.0, 1.0, 3, 3);
  base.V.col(2).array() += 0.5;  // moved: accepted, its positions taken
  EXPECT_EQ(welded_positions(q, base), base.V);
  TriMesh other = base;
  std::swap(other.F(0, 1), other.F(0, 2));  // same counts, other faces
  EXPECT_THROW(welded_positions(q, other), InvalidInput);
  EXPECT_THROW(welded_positions(q, test::plane_grid(1.0, 1.0, 4, 3)), InvalidInput);
  base.V(0, 0) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(welded_positions(q, base), InvalidInput);
}

}  // namespace
}  // namespace mq
