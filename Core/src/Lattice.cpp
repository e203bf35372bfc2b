// spaceskip::planLattice: image blocks laid on one voxel lattice (see Lattice.h).
#include "spaceskip/Lattice.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace spaceskip {

namespace {

using Box = std::array<int, 6>;

bool inverse3(const double m[9], double inv[9]) {
  const double c0 = m[4] * m[8] - m[5] * m[7];
  const double c1 = m[5] * m[6] - m[3] * m[8];
  const double c2 = m[3] * m[7] - m[4] * m[6];
  const double det = m[0] * c0 + m[1] * c1 + m[2] * c2;
  if (det == 0) {
    return false;
  }
  const double r = 1.0 / det;
  inv[0] = c0 * r;
  inv[1] = (m[2] * m[7] - m[1] * m[8]) * r;
  inv[2] = (m[1] * m[5] - m[2] * m[4]) * r;
  inv[3] = c1 * r;
  inv[4] = (m[0] * m[8] - m[2] * m[6]) * r;
  inv[5] = (m[2] * m[3] - m[0] * m[5]) * r;
  inv[6] = c2 * r;
  inv[7] = (m[1] * m[6] - m[0] * m[7]) * r;
  inv[8] = (m[0] * m[4] - m[1] * m[3]) * r;
  return true;
}

// The lattice's geometry: the first block's spacing and orientation; its index space the whole
// image's when anchored (its point wholeExtent[lo] at wholeOrigin), else the first block's.
void setGeometry(const LatticeRequest& req, LatticePlan& plan) {
  const LatticeBlock& first = req.blocks[0];
  std::copy(first.spacing, first.spacing + 3, plan.spacing);
  std::copy(first.direction, first.direction + 9, plan.direction);
  // The first block's origin (its point of index 0, 0, 0).
  const double* d = first.direction;
  double shift[3] = {first.extent[0] * first.spacing[0], first.extent[2] * first.spacing[1],
                     first.extent[4] * first.spacing[2]};
  const int* given = req.wholeExtent;
  if (req.anchored) {
    std::copy(req.wholeOrigin, req.wholeOrigin + 3, plan.origin);
    shift[0] = given[0] * first.spacing[0];
    shift[1] = given[2] * first.spacing[1];
    shift[2] = given[4] * first.spacing[2];
  } else {
    std::copy(first.firstPoint, first.firstPoint + 3, plan.origin);
  }
  for (int a = 0; a < 3; ++a) {
    plan.origin[a] -= d[3 * a] * shift[0] + d[3 * a + 1] * shift[1] + d[3 * a + 2] * shift[2];
  }
}

// Places each block on the lattice (points and own cells in its index space); false with the
// reason when a block is off it.
bool placeBlocks(const LatticeRequest& req, LatticePlan& plan, std::vector<Box>& pts,
                 std::vector<Box>& cells) {
  const size_t n = req.blocks.size();
  double inv[9];
  if (!inverse3(plan.direction, inv)) {
    plan.why = "a singular direction matrix";
    return false;
  }
  for (size_t i = 0; i < n; ++i) {
    const LatticeBlock& b = req.blocks[i];
    for (int a = 0; a < 3; ++a) {
      if (!(std::abs(b.spacing[a] - plan.spacing[a]) <= 1e-6 * std::abs(plan.spacing[a]))) {
        plan.why = "blocks of different spacing";
        return false;
      }
    }
    for (int k = 0; k < 9; ++k) {
      if (std::abs(b.direction[k] - plan.direction[k]) > 1e-9) {
        plan.why = "blocks of different orientation";
        return false;
      }
    }
    const double rel[3] = {b.firstPoint[0] - plan.origin[0], b.firstPoint[1] - plan.origin[1],
                           b.firstPoint[2] - plan.origin[2]};
    plan.pieces[i].draws = b.hasOwnCells && b.hasScalars;
    for (int a = 0; a < 3; ++a) {
      if (b.extent[2 * a] == b.extent[2 * a + 1]) {
        plan.why = "a block one point thick";
        return false;
      }
      const double idx =
          (inv[3 * a] * rel[0] + inv[3 * a + 1] * rel[1] + inv[3 * a + 2] * rel[2]) / plan.spacing[a];
      const double r = std::round(idx);
      if (!(std::abs(idx - r) <= 1e-3)) {
        plan.why = "block origins a fraction of a voxel apart";
        return false;
      }
      const int shift = static_cast<int>(r) - b.extent[2 * a];
      pts[i][2 * a] = b.extent[2 * a] + shift;
      pts[i][2 * a + 1] = b.extent[2 * a + 1] + shift;
      cells[i][2 * a] = b.ownCells[2 * a] + shift;
      cells[i][2 * a + 1] = b.ownCells[2 * a + 1] + shift;
    }
  }
  return true;
}

// The whole image: the union of the drawing blocks' points, or the anchored extent holding them.
bool wholeImage(const LatticeRequest& req, LatticePlan& plan, const std::vector<Box>& pts) {
  bool any = false;
  int* whole = plan.wholeExtent;
  const LatticeBlock* first = nullptr;
  for (size_t i = 0; i < pts.size(); ++i) {
    if (!plan.pieces[i].draws) {
      continue;
    }
    const LatticeBlock& b = req.blocks[i];
    if (first && (b.scalarType != first->scalarType || b.components != first->components)) {
      plan.why = "blocks with different scalar types";
      return false;
    }
    first = first ? first : &b;
    for (int a = 0; a < 3; ++a) {
      whole[2 * a] = any ? std::min(whole[2 * a], pts[i][2 * a]) : pts[i][2 * a];
      whole[2 * a + 1] = any ? std::max(whole[2 * a + 1], pts[i][2 * a + 1]) : pts[i][2 * a + 1];
    }
    any = true;
  }
  if (!any) {
    plan.why = "no block with the drawn scalars";
    return false;
  }
  if (!req.anchored) {
    return true;
  }
  const int* given = req.wholeExtent;
  for (size_t i = 0; i < pts.size(); ++i) {
    for (int a = 0; a < 3 && plan.pieces[i].draws; ++a) {
      if (pts[i][2 * a] < given[2 * a] || pts[i][2 * a + 1] > given[2 * a + 1]) {
        plan.why = "a block outside the whole extent given to the mapper";
        return false;
      }
    }
  }
  std::copy(given, given + 6, whole);
  return true;
}

// Owned cells: the block's own (non-duplicate) cells, and the cell layer past its last points
// where a neighbour starts one point further on (blocks that do not share their face points);
// false when two drawing blocks overlap.
bool ownCells(LatticePlan& plan, const std::vector<Box>& pts, const std::vector<Box>& cells) {
  const size_t n = pts.size();
  auto sideBySide = [&](size_t i, size_t j, int axis) {
    for (int b = 0; b < 3; ++b) {
      if (b != axis && !(cells[i][2 * b] < cells[j][2 * b + 1] && cells[j][2 * b] < cells[i][2 * b + 1])) {
        return false;
      }
    }
    return true;
  };
  for (size_t i = 0; i < n; ++i) {
    int* owned = plan.pieces[i].owned;
    std::copy(cells[i].begin(), cells[i].end(), owned);
    for (int a = 0; a < 3 && plan.pieces[i].draws; ++a) {
      const int h = cells[i][2 * a + 1];  // the first cell past the block's own
      if (h != pts[i][2 * a + 1]) {
        continue;  // ghost cells on that side: the next block's
      }
      bool gapNeighbour = false, covered = false;
      for (size_t j = 0; j < n; ++j) {
        if (j == i || !plan.pieces[j].draws || !sideBySide(i, j, a)) {
          continue;
        }
        gapNeighbour = gapNeighbour || pts[j][2 * a] == h + 1;
        covered = covered || (cells[j][2 * a] <= h && h < cells[j][2 * a + 1]);
      }
      if (gapNeighbour && !covered) {
        owned[2 * a + 1] = h + 1;
      }
    }
  }
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = i + 1; j < n && plan.pieces[i].draws; ++j) {
      const int* oi = plan.pieces[i].owned;
      const int* oj = plan.pieces[j].owned;
      bool overlap = plan.pieces[j].draws;
      for (int a = 0; a < 3 && overlap; ++a) {
        overlap = oi[2 * a] < oj[2 * a + 1] && oj[2 * a] < oi[2 * a + 1];
      }
      if (overlap) {
        plan.why = "blocks overlap by more than a face of points, and no ghost array marks the "
                   "duplicated cells";
        return false;
      }
    }
  }
  return true;
}

// What each drawing block reads: its cells and `layers` around them, inside the whole image;
// when that reaches past its points, the copies that fill a padded piece.
void padPieces(LatticePlan& plan, int layers) {
  const size_t n = plan.pieces.size();
  const int* whole = plan.wholeExtent;
  for (size_t i = 0; i < n; ++i) {
    LatticePiece& p = plan.pieces[i];
    if (!p.draws) {
      continue;
    }
    bool inside = true;
    for (int a = 0; a < 3; ++a) {
      p.need[2 * a] = std::max(whole[2 * a], p.owned[2 * a] - layers);
      p.need[2 * a + 1] = std::min(whole[2 * a + 1], p.owned[2 * a + 1] + layers);
      inside = inside && p.points[2 * a] <= p.need[2 * a] && p.need[2 * a + 1] <= p.points[2 * a + 1];
    }
    p.padded = !inside;
    if (inside) {
      continue;
    }
    // The other blocks' points, then the block's own (its values win where they overlap).
    for (size_t k = 0; k <= n; ++k) {
      const size_t j = k < n ? k : i;
      if ((k < n && j == i) || !plan.pieces[j].draws) {
        continue;
      }
      LatticeCopy c;
      c.block = j;
      bool meets = true;
      for (int a = 0; a < 3; ++a) {
        c.box[2 * a] = std::max(p.need[2 * a], plan.pieces[j].points[2 * a]);
        c.box[2 * a + 1] = std::min(p.need[2 * a + 1], plan.pieces[j].points[2 * a + 1]);
        meets = meets && c.box[2 * a] <= c.box[2 * a + 1];
      }
      if (meets) {
        p.copies.push_back(c);
      }
    }
  }
}

}  // namespace

LatticePlan planLattice(const LatticeRequest& req) {
  LatticePlan plan;
  const size_t n = req.blocks.size();
  if (n == 0) {
    plan.why = "no block";
    return plan;
  }
  plan.pieces.resize(n);
  setGeometry(req, plan);
  std::vector<Box> pts(n), cells(n);
  if (!placeBlocks(req, plan, pts, cells)) {
    return plan;
  }
  for (size_t i = 0; i < n; ++i) {
    std::copy(pts[i].begin(), pts[i].end(), plan.pieces[i].points);
  }
  if (!wholeImage(req, plan, pts) || !ownCells(plan, pts, cells)) {
    return plan;
  }
  padPieces(plan, req.layers);
  plan.onLattice = true;
  return plan;
}

void nearestOwnPoint(const LatticePiece& piece, const int ijk[3], int out[3]) {
  for (int a = 0; a < 3; ++a) {
    out[a] = std::min(std::max(ijk[a], piece.points[2 * a]), piece.points[2 * a + 1]);
  }
}

}  // namespace spaceskip
