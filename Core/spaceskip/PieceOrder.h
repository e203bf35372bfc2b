// Front-to-back order of the boxes of pieces (image blocks, MPI ranks' pieces) for compositing
// their images in float: per pixel, a ray meets disjoint convex pieces one after the other, so a
// front-to-back order of the pieces gives every pixel the order its ray meets them in.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

namespace spaceskip {

/// A piece's box: [lo, hi] per axis, interleaved like a VTK extent (x0, x1, y0, y1, z0, z1), in
/// one index space for all pieces (e.g. the whole image's point indices: the cells [lo, hi)).
using PieceBox = std::array<double, 6>;

/// The order in which rays from `eye` (perspective) or along `dir` (parallel projection) reach
/// the disjoint `boxes`, front first, as indices into `boxes`. Exact whenever axis planes
/// separate the boxes recursively (a binary space partition: grids, k-d splits, the pieces
/// ParaView's extent translator and readers make): the side the rays reach first goes first.
/// Boxes no axis plane separates are ordered by the distance of their centres (perspective) or
/// their centres along `dir` (parallel). `eye` and `dir` are in the boxes' index space.
std::vector<size_t> visibilityOrder(const std::vector<PieceBox>& boxes, const double eye[3],
                                    const double dir[3], bool parallel);

}  // namespace spaceskip
