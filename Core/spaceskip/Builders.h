// The builder registry: one row per BuilderKind says what the builder is called (VTK/plugin and
// CLI), which traversal renders it, what it builds on each backend and what stands in for it
// where it cannot run. The Engine, both backends, the CLI and the mapper read this table; a test
// (TestBuilderRegistry) checks the CLI's names, the mapper's enum and the plugin XML against it.
// Adding a builder: one row in Builders.cpp plus the builder's own files.
#pragma once
#include "Classification.h"
#include "Tree.h"
#include "Types.h"

namespace spaceskip {

namespace cuda {
struct BuildContext;  // cuda/BuildContext.cuh: device occupancy, stream, output tree, workspaces
}

/// A host builder: the tree over the occupied bricks of `occ`.
using CpuBuildFn = Tree (*)(const OccupancyGrid& occ, const BuildParams& p);
/// A device builder: fills ctx's tree from ctx's device occupancy.
using CudaBuildFn = void (*)(cuda::BuildContext& ctx, const BuildParams& p);

/// What a traversal needs beside the occupancy grid (and the tree, for Tree/Hybrid).
enum class BuilderExtra : int {
  None,
  DistanceField,  ///< per-brick empty distance (DistanceGrid)
  CoarseGrid      ///< the occupancy coarsened to kHybridCell cells per brick edge (Hybrid)
};
/// Hybrid's grid cell edge in cells (paper 3.3).
constexpr int kHybridCell = 16;

struct BuilderInfo {
  BuilderKind kind;
  const char* name;     ///< VTK / plugin name ("KdTreeGPUFast"); builderName()
  const char* cliName;  ///< the CLI's ("kdtree-gpu-fast")
  TraversalKind traversal;
  BuilderExtra extra;
  CpuBuildFn cpu;    ///< host build (oneTBB); nullptr: none (or no tree to build)
  CudaBuildFn cuda;  ///< device build; nullptr: the CUDA backend runs `cpu` and uploads the tree
  /// Where neither applies on the chosen backend (a GPU-only builder on the CPU backend), this
  /// builds instead, with a warning.
  BuilderKind fallback;
  const char* summary;  ///< one line for help texts
};

/// Every builder, in BuilderKind order (Auto last: the Engine resolves it before a backend sees it).
const BuilderInfo* builderRegistry(int* count);
const BuilderInfo& builderInfo(BuilderKind b);
/// True when the builder's traversal walks a tree (which some builder must make).
inline bool buildsTree(const BuilderInfo& b) {
  return b.traversal == TraversalKind::Tree || b.traversal == TraversalKind::Hybrid;
}
/// Whether building `b` makes anything beyond the classification's occupancy grid (a tree, a
/// distance field, a coarse grid): Naive and Grid make nothing.
inline bool buildsBeyondClassification(BuilderKind b) {
  const BuilderInfo& i = builderInfo(b);
  return buildsTree(i) || i.extra != BuilderExtra::None;
}
/// Whether a backend without device builders can build `b` itself (else it takes b.fallback).
inline bool runsOnCpu(const BuilderInfo& b) { return !buildsTree(b) || b.cpu != nullptr; }

/// Which traversal renders the hierarchy of builder `b`.
inline TraversalKind traversalFor(BuilderKind b) { return builderInfo(b).traversal; }

/// Runs the registry's host builder for `p.builder` and checks the result against the
/// traversal's stack (kMaxTreeHeight). Throws BackendError when `p.builder` has no host builder.
Tree buildTreeCPU(const OccupancyGrid& occ, const BuildParams& p);
/// Throws std::runtime_error when `height` would overflow the traversal's stack: every builder,
/// host or device, is checked here.
void checkTreeHeight(BuilderKind b, int height);

/// Coarser occupancy (a brick is occupied when any of its factor^3 children is): Hybrid's grid.
OccupancyGrid coarsen(const OccupancyGrid& occ, int factor);

}  // namespace spaceskip
