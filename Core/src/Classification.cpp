// Per-brick value ranges (once per volume) and conservative occupancy (per opacity edit).
#include "spaceskip/Classification.h"
#include "spaceskip/GradientBound.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>

namespace spaceskip {

namespace {
box3i brickBoxOf(vec3i cellDims, int brick, int x, int y, int z) { return brickCellBox(vec3i{x, y, z}, brick, cellDims); }

template <class T, int NC>
void rangesOf(const Volume& v, RangeGrid& g) {
  const T* data = static_cast<const T*>(v.data);
  const int64_t nx = v.dims.x, ny = v.dims.y, nz = v.dims.z;
  // Parallel over brick rows (y,z): each task writes its own bricks. brickRange's spans, in line
  // order: each voxel line of the row is read once and folded into the bricks it crosses.
  tbb::parallel_for(tbb::blocked_range<int64_t>(0, int64_t(g.dims.y) * g.dims.z),
                    [&](const tbb::blocked_range<int64_t>& r) {
    std::vector<float> lo(size_t(g.dims.x)), hi(size_t(g.dims.x));
    for (int64_t row = r.begin(); row != r.end(); ++row) {
      const int by = int(row % g.dims.y), bz = int(row / g.dims.y);
      std::fill(lo.begin(), lo.end(), std::numeric_limits<float>::infinity());
      std::fill(hi.begin(), hi.end(), -std::numeric_limits<float>::infinity());
      int64_t y0, y1, z0, z1;
      brickVoxelSpan(by, g.brick, ny, y0, y1);
      brickVoxelSpan(bz, g.brick, nz, z0, z1);
      for (int64_t z = z0; z <= z1; ++z)
        for (int64_t y = y0; y <= y1; ++y) {
          const T* line = data + (nx * (y + ny * z)) * NC + (NC - 1);  // the opacity channel
          for (int bx = 0; bx < g.dims.x; ++bx) {
            int64_t x0, x1;
            brickVoxelSpan(bx, g.brick, nx, x0, x1);
            foldRange<T, NC>(line, x0, x1, lo[size_t(bx)], hi[size_t(bx)]);
          }
        }
      for (int bx = 0; bx < g.dims.x; ++bx) {
        g.vmin[size_t(g.index(bx, by, bz))] = lo[size_t(bx)];
        g.vmax[size_t(g.index(bx, by, bz))] = hi[size_t(bx)];
      }
    }
  });
}
}  // namespace

box3i RangeGrid::brickBox(int x, int y, int z) const { return brickBoxOf(cellDims, brick, x, y, z); }
box3i OccupancyGrid::brickBox(int x, int y, int z) const { return brickBoxOf(cellDims, brick, x, y, z); }

RangeGrid computeRangeGrid(const Volume& v, int brick) {
  validate(v);
  RangeGrid g;
  g.brick = std::max(1, brick);
  g.cellDims = v.cellDims();
  g.dims = vec3i{(g.cellDims.x + g.brick - 1) / g.brick, (g.cellDims.y + g.brick - 1) / g.brick,
                 (g.cellDims.z + g.brick - 1) / g.brick};
  g.vmin.resize(size_t(g.size()));
  g.vmax.resize(size_t(g.size()));
  dispatchVoxelType(v.type, [&](auto t) {
    dispatchComponents(v.components, [&](auto nc) { rangesOf<decltype(t), decltype(nc)::value>(v, g); });
  });
  return v.warp ? remapRangeGrid(g, *v.warp) : g;
}

RangeGrid remapRangeGrid(const RangeGrid& grid, const AxisWarp& w) {
  RangeGrid out;
  out.brick = grid.brick;
  out.cellDims = grid.cellDims;
  out.dims = grid.dims;
  out.vmin.resize(size_t(out.size()));
  out.vmax.resize(size_t(out.size()));
  const int B = grid.brick;
  // Per axis, virtual brick b -> the grid bricks [lo[b], hi[b]] holding the cells it reads.
  std::vector<int> lo[3], hi[3];
  const int bricks[3] = {grid.dims.x, grid.dims.y, grid.dims.z};
  const int cells[3] = {grid.cellDims.x, grid.cellDims.y, grid.cellDims.z};
  for (int a = 0; a < 3; ++a) {
    lo[a].resize(size_t(bricks[a]));
    hi[a].resize(size_t(bricks[a]));
    for (int b = 0; b < bricks[a]; ++b) {
      if (w.points(a) < 2) {  // one point: one cell of constant value
        lo[a][size_t(b)] = hi[a][size_t(b)] = b;
        continue;
      }
      int64_t i0 = 0, i1 = 0;
      w.cellSpan(a, int64_t(b) * B, std::min<int64_t>(int64_t(b + 1) * B, cells[a]), i0, i1);
      lo[a][size_t(b)] = int(std::min<int64_t>(i0 / B, bricks[a] - 1));
      hi[a][size_t(b)] = int(std::min<int64_t>(i1 / B, bricks[a] - 1));
    }
  }
  tbb::parallel_for(tbb::blocked_range<int>(0, out.dims.z), [&](const tbb::blocked_range<int>& r) {
    for (int z = r.begin(); z != r.end(); ++z)
      for (int y = 0; y < out.dims.y; ++y)
        for (int x = 0; x < out.dims.x; ++x) {
          float mn = std::numeric_limits<float>::infinity(), mx = -std::numeric_limits<float>::infinity();
          for (int gz = lo[2][size_t(z)]; gz <= hi[2][size_t(z)]; ++gz)
            for (int gy = lo[1][size_t(y)]; gy <= hi[1][size_t(y)]; ++gy)
              for (int gx = lo[0][size_t(x)]; gx <= hi[0][size_t(x)]; ++gx) {
                const int64_t i = grid.index(gx, gy, gz);
                mn = std::min(mn, grid.vmin[size_t(i)]);
                mx = std::max(mx, grid.vmax[size_t(i)]);
              }
          const int64_t o = out.index(x, y, z);
          out.vmin[size_t(o)] = mn;
          out.vmax[size_t(o)] = mx;
        }
  });
  return out;
}

OccupancyGrid classify(const RangeGrid& ranges, const TransferFunction& tf, const CropClip& cc) {
  return classifyWithGradientRows(ranges, tf, cc, GradientRowsView{});
}

void gradientScale(const double spacing[3], double rangeMin, double rangeMax, float k[3]) {
  const double avg = (std::fabs(spacing[0]) + std::fabs(spacing[1]) + std::fabs(spacing[2])) / 3.0;
  double range = rangeMax - rangeMin;
  if (!(range > 0) || !std::isfinite(range)) range = 1.0;
  for (int a = 0; a < 3; ++a) {
    const double h = std::fabs(spacing[a]);
    k[a] = h > 0 ? float(avg / (2.0 * h) / (0.25 * range)) : 0.f;
  }
}

GradientRows::GradientRows(const TransferFunction& tf, const double spacing[3]) {
  if (!tf.uses2D()) return;
  const int W = tf.width2D, H = tf.height2D;
  // Rows 0..r as classificationTF builds all rows: W + 1 entries, entry j the larger of columns
  // j-1 and j, over [rangeMin, rangeMax] (its column mapping).
  TransferFunction prefix;
  prefix.rangeMin = tf.rangeMin;
  prefix.rangeMax = tf.rangeMax;
  std::vector<float> col(size_t(W), 0.f);
  for (int r = 0; r < H; ++r) {
    for (int x = 0; x < W; ++x) {
      const float a = tf.table2D[size_t(r) * size_t(W) + size_t(x)].w;
      if (a > col[size_t(x)]) col[size_t(x)] = a;  // NaN never raises it
    }
    pairMaxEntries(col, prefix.table);
    const OpacityRangeMax rows(prefix);
    if (r == 0) {
      if (rows.levels().size() * size_t(H) > kMaxFloats) return;  // too large: the 1-D rule alone
      view_.prefix = rows.view();
      view_.stride = int64_t(rows.levels().size());
      levels_.reserve(rows.levels().size() * size_t(H));
    }
    levels_.insert(levels_.end(), rows.levels().begin(), rows.levels().end());
  }
  float k[3];
  gradientScale(spacing, tf.rangeMin, tf.rangeMax, k);
  view_.gradNorm = std::sqrt(k[0] * k[0] + k[1] * k[1] + k[2] * k[2]);
  view_.prefix.levels = levels_.data();
  view_.height = H;
}

OccupancyGrid classifyWithGradientRows(const RangeGrid& ranges, const TransferFunction& tf, const CropClip& cc,
                                       const GradientRowsView& rows) {
  OccupancyGrid o;
  o.brick = ranges.brick;
  o.cellDims = ranges.cellDims;
  o.dims = ranges.dims;
  o.occ.resize(size_t(ranges.size()));
  OpacityRangeMax rmq(tf);
  o.occupied = tbb::parallel_reduce(
      tbb::blocked_range<int64_t>(0, ranges.size(), 4096), int64_t(0),
      [&](const tbb::blocked_range<int64_t>& r, int64_t acc) {
        for (int64_t i = r.begin(); i != r.end(); ++i) {
          const uint8_t occ = brickOccupied(i, ranges.vmin[size_t(i)], ranges.vmax[size_t(i)], rmq, ranges.dims,
                                            ranges.brick, ranges.cellDims, cc) &&
                                      gradientRowsAllow(i, ranges.vmin.data(), ranges.vmax.data(), ranges.dims, rows)
                                  ? 1
                                  : 0;
          o.occ[size_t(i)] = occ;
          acc += occ;
        }
        return acc;
      },
      [](int64_t a, int64_t b) { return a + b; });
  return o;
}

SubMasks computeSubMasks(const Volume& v, const OccupancyGrid& occ, const TransferFunction& tf, const Tuning& t) {
  SubMasks out;
  // Not for a warped volume: the masks read voxels by the virtual lattice's index (AxisWarp.h).
  if (!t.subMasks || !usesSubMasks(occ.brick) || v.components != 1 || !v.data || occ.occ.empty() || v.warp)
    return out;
  out.mask.resize(size_t(occ.size()));
  out.state.resize(size_t(occ.size()));
  OpacityRangeMax rmq(tf);
  const int maxSet = subMaskMaxSet(t);
  const int64_t bx = occ.dims.x, by = occ.dims.y;
  dispatchVoxelType(v.type, [&](auto t) {
    using T = decltype(t);
    const T* data = static_cast<const T*>(v.data);
    tbb::parallel_for(tbb::blocked_range<int64_t>(0, occ.size(), 4096), [&](const tbb::blocked_range<int64_t>& r) {
      for (int64_t i = r.begin(); i != r.end(); ++i) {
        const bool o = occ.occ[size_t(i)] != 0;
        const uint64_t m =
            o ? subBrickMask(data, v.dims, occ.cellDims, occ.brick, i % bx, (i / bx) % by, i / (bx * by), rmq.view()) : 0;
        out.mask[size_t(i)] = m;
        out.state[size_t(i)] = subBrickState(o, m, maxSet);
      }
    });
  });
  int64_t set = 0;
  for (const uint64_t m : out.mask) set += popcount64(m);
  out.share = occ.occupied > 0 ? double(set) / (64.0 * double(occ.occupied)) : 1.0;
  return out;
}

}  // namespace spaceskip
