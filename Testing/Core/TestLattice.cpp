// spaceskip::planLattice: image blocks laid on one lattice, their owned cells and padded copies.
#include "spaceskip/Lattice.h"

#include <gtest/gtest.h>

#include <algorithm>

namespace {

using spaceskip::LatticeBlock;
using spaceskip::LatticePlan;
using spaceskip::LatticeRequest;

// A block of points [x0, x1] x [y0, y1] x [z0, z1] of an image with spacing `s` and origin 0,
// given with its own extent starting at 0 (as a reader's piece) or at its place (`local` false).
LatticeBlock block(int x0, int x1, int y0, int y1, int z0, int z1, double s = 1.0, bool local = true) {
  LatticeBlock b;
  const int e[6] = {x0, x1, y0, y1, z0, z1};
  for (int a = 0; a < 3; ++a) {
    b.spacing[a] = s;
    b.firstPoint[a] = e[2 * a] * s;
    const int shift = local ? e[2 * a] : 0;
    b.extent[2 * a] = e[2 * a] - shift;
    b.extent[2 * a + 1] = e[2 * a + 1] - shift;
    b.ownCells[2 * a] = b.extent[2 * a];
    b.ownCells[2 * a + 1] = b.extent[2 * a + 1];
  }
  b.hasScalars = true;
  b.scalarType = 10;  // VTK_FLOAT
  return b;
}

// Every cell of `whole` (cells [lo, hi)) owned by exactly one drawing piece.
void expectPartition(const LatticePlan& plan, const int whole[6]) {
  for (int z = whole[4]; z < whole[5]; ++z) {
    for (int y = whole[2]; y < whole[3]; ++y) {
      for (int x = whole[0]; x < whole[1]; ++x) {
        int owners = 0;
        for (const auto& p : plan.pieces) {
          owners += p.draws && p.owned[0] <= x && x < p.owned[1] && p.owned[2] <= y &&
                    y < p.owned[3] && p.owned[4] <= z && z < p.owned[5];
        }
        ASSERT_EQ(owners, 1) << "cell " << x << " " << y << " " << z;
      }
    }
  }
}

TEST(Lattice, SharedFacesPartitionTheCells) {
  LatticeRequest req;
  req.blocks = {block(0, 8, 0, 15, 0, 15), block(8, 15, 0, 15, 0, 15)};
  const LatticePlan plan = spaceskip::planLattice(req);
  ASSERT_TRUE(plan.onLattice) << plan.why;
  const int whole[6] = {0, 15, 0, 15, 0, 15};
  EXPECT_TRUE(std::equal(whole, whole + 6, plan.wholeExtent));
  EXPECT_EQ(plan.pieces[1].points[0], 8);
  EXPECT_EQ(plan.pieces[0].owned[1], 8);
  EXPECT_FALSE(plan.pieces[0].padded);
  EXPECT_FALSE(plan.pieces[1].padded);
  expectPartition(plan, whole);
  for (int a = 0; a < 3; ++a) {
    EXPECT_DOUBLE_EQ(plan.origin[a], 0.0);
  }
}

TEST(Lattice, AGapIsOwnedByTheLowerBlockWhichIsPadded) {
  LatticeRequest req;
  req.blocks = {block(0, 7, 0, 15, 0, 15), block(8, 15, 0, 15, 0, 15)};
  const LatticePlan plan = spaceskip::planLattice(req);
  ASSERT_TRUE(plan.onLattice) << plan.why;
  EXPECT_EQ(plan.pieces[0].owned[1], 8);  // the gap cell [7, 8)
  EXPECT_TRUE(plan.pieces[0].padded);
  EXPECT_FALSE(plan.pieces[1].padded);
  // The neighbour's points first, its own last (they win).
  ASSERT_EQ(plan.pieces[0].copies.size(), 2u);
  EXPECT_EQ(plan.pieces[0].copies[0].block, 1u);
  EXPECT_EQ(plan.pieces[0].copies[1].block, 0u);
  EXPECT_EQ(plan.pieces[0].copies[0].box[0], 8);
  EXPECT_EQ(plan.pieces[0].copies[0].box[1], 8);
  const int whole[6] = {0, 15, 0, 15, 0, 15};
  expectPartition(plan, whole);
}

TEST(Lattice, ShadingLayersPadBothSides) {
  LatticeRequest req;
  req.layers = 1;
  req.blocks = {block(0, 8, 0, 15, 0, 15), block(8, 15, 0, 15, 0, 15)};
  const LatticePlan plan = spaceskip::planLattice(req);
  ASSERT_TRUE(plan.onLattice) << plan.why;
  EXPECT_TRUE(plan.pieces[0].padded);
  EXPECT_EQ(plan.pieces[0].need[1], 9);
  EXPECT_TRUE(plan.pieces[1].padded);
  EXPECT_EQ(plan.pieces[1].need[0], 7);
  EXPECT_EQ(plan.pieces[1].need[5], 15);  // clamped to the whole image
}

TEST(Lattice, GhostCellsAreLeftToTheirOwner) {
  LatticeRequest req;
  LatticeBlock a = block(0, 10, 0, 15, 0, 15), b = block(6, 15, 0, 15, 0, 15);
  a.ownCells[1] = 8;  // cells 8, 9 are ghosts (b's)
  b.ownCells[0] = 2;  // b's cells 6, 7 (local 0, 1) are ghosts (a's)
  req.blocks = {a, b};
  const LatticePlan plan = spaceskip::planLattice(req);
  ASSERT_TRUE(plan.onLattice) << plan.why;
  EXPECT_EQ(plan.pieces[0].owned[1], 8);
  EXPECT_EQ(plan.pieces[1].owned[0], 8);
  const int whole[6] = {0, 15, 0, 15, 0, 15};
  expectPartition(plan, whole);
}

TEST(Lattice, OffLatticeSaysWhy) {
  LatticeRequest req;
  req.blocks = {block(0, 8, 0, 15, 0, 15), block(8, 15, 0, 15, 0, 15, 1.5)};
  EXPECT_EQ(spaceskip::planLattice(req).why, "blocks of different spacing");
  req.blocks[1] = block(8, 15, 0, 15, 0, 15);
  req.blocks[1].firstPoint[0] += 0.5;
  EXPECT_EQ(spaceskip::planLattice(req).why, "block origins a fraction of a voxel apart");
  req.blocks[1] = block(4, 15, 0, 15, 0, 15);
  const LatticePlan overlap = spaceskip::planLattice(req);
  EXPECT_FALSE(overlap.onLattice);
  EXPECT_NE(overlap.why.find("overlap"), std::string::npos);
  req.blocks[1] = block(8, 15, 0, 15, 0, 15);
  req.blocks[1].scalarType = 11;
  EXPECT_EQ(spaceskip::planLattice(req).why, "blocks with different scalar types");
  req.blocks[1] = block(8, 8, 0, 15, 0, 15);
  EXPECT_EQ(spaceskip::planLattice(req).why, "a block one point thick");
}

TEST(Lattice, AnchoredWholeExtent) {
  LatticeRequest req;
  req.anchored = true;
  const int given[6] = {-4, 31, 0, 15, 0, 15};
  std::copy(given, given + 6, req.wholeExtent);
  req.wholeOrigin[0] = -4;  // the point of index -4 at x = -4: index 0 at x = 0
  // Blocks given in their own local extents, placed by their first points.
  req.blocks = {block(0, 8, 0, 15, 0, 15), block(8, 15, 0, 15, 0, 15)};
  LatticePlan plan = spaceskip::planLattice(req);
  ASSERT_TRUE(plan.onLattice) << plan.why;
  EXPECT_TRUE(std::equal(given, given + 6, plan.wholeExtent));
  EXPECT_DOUBLE_EQ(plan.origin[0], 0.0);
  EXPECT_EQ(plan.pieces[1].points[0], 8);
  req.wholeExtent[1] = 12;
  plan = spaceskip::planLattice(req);
  EXPECT_EQ(plan.why, "a block outside the whole extent given to the mapper");
}

TEST(Lattice, BlocksWithoutScalarsOrCellsDoNotDraw) {
  LatticeRequest req;
  LatticeBlock ghost = block(8, 15, 0, 15, 0, 15);
  ghost.hasOwnCells = false;
  req.blocks = {block(0, 8, 0, 15, 0, 15), ghost};
  LatticePlan plan = spaceskip::planLattice(req);
  ASSERT_TRUE(plan.onLattice) << plan.why;
  EXPECT_TRUE(plan.pieces[0].draws);
  EXPECT_FALSE(plan.pieces[1].draws);
  const int whole[6] = {0, 8, 0, 15, 0, 15};
  EXPECT_TRUE(std::equal(whole, whole + 6, plan.wholeExtent));
  req.blocks[0].hasScalars = false;
  EXPECT_EQ(spaceskip::planLattice(req).why, "no block with the drawn scalars");
}

TEST(Lattice, NearestOwnPointClamps) {
  spaceskip::LatticePiece p;
  const int pts[6] = {0, 7, 0, 15, 0, 15};
  std::copy(pts, pts + 6, p.points);
  const int ijk[3] = {8, -1, 5};
  int out[3];
  spaceskip::nearestOwnPoint(p, ijk, out);
  EXPECT_EQ(out[0], 7);
  EXPECT_EQ(out[1], 0);
  EXPECT_EQ(out[2], 5);
}

}  // namespace
