// Lattice planning for image blocks (the leaves of a composite data set, an MPI rank's share of
// them): whether the blocks lie on one voxel lattice, and if so each block as a piece of the
// image they make together (spaceskip::VolumePiece): its points and the cells it draws in the
// lattice's index space, and the neighbours' voxels it must borrow when it reads past its own.
// Plain structs in, a plan out; the VTK module turns the plan into image pieces.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace spaceskip {

/// One image block as the planner sees it.
struct LatticeBlock {
  double spacing[3] = {1, 1, 1};
  double direction[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};  ///< row-major, as vtkImageData's
  int extent[6] = {0, -1, 0, -1, 0, -1};               ///< point extent (x0, x1, y0, y1, z0, z1)
  double firstPoint[3] = {0, 0, 0};  ///< physical position of point (extent[0], extent[2], extent[4])
  /// The cells no ghost array marks as duplicates, [lo, hi) per axis in the block's own indices;
  /// hasOwnCells false: every cell is a duplicate (another block's).
  bool hasOwnCells = true;
  int ownCells[6] = {0, 0, 0, 0, 0, 0};
  /// The drawn scalars: present with one tuple per point, their type and component count.
  bool hasScalars = false;
  int scalarType = 0;
  int components = 1;
};

struct LatticeRequest {
  std::vector<LatticeBlock> blocks;
  /// Voxel layers a block reads past its cells (1 with shading's gradients or slice mode).
  int layers = 0;
  /// The whole image the blocks of all ranks make (MPI): its point extent, its first point at
  /// wholeOrigin. anchored false: the image these blocks make, on the first block's lattice.
  bool anchored = false;
  int wholeExtent[6] = {0, -1, 0, -1, 0, -1};
  double wholeOrigin[3] = {0, 0, 0};
};

/// A region [lo, hi] (points, per axis) of block `block`'s points copied into a padded piece.
struct LatticeCopy {
  size_t block = 0;
  int box[6] = {0, -1, 0, -1, 0, -1};
};

struct LatticePiece {
  bool draws = false;  ///< false: no own cells, or not the drawn scalars
  int points[6] = {0, -1, 0, -1, 0, -1};  ///< the block's points in the lattice's index space
  int owned[6] = {0, 0, 0, 0, 0, 0};      ///< the cells it draws, [lo, hi) per axis
  /// The block reads points it does not hold (a gap to its neighbour, shading layers): the piece
  /// is a copy of extent `need`, filled by `copies` in order (the neighbours' points, then its
  /// own, which win), the points no block has taken from the block's nearest point.
  bool padded = false;
  int need[6] = {0, -1, 0, -1, 0, -1};
  std::vector<LatticeCopy> copies;
};

struct LatticePlan {
  bool onLattice = false;
  std::string why;  ///< why not, when !onLattice
  /// The lattice's geometry (set even when !onLattice): index (0, 0, 0) at origin.
  double origin[3] = {0, 0, 0};
  double spacing[3] = {1, 1, 1};
  double direction[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  int wholeExtent[6] = {0, -1, 0, -1, 0, -1};
  std::vector<LatticePiece> pieces;  ///< one per block, in the request's order
};

/// Lays the blocks on one lattice: same spacing and orientation, origins a whole number of voxels
/// apart, no overlap beyond a shared face of points unless ghost cells mark it. Blocks that share
/// a face of points own the cells on their side; across a gap of one cell the lower block owns
/// the gap. Fails (with `why`) for blocks off one lattice, one point thick, overlapping, of
/// different scalar types, or outside an anchored whole extent.
LatticePlan planLattice(const LatticeRequest& request);

/// The point of `plan.pieces[piece].points` nearest to `ijk` (a padded copy's fallback).
void nearestOwnPoint(const LatticePiece& piece, const int ijk[3], int out[3]);

}  // namespace spaceskip
