// CPU hierarchy builders over the brick occupancy grid; all emit Core's flat Tree.
#pragma once
#include "Classification.h"
#include "Engine.h"
#include "Integrator.h"
#include "Tree.h"

namespace spaceskip {

/// Runs the CPU builder for `p.builder` (LBVHCPU, KdTreeCPU, Hybrid's shallow tree).
/// Throws BackendError when `p.builder` has no CPU implementation.
Tree buildTreeCPU(const OccupancyGrid& occ, const BuildParams& p);

/// Coarser occupancy (a brick is occupied when any of its factor^3 children is): Hybrid's grid.
OccupancyGrid coarsen(const OccupancyGrid& occ, int factor);

/// Which traversal renders the hierarchy of builder `b`.
TraversalKind traversalFor(BuilderKind b);

}  // namespace spaceskip
