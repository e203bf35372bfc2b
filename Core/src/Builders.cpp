// Builder dispatch and helpers shared by the CPU builders.
#include "spaceskip/Builders.h"

#include "spaceskip/KdTreeBuilder.h"
#include "spaceskip/LbvhBuilder.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <stdexcept>
#include <string>

namespace spaceskip {

TraversalKind traversalFor(BuilderKind b) {
  switch (b) {
    case BuilderKind::Naive: return TraversalKind::Naive;
    case BuilderKind::Grid:
    case BuilderKind::DistanceGrid: return TraversalKind::Grid;
    case BuilderKind::Hybrid: return TraversalKind::Hybrid;
    default: return TraversalKind::Tree;
  }
}

OccupancyGrid coarsen(const OccupancyGrid& occ, int factor) {
  OccupancyGrid c;
  c.brick = occ.brick * factor;
  c.cellDims = occ.cellDims;
  c.dims = vec3i{(occ.dims.x + factor - 1) / factor, (occ.dims.y + factor - 1) / factor,
                 (occ.dims.z + factor - 1) / factor};
  c.occ.assign(size_t(c.size()), 0);
  tbb::parallel_for(tbb::blocked_range<int>(0, c.dims.z), [&](const tbb::blocked_range<int>& r) {
    for (int z = r.begin(); z != r.end(); ++z)
      for (int y = 0; y < c.dims.y; ++y)
        for (int x = 0; x < c.dims.x; ++x) {
          uint8_t any = 0;
          for (int k = z * factor; k < std::min((z + 1) * factor, occ.dims.z) && !any; ++k)
            for (int j = y * factor; j < std::min((y + 1) * factor, occ.dims.y) && !any; ++j)
              for (int i = x * factor; i < std::min((x + 1) * factor, occ.dims.x) && !any; ++i)
                any = occ.at(i, j, k) ? 1 : 0;
          c.occ[size_t(c.index(x, y, z))] = any;
        }
  });
  for (uint8_t v : c.occ) c.occupied += v;
  return c;
}

Tree buildTreeCPU(const OccupancyGrid& occ, const BuildParams& p) {
  Tree t;
  switch (p.builder) {
    case BuilderKind::LBVHCPU: t = buildLbvh(occ); break;
    case BuilderKind::KdTreeCPU: t = buildKdTree(occ, p); break;
    case BuilderKind::Hybrid: {
      // Paper 3.3: the shallow k-d tree; the 16^3 grid is coarsen()'s, rendered per leaf.
      BuildParams q = p;
      q.leaf = LeafCriterion::Shallow;
      t = buildKdTree(occ, q);
      break;
    }
    default:
      throw BackendError(std::string("builder ") + builderName(p.builder) + " has no CPU implementation");
  }
  if (t.height >= kMaxTreeHeight)
    throw std::runtime_error(std::string(builderName(p.builder)) + ": tree height " + std::to_string(t.height) +
                             " reaches kMaxTreeHeight");
  return t;
}

}  // namespace spaceskip
