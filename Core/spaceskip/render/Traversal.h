// Space-skipping traversals as iterators: each `step` does a bounded amount of work (one grid
// cell, one distance-field leap, or one tree node) and says whether it produced a possibly
// non-empty interval [a, b) of the ray. The integrator interleaves these steps with single
// samples ("if-if", Aila & Laine 2009; Open VKL's interval iterators), so the lanes of a GPU warp
// stay together: a lane whose interval is used up takes one traversal step while its neighbours
// take one sample, instead of the whole warp waiting for one lane's march of a long run (the
// callback form this replaced ran at 49% SIMT efficiency on the Menger sponge, 97% for Naive:
// docs/results/round6-h100/profile-dense-before). Written once for host and device.
#pragma once
#include "FrameShared.h"

namespace spaceskip {

/// What one traversal step produced.
enum class Step : int { Skip, Interval, Done };

/// 3-D DDA (Amanatides & Woo 1987) over the bricks of `g`, restricted to t in [tmin, tmax):
/// each step visits one brick and yields it as an interval when it is occupied. With a distance
/// field, an empty brick at distance d >= 2 is left together with the (2d-1)^3 empty bricks
/// around it: the ray leaps to where it exits that cube (proximity clouds), then the DDA
/// restarts there. With value ranges (GridView::vmin) a brick is occupied when
/// `m.active(vmin, vmax)` says so, decided when the previous interval's samples are taken.
/// With sub-brick masks (GridView::sub) an occupied brick whose byte says so (bit 7,
/// kBrickPartsBit) is walked by a second DDA over its 4^3 parts, which yields the runs of set
/// parts only (no memory reads beyond the mask).
template <bool Parts>
struct GridIterT {
  const GridView* g;
  vec3f org, dir, inv;
  float t, tmax, B;
  int cell[3], step[3];
  float tNext[3], tDelta[3];
  bool done;
  // The brick being walked part by part: its mask (0: none), the part, where the ray leaves
  // the part along each axis, the cursor and where the ray leaves the brick.
  uint64_t mask = 0;
  int sc[3];
  float sNext[3];
  float ts, tsEnd;

  /// The next run of set parts of the brick being walked: [a, b). false: the brick is done.
  SS_FUNC bool partRun(float& a, float& b) {
    const float S = B * (1.f / float(kSubPerAxis));
    bool have = false;
    while (ts < tsEnd) {
      const int axis = sNext[0] < sNext[1] ? (sNext[0] < sNext[2] ? 0 : 2) : (sNext[1] < sNext[2] ? 1 : 2);
      const bool set = (mask >> (sc[0] + kSubPerAxis * (sc[1] + kSubPerAxis * sc[2]))) & 1u;
      const float te = ss_max(ts, ss_min(sNext[axis], tsEnd));
      if (set && !have) {
        a = ts;
        have = true;
      } else if (!set && have) {
        break;  // the run ends where this part begins
      }
      ts = te;
      sc[axis] += step[axis];
      sNext[axis] += float(step[axis]) * S * inv[axis];
      if (sc[axis] < 0 || sc[axis] >= kSubPerAxis) ts = tsEnd;  // left the brick
    }
    if (have) {
      b = ts;
      return true;
    }
    mask = 0;
    return false;
  }

  /// Starts walking the parts of brick `c` (mask `m`) from t0 to t1.
  SS_FUNC void enterParts(const int c[3], uint64_t m, float t0, float t1) {
    const float S = B * (1.f / float(kSubPerAxis));
    mask = m;
    ts = t0;
    tsEnd = t1;
    const vec3f p = org + dir * t0;
    for (int a = 0; a < 3; ++a) {
      const float base = float(c[a]) * B;
      int k = int(floorf((p[a] - base) / S));
      k = ss_maxi(0, ss_mini(k, kSubPerAxis - 1));
      sc[a] = k;
      sNext[a] = step[a] == 0 ? INFINITY : (base + float(step[a] > 0 ? k + 1 : k) * S - org[a]) * inv[a];
    }
  }

  /// Where the ray leaves cell c along axis a (the cell's far face in the step direction).
  SS_FUNC float exitOf(int a, int c) const {
    return step[a] == 0 ? INFINITY : (float(step[a] > 0 ? c + 1 : c) * B - org[a]) * inv[a];
  }

  SS_FUNC void init(const GridView& grid, const Ray& r, vec3f invDir, float tmin, float tEnd) {
    g = &grid;
    org = r.org;
    dir = r.dir;
    inv = invDir;
    t = tmin;
    tmax = tEnd;
    B = float(grid.brick);
    mask = 0;
    done = !(tmin < tEnd);
    if (done) return;
    const vec3f p = org + dir * tmin;
    for (int a = 0; a < 3; ++a) {
      int c = int(floorf(p[a] / B));
      c = ss_maxi(0, ss_mini(c, grid.dims[a] - 1));
      cell[a] = c;
      const float d = dir[a];
      step[a] = d > 0.f ? 1 : d < 0.f ? -1 : 0;
      tDelta[a] = step[a] == 0 ? INFINITY : float(step[a]) * B * inv[a];
      tNext[a] = exitOf(a, c);
    }
  }

  template <class Marcher>
  SS_FUNC Step next(const Marcher& m, float& a, float& b) {
    if (Parts && mask && partRun(a, b)) return Step::Interval;
    if (done || !(t < tmax)) {
      done = true;
      return Step::Done;
    }
    const int64_t idx = cell[0] + int64_t(g->dims.x) * (cell[1] + int64_t(g->dims.y) * cell[2]);
    int dist;
    bool walkParts = false;
    if (g->vmin) {
      dist = m.active(g->vmin[idx], g->vmax[idx]) ? 0 : 1;
    } else {
      // DistanceGrid's field or the brick states: bit 7 says "walk the parts" (subBrickState).
      const int raw = g->dist ? g->dist[idx] : g->occ[idx];
      walkParts = Parts && (raw & kBrickPartsBit) != 0 && g->sub != nullptr;
      dist = g->dist ? (raw & 0x7f) : (raw != 0 ? 0 : 1);
    }
    if (dist >= 2) {
      // Leave the empty cube [cell - (dist-1), cell + (dist-1)] through its nearest exit face.
      const int rad = dist - 1;
      float tJump = INFINITY;
      int ja = 0;
      for (int ax = 0; ax < 3; ++ax) {
        const float ta = exitOf(ax, cell[ax] + step[ax] * rad);  // the cube's far face on axis ax
        if (ta < tJump) {
          tJump = ta;
          ja = ax;
        }
      }
      if (!(tJump < tmax)) {  // the rest of the ray is empty
        done = true;
        return Step::Done;
      }
      const vec3f q = org + dir * tJump;
      for (int ax = 0; ax < 3; ++ax) {
        int c;
        if (ax == ja) {
          c = cell[ax] + step[ax] * (rad + 1);
        } else {  // still inside the cube's slab on this axis (clamped against rounding)
          c = int(floorf(q[ax] / B));
          c = ss_maxi(ss_maxi(cell[ax] - rad, 0), ss_mini(c, ss_mini(cell[ax] + rad, g->dims[ax] - 1)));
        }
        if (c < 0 || c >= g->dims[ax]) {  // left the grid
          done = true;
          return Step::Done;
        }
        cell[ax] = c;
        tNext[ax] = exitOf(ax, c);
      }
      t = ss_max(t, tJump);
      return Step::Skip;
    }
    const int axis = tNext[0] < tNext[1] ? (tNext[0] < tNext[2] ? 0 : 2) : (tNext[1] < tNext[2] ? 1 : 2);
    const float tExit = ss_max(t, ss_min(tNext[axis], tmax));
    a = t;
    b = tExit;
    t = tExit;
    const uint64_t parts = Parts && dist == 0 && walkParts ? g->sub[idx] : ~uint64_t(0);
    if (Parts && parts != ~uint64_t(0)) enterParts(cell, parts, a, tExit);
    cell[axis] += step[axis];
    tNext[axis] += tDelta[axis];
    if (cell[axis] < 0 || cell[axis] >= g->dims[axis]) done = true;
    if (dist != 0) return Step::Skip;
    if (!Parts || parts == ~uint64_t(0)) return Step::Interval;
    return mask && partRun(a, b) ? Step::Interval : Step::Skip;
  }
};
/// The DDA over whole bricks (bricks marked for their parts are marched whole).
using GridIter = GridIterT<false>;
/// The DDA walking the parts of the bricks marked for it (TraversalKind::GridParts).
using GridPartsIter = GridIterT<true>;

/// Ordered front-to-back traversal of the flat tree: the nearer child (by entry distance)
/// first, the farther one pushed on a fixed stack of kMaxTreeHeight entries. Each step handles
/// one node (after popping one when the last is done) and yields a hit leaf's interval.
struct TreeIter {
  const TreeView* tv;
  Ray r;
  vec3f inv;
  float tmin, tmax;
  // Only node indices are stacked: a popped node's interval is recomputed from its box (the
  // same float operations give the same values), which halves the stack's local-memory traffic.
  int stack[kMaxTreeHeight + 1];
  int sp;
  int node;         ///< the node to handle next; -1: pop one first
  float nodeT0, nodeT1;

  SS_FUNC bool clip(int n, float& t0, float& t1) const {
    const box3i& bx = tv->nodes[n].box;
    intersectBox(r, inv, vec3f{float(bx.lo.x), float(bx.lo.y), float(bx.lo.z)},
                 vec3f{float(bx.hi.x), float(bx.hi.y), float(bx.hi.z)}, t0, t1);
    t0 = ss_max(t0, tmin);
    t1 = ss_min(t1, tmax);
    return t0 < t1;
  }

  SS_FUNC void init(const TreeView& view, const Ray& ray, vec3f invDir, float tBegin, float tEnd) {
    tv = &view;
    r = ray;
    inv = invDir;
    tmin = tBegin;
    tmax = tEnd;
    sp = 0;
    node = -1;
    if (view.numNodes > 0 && clip(0, nodeT0, nodeT1)) node = 0;
  }

  template <class Marcher>
  SS_FUNC Step next(const Marcher&, float& a, float& b) {
    if (node < 0) {
      if (sp == 0) return Step::Done;
      node = stack[--sp];
      clip(node, nodeT0, nodeT1);
    }
    const Node& n = tv->nodes[node];
    if (n.child < 0) {
      a = nodeT0;
      b = nodeT1;
      node = -1;
      return Step::Interval;
    }
    float t0[2], t1[2];
    const bool hit0 = clip(n.child, t0[0], t1[0]);
    const bool hit1 = clip(n.child + 1, t0[1], t1[1]);
    if (hit0 && hit1) {
      const int nearC = t0[1] < t0[0] ? 1 : 0;
      stack[sp++] = n.child + (1 - nearC);
      node = n.child + nearC;
      nodeT0 = t0[nearC];
      nodeT1 = t1[nearC];
    } else if (hit0 || hit1) {
      const int c = hit0 ? 0 : 1;
      node = n.child + c;
      nodeT0 = t0[c];
      nodeT1 = t1[c];
    } else {
      node = -1;
    }
    return Step::Skip;
  }
};

/// The paper's hybrid: a shallow tree whose leaves are walked with the brick grid's DDA.
struct HybridIter {
  TreeIter tree;
  GridIter grid;
  bool inLeaf;

  SS_FUNC void init(const TreeView& tv, const GridView& g, const Ray& r, vec3f inv, float tmin, float tmax) {
    tree.init(tv, r, inv, tmin, tmax);
    grid.g = &g;
    inLeaf = false;
  }

  template <class Marcher>
  SS_FUNC Step next(const Marcher& m, float& a, float& b) {
    if (inLeaf) {
      const Step s = grid.next(m, a, b);
      if (s != Step::Done) return s;
      inLeaf = false;
    }
    const Step s = tree.next(m, a, b);
    if (s != Step::Interval) return s;
    grid.init(*grid.g, tree.r, tree.inv, a, b);
    inLeaf = true;
    return Step::Skip;
  }
};

}  // namespace spaceskip
