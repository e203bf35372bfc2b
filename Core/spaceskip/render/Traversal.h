// Space-skipping traversals: each yields the ray's possibly non-empty intervals front to back.
// Written once for host and device; `visit(t0, t1)` returns false to stop (early termination).
#pragma once
#include "FrameShared.h"

namespace spaceskip {

/// 3-D DDA (Amanatides & Woo 1987) over the bricks of `g`, restricted to t in [tmin, tmax).
/// Consecutive occupied bricks are merged into one interval (not with value ranges, see GridView). With a distance field, an empty
/// brick at distance d >= 2 is left together with the (2d-1)^3 empty bricks around it: the ray
/// jumps to where it exits that cube (proximity clouds), then the DDA restarts there.
template <class Visit>
SS_FUNC bool traverseGrid(const GridView& g, const Ray& r, vec3f inv, float tmin, float tmax,
                          Visit& visit) {
  if (!(tmin < tmax)) return true;
  const float B = float(g.brick);
  vec3f p = r.org + r.dir * tmin;
  int cell[3], step[3];
  float tNext[3], tDelta[3];
  // Where the ray leaves cell c along axis a (the cell's far face in the step direction).
  auto exitOf = [&](int a, int c) {
    return step[a] == 0 ? INFINITY : (float(step[a] > 0 ? c + 1 : c) * B - r.org[a]) * inv[a];
  };
  for (int a = 0; a < 3; ++a) {
    int c = int(floorf(p[a] / B));
    c = ss_maxi(0, ss_mini(c, g.dims[a] - 1));
    cell[a] = c;
    const float d = r.dir[a];
    step[a] = d > 0.f ? 1 : d < 0.f ? -1 : 0;
    tDelta[a] = step[a] == 0 ? INFINITY : float(step[a]) * B * inv[a];
    tNext[a] = exitOf(a, c);
  }
  float t = tmin;
  float runStart = -1.f;
  bool inRun = false;
  while (t < tmax) {
    const int64_t idx = cell[0] + int64_t(g.dims.x) * (cell[1] + int64_t(g.dims.y) * cell[2]);
    const int dist = g.vmin ? (visit.active(g.vmin[idx], g.vmax[idx]) ? 0 : 1)
                     : g.dist ? int(g.dist[idx])
                              : (g.occ[idx] != 0 ? 0 : 1);
    const bool occ = dist == 0;
    if (occ && !inRun) {
      runStart = t;
      inRun = true;
    } else if (!occ && inRun) {
      if (!visit(runStart, t)) return false;
      inRun = false;
    }
    if (dist >= 2) {
      // Leave the empty cube [cell - (dist-1), cell + (dist-1)] through its nearest exit face.
      const int rad = dist - 1;
      float tJump = INFINITY;
      int ja = 0;
      for (int a = 0; a < 3; ++a) {
        const float ta = exitOf(a, cell[a] + step[a] * rad);  // the cube's far face on axis a
        if (ta < tJump) {
          tJump = ta;
          ja = a;
        }
      }
      if (!(tJump < tmax)) return true;  // the rest of the ray is empty
      const vec3f q = r.org + r.dir * tJump;
      for (int a = 0; a < 3; ++a) {
        int c;
        if (a == ja) {
          c = cell[a] + step[a] * (rad + 1);
        } else {  // still inside the cube's slab on this axis (clamped against rounding)
          c = int(floorf(q[a] / B));
          c = ss_maxi(ss_maxi(cell[a] - rad, 0), ss_mini(c, ss_mini(cell[a] + rad, g.dims[a] - 1)));
        }
        if (c < 0 || c >= g.dims[a]) return true;  // left the grid
        cell[a] = c;
        tNext[a] = exitOf(a, c);
      }
      t = ss_max(t, tJump);
      continue;
    }
    int axis = tNext[0] < tNext[1] ? (tNext[0] < tNext[2] ? 0 : 2) : (tNext[1] < tNext[2] ? 1 : 2);
    float tExit = ss_max(t, ss_min(tNext[axis], tmax));
    if (g.vmin && inRun) {  // ray-dependent decisions: hand this brick over before the next
      if (!visit(runStart, tExit)) return false;
      inRun = false;
    }
    t = tExit;
    cell[axis] += step[axis];
    tNext[axis] += tDelta[axis];
    if (cell[axis] < 0 || cell[axis] >= g.dims[axis]) break;
  }
  if (inRun) return visit(runStart, tmax < t ? tmax : t);
  return true;
}

/// Ordered front-to-back traversal of the flat tree: the nearer child (by entry distance)
/// first, the farther one pushed on a fixed stack of kMaxTreeHeight entries.
/// `leaf(nodeIndex, t0, t1)` is called per hit leaf.
template <class Leaf>
SS_FUNC bool traverseTree(const TreeView& tv, const Ray& r, vec3f inv, float tmin, float tmax,
                          Leaf& leaf) {
  if (tv.numNodes <= 0) return true;
  // Only node indices are stacked: a popped node's interval is recomputed from its box (the
  // same float operations give the same values), which halves the stack's local-memory traffic.
  int stack[kMaxTreeHeight + 1];
  int sp = 0;
  int node = 0;
  float tn, tf;
  {
    const box3i& b = tv.nodes[0].box;
    intersectBox(r, inv, vec3f{float(b.lo.x), float(b.lo.y), float(b.lo.z)},
                 vec3f{float(b.hi.x), float(b.hi.y), float(b.hi.z)}, tn, tf);
    if (ss_max(tn, tmin) >= ss_min(tf, tmax)) return true;
  }
  float nodeT0 = ss_max(tn, tmin), nodeT1 = ss_min(tf, tmax);
  for (;;) {
    const Node& n = tv.nodes[node];
    if (n.child < 0) {
      if (!leaf(node, nodeT0, nodeT1)) return false;
    } else {
      float t0[2], t1[2];
      for (int c = 0; c < 2; ++c) {
        const box3i& b = tv.nodes[n.child + c].box;
        intersectBox(r, inv, vec3f{float(b.lo.x), float(b.lo.y), float(b.lo.z)},
                     vec3f{float(b.hi.x), float(b.hi.y), float(b.hi.z)}, t0[c], t1[c]);
        t0[c] = ss_max(t0[c], tmin);
        t1[c] = ss_min(t1[c], tmax);
      }
      bool hit0 = t0[0] < t1[0], hit1 = t0[1] < t1[1];
      if (hit0 && hit1) {
        int nearC = t0[1] < t0[0] ? 1 : 0;
        stack[sp] = n.child + (1 - nearC);
        ++sp;
        node = n.child + nearC;
        nodeT0 = t0[nearC];
        nodeT1 = t1[nearC];
        continue;
      }
      if (hit0 || hit1) {
        int c = hit0 ? 0 : 1;
        node = n.child + c;
        nodeT0 = t0[c];
        nodeT1 = t1[c];
        continue;
      }
    }
    // pop
    if (sp == 0) return true;
    --sp;
    node = stack[sp];
    const box3i& b = tv.nodes[node].box;
    intersectBox(r, inv, vec3f{float(b.lo.x), float(b.lo.y), float(b.lo.z)},
                 vec3f{float(b.hi.x), float(b.hi.y), float(b.hi.z)}, tn, tf);
    nodeT0 = ss_max(tn, tmin);
    nodeT1 = ss_min(tf, tmax);
  }
}

}  // namespace spaceskip
