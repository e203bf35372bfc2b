// Procedural stand-ins for the paper's data sets (DESIGN.md "Benchmarks").
#pragma once
#include "spaceskip/TransferFunction.h"
#include "spaceskip/Volume.h"

#include <string>
#include <vector>

namespace spaceskip {

/// Shapes: "menger" (level-3 sponge, 40.6% occupied), "nbody" (one fixed set of 229,376 particles
/// in cosmic-web halos and filaments, splatted into single voxels at any resolution: occupied 8^3
/// bricks 13% at 256^3 falling to 1.1% at 2048^3 like the paper's N-body, so voxel occupancy
/// falls with resolution, 0.83% at 256^3 to 0.0025% at 2048^3), "shell" (sphere shell), "noise" (smooth value noise),
/// "rm" (Richtmyer-Meshkov-like mixing layer), "vessels" (branching tubes, ~1%).
/// The paper's other data sets (Fig. 1), each at any dims with the paper's voxel occupancy under
/// the "ramp" preset over the volume's range (the bench's TF): "aneurism" (vessels and a sac,
/// 1.01%), "xmas_tree" (branches round an empty cone, 2.9%, height along y), "magnetic" (turbulent
/// flux blobs, 16.6%), "stag_beetle" (exoskeleton shells, legs, mandibles, 4.04%), "kingsnake"
/// (a coiled skeleton, 0.39%), "richtmyer_meshkov" (homogeneous heavy fluid below, empty above, a
/// turbulent mixing layer between, 50.6%, mixing along z).
/// All uint8 except "noise" (float32). Throws std::invalid_argument for unknown shapes.
Volume generateVolume(const std::string& shape, vec3l dims, unsigned seed = 1);
std::vector<std::string> generatorShapes();

/// Fraction of voxels a transfer function makes visible (opacity > 0 at the voxel's value,
/// NaN transparent): the paper's "occupancy" (Fig. 1).
double visibleVoxelFraction(const Volume& v, const TransferFunction& tf);

/// One data set of the paper's table (shared/paper/paper_results.csv) and its stand-in.
struct PaperDataset {
  const char* name;   ///< the paper's row ("xmas_tree", "nbody_2048", ...)
  const char* shape;  ///< generateVolume's shape
  vec3l dims;         ///< the paper's dims
  double occupancyPct;  ///< the paper's occupancy (% of voxels)
};
/// The paper's rows in its order.
const std::vector<PaperDataset>& paperDatasets();

}  // namespace spaceskip
