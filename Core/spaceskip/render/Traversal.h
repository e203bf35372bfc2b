// Space-skipping traversals as iterators: each `step` does a bounded amount of work (one grid
// cell, one distance-field leap, or one tree node) and says whether it produced a possibly
// non-empty interval [a, b) of the ray. The integrator interleaves these steps with single
// samples ("if-if", Aila & Laine 2009; Open VKL's interval iterators), so the lanes of a GPU warp
// stay together: a lane whose interval is used up takes one traversal step while its neighbours
// take one sample, instead of the whole warp waiting for one lane's march of a long run (the
// callback form this replaced ran at 49% SIMT efficiency on the Menger sponge, 97% for Naive:
// docs/results/HISTORY.md, traversals as iterators). Written once for host and device.
#pragma once
#include "FrameShared.h"

namespace spaceskip {

/// What one traversal step produced.
enum class Step : int { Skip, Interval, Done };

/// The box of the set parts of a sub-brick mask m != 0 (x fastest, Classification.h): per axis
/// the first and the last part index that holds a set part.
SS_FUNC void setPartBox(uint64_t m, vec3i& lo, vec3i& hi) {
  static_assert(kSubPerAxis == 4, "the folds below are for 4 x 4 x 4 parts");
  const uint32_t z0 = uint32_t(m) & 0xffffu, z1 = uint32_t(m) >> 16;
  const uint32_t z2 = uint32_t(m >> 32) & 0xffffu, z3 = uint32_t(m >> 48);
  const uint32_t zs = uint32_t(z0 != 0) | uint32_t(z1 != 0) << 1 | uint32_t(z2 != 0) << 2 | uint32_t(z3 != 0) << 3;
  const uint32_t xy = z0 | z1 | z2 | z3;  // bit x + 4y: a part of that column is set
  const uint32_t ys = uint32_t((xy & 0xfu) != 0) | uint32_t((xy & 0xf0u) != 0) << 1 |
                      uint32_t((xy & 0xf00u) != 0) << 2 | uint32_t((xy & 0xf000u) != 0) << 3;
  const uint32_t xs = (xy | xy >> 4 | xy >> 8 | xy >> 12) & 0xfu;
  lo = vec3i{ctz32(xs), ctz32(ys), ctz32(zs)};
  hi = vec3i{msb32(xs), msb32(ys), msb32(zs)};
}

/// 3-D DDA (Amanatides & Woo 1987) over the bricks of `g`, restricted to t in [tmin, tmax):
/// each step visits one brick and yields it as an interval when it is occupied. With a distance
/// field, an empty brick at distance d >= 2 is left together with the (2d-1)^3 empty bricks
/// around it: the ray leaps to where it exits that cube (proximity clouds), then the DDA
/// restarts there. With value ranges (GridView::vmin) a brick is occupied when
/// `m.active(vmin, vmax)` says so, decided when the previous interval's samples are taken.
/// With sub-brick masks (GridView::sub) an occupied brick whose byte says so (bit 7,
/// kBrickPartsBit) is walked by a second DDA over its 4^3 parts, inside the box of its set
/// parts, which yields the runs of set parts only (no memory reads beyond the mask).
template <bool Parts>
struct GridIterT {
  // The DDA's per-axis state is vec3 (axisOf/setAxis, Math.h), never an array indexed by the
  // axis the ray steps along: that index is known at run time only, and such an array would put
  // the whole iterator in local memory on a GPU (152 bytes a thread, loaded and stored at every
  // step of every ray: measured with the grid DDA's state in registers).
  const GridView* g;
  vec3f org, dir, inv;
  float t, tmax, B;
  /// 1 / B where B is a power of two (then x * invB is x / B, bit for bit), else 0.
  float invB;
  vec3i cell, step;
  vec3f tNext, tDelta;
  bool done;
  // The brick being walked part by part: its mask (0: none), the part, where the ray leaves
  // the part along each axis, the cursor and where the ray leaves the brick.
  uint64_t mask = 0;
  vec3i sc;
  vec3f sNext;
  float ts, tsEnd;

  /// The next run of set parts of the brick being walked: [a, b). false: the brick is done.
  SS_FUNC bool partRun(float& a, float& b) {
    const float S = B * (1.f / float(kSubPerAxis));
    bool have = false;
    while (ts < tsEnd) {
      const int axis = sNext.x < sNext.y ? (sNext.x < sNext.z ? 0 : 2) : (sNext.y < sNext.z ? 1 : 2);
      const bool set = (mask >> (sc.x + kSubPerAxis * (sc.y + kSubPerAxis * sc.z))) & 1u;
      const float te = ss_max(ts, ss_min(axisOf(sNext, axis), tsEnd));
      if (set && !have) {
        a = ts;
        have = true;
      } else if (!set && have) {
        break;  // the run ends where this part begins
      }
      ts = te;
      const int st = axisOf(step, axis);
      const int c = axisOf(sc, axis) + st;
      setAxis(sc, axis, c);
      setAxis(sNext, axis, axisOf(sNext, axis) + float(st) * S * axisOf(inv, axis));
      if (c < 0 || c >= kSubPerAxis) ts = tsEnd;  // left the brick
    }
    if (have) {
      b = ts;
      return true;
    }
    mask = 0;
    return false;
  }

  /// x / B (a coordinate in bricks), as a multiplication where that is exact.
  SS_FUNC float inBricks(float x) const { return invB != 0.f ? x * invB : x / B; }

  /// Where the ray meets the face k (0..kSubPerAxis) of the parts of the brick at `base` (its
  /// low corner along axis a); S is a part's size. The clip, the start and the part DDA share it.
  SS_FUNC float partFace(int a, float base, float S, int k) const {
    return (base + float(k) * S - axisOf(org, a)) * axisOf(inv, a);
  }

  /// Starts walking the parts of brick `c` (mask `m`) from t0 to t1. The walk is clipped to
  /// the box of the set parts first (setPartBox; nothing to clip when it is the whole brick):
  /// the parts outside it are unset and a sample on their faces has opacity 0 (the parts' +1
  /// halo), so the runs give the same samples, and a ray that misses the box walks nothing
  /// (mask 0).
  SS_FUNC void enterParts(vec3i c, uint64_t m, float t0, float t1) {
    const float S = B * (1.f / float(kSubPerAxis));
    mask = 0;
    if (m == 0) return;  // emptied by an edit since its byte was written: nothing to walk
    vec3i lo, hi;
    setPartBox(m, lo, hi);
    const bool wholeBox = (lo.x | lo.y | lo.z) == 0 && (hi.x & hi.y & hi.z) == kSubPerAxis - 1;
    for (int a = 0; a < 3; ++a) {
      const int st = axisOf(step, a);
      if (st == 0 || wholeBox) continue;
      const float base = float(axisOf(c, a)) * B;
      const float tLo = partFace(a, base, S, axisOf(lo, a));
      const float tHi = partFace(a, base, S, axisOf(hi, a) + 1);
      t0 = ss_max(t0, st > 0 ? tLo : tHi);
      t1 = ss_min(t1, st > 0 ? tHi : tLo);
    }
    mask = t0 < t1 ? m : 0;
    ts = t0;
    tsEnd = t1;
    const vec3f p = org + dir * t0;
    for (int a = 0; a < 3; ++a) {
      const float base = float(axisOf(c, a)) * B;
      int k = int(floorf(inBricks(axisOf(p, a) - base) * float(kSubPerAxis)));
      k = ss_maxi(0, ss_mini(k, kSubPerAxis - 1));
      const int st = axisOf(step, a);
      // Along the ray's axes the start lies in the box (clamped against rounding); across an
      // axis it never moves, so outside the box's slab no part it meets is set.
      if (st == 0 && (k < axisOf(lo, a) || k > axisOf(hi, a))) mask = 0;
      k = ss_maxi(axisOf(lo, a), ss_mini(k, axisOf(hi, a)));
      setAxis(sc, a, k);
      setAxis(sNext, a, st == 0 ? INFINITY : partFace(a, base, S, st > 0 ? k + 1 : k));
    }
  }

  /// Where the ray leaves cell c along axis a (the cell's far face in the step direction).
  SS_FUNC float exitOf(int a, int c) const {
    const int st = axisOf(step, a);
    return st == 0 ? INFINITY : (float(st > 0 ? c + 1 : c) * B - axisOf(org, a)) * axisOf(inv, a);
  }

  SS_FUNC void init(const GridView& grid, const Ray& r, vec3f invDir, float tmin, float tEnd) {
    g = &grid;
    org = r.org;
    dir = r.dir;
    inv = invDir;
    t = tmin;
    tmax = tEnd;
    B = float(grid.brick);
    invB = (grid.brick & (grid.brick - 1)) == 0 ? 1.f / B : 0.f;
    mask = 0;
    done = !(tmin < tEnd);
    if (done) {  // next() says Done before it reads the DDA's state; set for the compilers' checks
      cell = step = vec3i{0, 0, 0};
      tNext = tDelta = vec3f{0.f, 0.f, 0.f};
      return;
    }
    const vec3f p = org + dir * tmin;
    for (int a = 0; a < 3; ++a) {
      int c = int(floorf(inBricks(axisOf(p, a))));
      c = ss_maxi(0, ss_mini(c, axisOf(grid.dims, a) - 1));
      setAxis(cell, a, c);
      const float d = axisOf(dir, a);
      const int st = d > 0.f ? 1 : d < 0.f ? -1 : 0;
      setAxis(step, a, st);
      setAxis(tDelta, a, st == 0 ? INFINITY : float(st) * B * axisOf(inv, a));
      setAxis(tNext, a, exitOf(a, c));
    }
  }

  template <class Marcher>
  SS_FUNC Step next(const Marcher& m, float& a, float& b) {
    if (Parts && mask && partRun(a, b)) return Step::Interval;
    if (done || !(t < tmax)) {
      done = true;
      return Step::Done;
    }
    const int64_t idx = cell.x + int64_t(g->dims.x) * (cell.y + int64_t(g->dims.y) * cell.z);
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
        const float ta = exitOf(ax, axisOf(cell, ax) + axisOf(step, ax) * rad);  // the cube's far face on axis ax
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
        const int ca = axisOf(cell, ax);
        int c;
        if (ax == ja) {
          c = ca + axisOf(step, ax) * (rad + 1);
        } else {  // still inside the cube's slab on this axis (clamped against rounding)
          c = int(floorf(inBricks(axisOf(q, ax))));
          c = ss_maxi(ss_maxi(ca - rad, 0), ss_mini(c, ss_mini(ca + rad, axisOf(g->dims, ax) - 1)));
        }
        if (c < 0 || c >= axisOf(g->dims, ax)) {  // left the grid
          done = true;
          return Step::Done;
        }
        setAxis(cell, ax, c);
        setAxis(tNext, ax, exitOf(ax, c));
      }
      t = ss_max(t, tJump);
      return Step::Skip;
    }
    const int axis = tNext.x < tNext.y ? (tNext.x < tNext.z ? 0 : 2) : (tNext.y < tNext.z ? 1 : 2);
    const float tExit = ss_max(t, ss_min(axisOf(tNext, axis), tmax));
    a = t;
    b = tExit;
    t = tExit;
    const uint64_t parts = Parts && dist == 0 && walkParts ? g->sub[idx] : ~uint64_t(0);
    if (Parts && parts != ~uint64_t(0)) enterParts(cell, parts, a, tExit);
    const int c = axisOf(cell, axis) + axisOf(step, axis);
    setAxis(cell, axis, c);
    setAxis(tNext, axis, axisOf(tNext, axis) + axisOf(tDelta, axis));
    if (c < 0 || c >= axisOf(g->dims, axis)) done = true;
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
