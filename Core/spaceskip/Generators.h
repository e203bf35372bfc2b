// Procedural stand-ins for the paper's data sets (DESIGN.md "Benchmarks").
#pragma once
#include "Volume.h"

#include <string>
#include <vector>

namespace spaceskip {

/// Shapes: "menger" (level-3 sponge, 40.6% occupied), "nbody" (clustered particle splats,
/// ~0.15% of voxels non-zero), "shell" (sphere shell), "noise" (smooth value noise),
/// "rm" (Richtmyer-Meshkov-like mixing layer), "vessels" (branching tubes, ~1%).
/// All uint8 except "noise" (float32). Throws std::invalid_argument for unknown shapes.
Volume generateVolume(const std::string& shape, vec3l dims, unsigned seed = 1);
std::vector<std::string> generatorShapes();

}  // namespace spaceskip
