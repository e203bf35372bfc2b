// Procedural stand-ins for the paper's data sets (DESIGN.md "Benchmarks").
#pragma once
#include "Volume.h"

#include <string>
#include <vector>

namespace spaceskip {

/// Shapes: "menger" (level-3 sponge, 40.6% occupied), "nbody" (one fixed set of 229,376 particles
/// in cosmic-web halos and filaments, splatted into single voxels at any resolution: occupied 8^3
/// bricks 13% at 256^3 falling to 1.1% at 2048^3 like the paper's N-body, so voxel occupancy
/// falls with resolution, 0.83% at 256^3 to 0.0025% at 2048^3), "shell" (sphere shell), "noise" (smooth value noise),
/// "rm" (Richtmyer-Meshkov-like mixing layer), "vessels" (branching tubes, ~1%).
/// All uint8 except "noise" (float32). Throws std::invalid_argument for unknown shapes.
Volume generateVolume(const std::string& shape, vec3l dims, unsigned seed = 1);
std::vector<std::string> generatorShapes();

}  // namespace spaceskip
