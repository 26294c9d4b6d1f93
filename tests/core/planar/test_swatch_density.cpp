// The faces per area of a swatch's pattern (core/planar/swatch_density) on generated lattices
// whose density is known exactly: the swatch's box, border and overhang must not change it.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/planar/quilt_elements.h"
#include "core/planar/swatch_density.h"

namespace mq {
namespace {

// A closed box of sides (sx, sy, sz) with its minimum corner at c (12 faces).
void add_box(TriMesh& m, const Vector3d& c, double sx, double sy, double sz) {
  const Eigen::Index base = m.V.rows();
  m.V.conservativeResize(base + 8, 3);
  for (int i = 0; i < 8; ++i)
    m.V.row(base + i) = c + Vector3d((i & 1) * sx, ((i >> 1) & 1) * sy, ((i >> 2) & 1) * sz);
  static const int kFaces[12][3] = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6},
                                    {0, 1, 4}, {1, 5, 4}, {2, 6, 3}, {3, 6, 7},
                                    {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  const Eigen::Index f0 = m.F.rows();
  m.F.conservativeResize(f0 + 12, 3);
  for (int f = 0; f < 12; ++f)
    for (int k = 0; k < 3; ++k) m.F(f0 + f, k) = static_cast<int>(base) + kFaces[f][k];
}

TriMesh empty_mesh() {
  TriMesh m;
  m.V.resize(0, 3);
  m.F.resize(0, 3);
  return m;
}

// Boxes of side `side` on a rows x cols lattice with basis (p, 0) and (shift, q).
TriMesh box_lattice(int rows, int cols, double p, double q, double shift, double side) {
  TriMesh m = empty_mesh();
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c)
      add_box(m, Vector3d(c * p + (r % 2) * shift, r * q, 0), side, side, 0.1);
  return m;
}

TEST(SwatchDensity, SquareLatticeIsExactWhateverTheOverhang) {
  // Boxes smaller and larger than the spacing (gaps, or overlapping footprints as rings have):
  // the swatch's box is then 0.56-2.3 times the pattern's area per element, the density the same.
  for (const double side : {0.3, 0.9, 1.6})
    for (const auto& [rows, cols] : {std::pair{3, 3}, std::pair{4, 6}, std::pair{7, 5}}) {
      const PreparedSwatch s = prepare_swatch(box_lattice(rows, cols, 1.0, 1.0, 0.0, side));
      SCOPED_TRACE(testing::Message() << rows << " x " << cols << ", side " << side);
      const SwatchFaceDensity d = swatch_face_density(s);
      EXPECT_NEAR(d.compact, 12.0, 1e-9);
      EXPECT_EQ(d.along_x + d.along_y, 0.0);
    }
}

TEST(SwatchDensity, ShiftedRowsAndRectangularCells) {
  // Rows shifted by half a cell (a centred lattice, as 4-in-1 chain mail): area per box p * q.
  const PreparedSwatch s = prepare_swatch(box_lattice(5, 6, 1.5, 0.8, 0.75, 0.5));
  EXPECT_NEAR(swatch_face_density(s).compact, 12.0 / (1.5 * 0.8), 1e-9);
}

TEST(SwatchDensity, TwoKindsOfElementOnOneLattice) {
  // A box at every lattice point and a smaller one at every cell's centre (flat rings and
  // their connectors): both per cell. Centres of the second set lie inside the first's hull.
  TriMesh m = box_lattice(5, 5, 1.0, 1.0, 0.0, 0.4);
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) add_box(m, Vector3d(c + 0.6, r + 0.6, 0), 0.2, 0.2, 0.1);
  const PreparedSwatch s = prepare_swatch(m);
  // The hull holds 4 x 4 cells: 16 of each kind, counted exactly; the density is 24 per cell.
  EXPECT_NEAR(swatch_face_density(s).compact, 24.0, 1e-9);
}

TEST(SwatchDensity, ThreadsAndLoneElementsCountOverTheSwatchBox) {
  // Threads run the swatch's length: no lattice of centres, faces over the box, by direction.
  TriMesh threads = empty_mesh();
  for (int i = 0; i < 4; ++i) add_box(threads, Vector3d(0, i * 1.0, 0), 8.0, 0.3, 0.1);
  add_box(threads, Vector3d(2, -1, 0), 0.3, 5.0, 0.1);  // one across them, along y
  const SwatchFaceDensity t = swatch_face_density(prepare_swatch(threads));
  EXPECT_NEAR(t.along_x, 48.0 / (8.0 * 5.0), 1e-9);
  EXPECT_NEAR(t.along_y, 12.0 / (8.0 * 5.0), 1e-9);
  EXPECT_EQ(t.compact, 0.0);
  // One element spans the swatch: over the box. Centres in a row (no area): compact, over it.
  TriMesh one = empty_mesh();
  add_box(one, Vector3d::Zero(), 1.0, 2.0, 0.1);
  const SwatchFaceDensity o = swatch_face_density(prepare_swatch(one));
  EXPECT_NEAR(o.compact + o.along_x + o.along_y, 12.0 / 2.0, 1e-9);
  TriMesh row = box_lattice(1, 5, 1.0, 1.0, 0.0, 0.5);
  add_box(row, Vector3d(5.5, 0, 0), 0.3, 2.0, 0.1);  // a bar the swatch's height: not compact
  const SwatchFaceDensity r = swatch_face_density(prepare_swatch(row));
  EXPECT_NEAR(r.compact, 60.0 / (5.8 * 2.0), 1e-9);
  EXPECT_NEAR(r.along_y, 12.0 / (5.8 * 2.0), 1e-9);
}

}  // namespace
}  // namespace mq
