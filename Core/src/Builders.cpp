// Builder dispatch and helpers shared by the CPU builders.
#include "spaceskip/Builders.h"

#include "spaceskip/KdTreeBuilder.h"
#include "spaceskip/LbvhBuilder.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cctype>
#include <stdexcept>
#include <string>

namespace spaceskip {

namespace {
#if SPACESKIP_HAVE_CUDA
#define SS_CUDA_BUILDER(fn) &fn
#else
#define SS_CUDA_BUILDER(fn) nullptr
#endif

// Paper 3.3: Hybrid's shallow k-d tree; its kHybridCell^3 grid is coarsen()'s, rendered per leaf.
Tree buildShallowKdTree(const OccupancyGrid& occ, const BuildParams& p) {
  BuildParams q = p;
  q.leaf = LeafCriterion::Shallow;
  return buildKdTree(occ, q);
}
Tree buildLbvhHost(const OccupancyGrid& occ, const BuildParams&) { return buildLbvh(occ); }

using B = BuilderKind;
using T = TraversalKind;
using X = BuilderExtra;
// clang-format off
constexpr BuilderInfo kRegistry[] = {
  {B::Naive,         "Naive",         "naive",           T::Naive,  X::None,          nullptr,            nullptr,                                B::Naive,
   "no skipping (the paper's baseline)"},
  {B::Grid,          "Grid",          "grid",            T::Grid,   X::None,          nullptr,            nullptr,                                B::Grid,
   "DDA over the macro-cell occupancy grid"},
  {B::LBVH,          "LBVH",          "lbvh",            T::Tree,   X::None,          &buildLbvhHost,     SS_CUDA_BUILDER(cuda::buildLbvh),       B::LBVH,
   "paper 3.1 on the render backend's device (CUDA, or the oneTBB twin)"},
  {B::LBVHCPU,       "LBVHCPU",       "lbvh-cpu",        T::Tree,   X::None,          &buildLbvhHost,     nullptr,                                B::LBVHCPU,
   "paper 3.1 built with oneTBB"},
  {B::KdTreeCPU,     "KdTreeCPU",     "kdtree-cpu",      T::Tree,   X::None,          &buildKdTree,       nullptr,                                B::KdTreeCPU,
   "paper 3.2.1 (Vidal et al. 2008) built with oneTBB"},
  {B::KdTreeGPU,     "KdTreeGPU",     "kdtree-gpu",      T::Tree,   X::None,          nullptr,            SS_CUDA_BUILDER(cuda::buildKdTreeGpu),     B::KdTreeCPU,
   "paper 3.2.2: CUDA, host-driven recursion"},
  {B::KdTreeGPUFast, "KdTreeGPUFast", "kdtree-gpu-fast", T::Tree,   X::None,          nullptr,            SS_CUDA_BUILDER(cuda::buildKdTreeGpuFast), B::KdTreeCPU,
   "ours: level-parallel CUDA k-d tree"},
  {B::Hybrid,        "Hybrid",        "hybrid",          T::Hybrid, X::CoarseGrid,    &buildShallowKdTree, nullptr,                               B::Hybrid,
   "paper 3.3: shallow k-d tree + 16^3 grid"},
  {B::DistanceGrid,  "DistanceGrid",  "distance-grid",   T::Grid,   X::DistanceField, nullptr,            nullptr,                                B::DistanceGrid,
   "ours: the Grid DDA leaping through empty space with a distance field"},
  {B::Auto,          "Auto",          "auto",            T::Naive,  X::None,          nullptr,            nullptr,                                B::Auto,
   "measures a few structures (Naive among them), the close ones twice, and keeps the fastest"},
};
// clang-format on
constexpr int kRegistrySize = int(sizeof kRegistry / sizeof kRegistry[0]);
static_assert(kRegistrySize == int(BuilderKind::Auto) + 1, "one registry row per BuilderKind");
constexpr bool rowsInEnumOrder() {
  for (int i = 0; i < kRegistrySize; ++i)
    if (int(kRegistry[i].kind) != i) return false;
  return true;
}
static_assert(rowsInEnumOrder(), "registry rows in BuilderKind order");

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}
}  // namespace

const BuilderInfo* builderRegistry(int* count) {
  if (count) *count = kRegistrySize;
  return kRegistry;
}

const BuilderInfo& builderInfo(BuilderKind b) {
  const int i = int(b);
  if (i < 0 || i >= kRegistrySize) throw std::invalid_argument("unknown builder " + std::to_string(i));
  return kRegistry[i];
}

const char* builderName(BuilderKind b) {
  const int i = int(b);
  return i >= 0 && i < kRegistrySize ? kRegistry[i].name : "?";
}

bool parseBuilder(const std::string& s, BuilderKind& out) {
  const std::string l = lower(s);
  for (const BuilderInfo& r : kRegistry)
    if (l == r.cliName || l == lower(r.name)) {
      out = r.kind;
      return true;
    }
  if (l == "macrocellgrid") {
    out = BuilderKind::Grid;
    return true;
  }
  return false;
}

void validate(const BuildParams& p) {
  if (p.bins < 0 || p.bins == 1)
    throw std::invalid_argument("bins must be 0 (sweep every brick boundary) or >= 2, got " + std::to_string(p.bins));
  builderInfo(p.builder);
}

void checkTreeHeight(BuilderKind b, int height) {
  if (height >= kMaxTreeHeight)
    throw std::runtime_error(std::string(builderName(b)) + ": tree height " + std::to_string(height) +
                             " reaches kMaxTreeHeight");
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
  const BuilderInfo& info = builderInfo(p.builder);
  if (!info.cpu) throw BackendError(std::string("builder ") + info.name + " has no CPU implementation");
  Tree t = info.cpu(occ, p);
  checkTreeHeight(p.builder, t.height);
  return t;
}

}  // namespace spaceskip
