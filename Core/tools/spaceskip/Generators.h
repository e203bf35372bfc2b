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
/// Points z0..z1 (inclusive) of generateVolume(shape, dims, seed), as a volume of their own
/// (origin and spacing untouched): one MPI rank's slab. "nbody" makes only the slab (a volume
/// larger than any one host's share never exists whole); other shapes are made whole and cut.
Volume generateSlab(const std::string& shape, vec3l dims, int64_t z0, int64_t z1, unsigned seed = 1);
std::vector<std::string> generatorShapes();
/// Time step `step` of a generated simulation (issue 38's playback): "nbody" advected, its
/// particles drifting step by step (step 0 is generateVolume("nbody")); "rm", the mixing layer
/// widening from a thin sheet at step 0 to the dense stand-in at step 24, its turbulence
/// drifting; as uint8 or float32 (value / 255). Throws std::invalid_argument for other shapes
/// or types.
Volume generateTimeStep(const std::string& shape, vec3l dims, int step, VoxelType type = VoxelType::UInt8,
                        unsigned seed = 1);

/// A label map (segmentation, issue 37): `labels` ellipsoidal blobs, ids 1..labels, background 0,
/// on a jittered grid of ~1.3 cells a label with the ids shuffled (neighbours' ids unrelated),
/// sizes log-uniform over 0.12..0.55 cells (volumes ~100x apart), each axis x0.7..1.3; uint8 for
/// <= 255 labels, else uint16. Deterministic per seed (not per thread count); every id present when
/// a cell is >= ~2 voxels wide (each blob's centre voxel keeps its id). Work: the painted voxels
/// (per blob only its rows), not voxels x labels. generateVolume's "labels" (256) and "labelsN".
Volume generateLabels(vec3l dims, int labels = 256, unsigned seed = 1);
/// The label count of a shape "labels" (256) or "labelsN" (N in 1..65535), else 0.
int labelShapeCount(const std::string& shape);

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
