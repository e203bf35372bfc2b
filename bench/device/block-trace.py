#!/usr/bin/env python3
"""What a render kernel's blocks did, from a block trace (bench/device/block-trace.sh): when each
block started and ended on which SM, what the launch order expected of it, and what the frame
would have taken in other orders.

  block-trace.py [--first N] TRACE...

--first N: also the blocks at launch positions 0..N-1 (a lab build's units launched first, e.g.
isolated on their SMs): their SM, start, time, the other blocks that ran on that SM beside them,
and their warps' march iterations and cycles an iteration.

The order's alternatives are played by a list scheduler: SM count x resident blocks slots, each
block in turn to the slot that frees first, each taking the time it took in the trace. It matched
the traced kernel within 1 % at N-body 2048^3 (724^2 and 1024^2, one H200).
"""
import heapq
import sys

import numpy as np


def load(path):
    b = open(path, "rb").read()
    n, gx, gy, gz, ox, oy, wx, _ = (int(v) for v in np.frombuffer(b[:32], np.uint32))
    hz = float(np.frombuffer(b[32:40], np.float64)[0])
    o = 40
    blocks = np.frombuffer(b[o:o + n * 32], np.uint64).reshape(n, 4)
    o += n * 32
    keys = np.frombuffer(b[o:o + n * 4], np.uint32)
    o += n * 4
    whole = np.frombuffer(b[o:], np.uint32)
    return dict(n=n, grid=(gx, gy, gz), origin=(ox, oy), wholeX=wx, hz=hz, blocks=blocks, keys=keys, whole=whole)


def schedule(order, took, slots):
    """The frame's end when blocks start in `order` on `slots` slots, each taking took[unit]."""
    free = [0.0] * slots
    end = 0.0
    for u in order:
        t = heapq.heappop(free) + took[u]
        end = max(end, t)
        heapq.heappush(free, t)
    return end


def neighbourhood_max(cost, gz, gy, gx, r):
    c = cost.reshape(gz, gy, gx)
    out = c.copy()
    for dy in range(-r, r + 1):
        for dx in range(-r, r + 1):
            s = np.zeros_like(c)
            s[:, max(-dy, 0):gy + min(-dy, 0), max(-dx, 0):gx + min(-dx, 0)] = \
                c[:, max(dy, 0):gy + min(dy, 0), max(dx, 0):gx + min(dx, 0)]
            out = np.maximum(out, s)
    return out.reshape(-1)


def main(paths, first=0):
    for path in paths:
        t = load(path)
        n, (gx, gy, gz), hz, blocks = t["n"], t["grid"], t["hz"], t["blocks"]
        sm = (blocks[:, 0] >> np.uint64(32)).astype(int)
        unit = (blocks[:, 0] & np.uint64(0xffffffff)).astype(int)
        start = blocks[:, 1].astype(np.int64)
        end = blocks[:, 2].astype(np.int64)
        t0 = start.min()
        start, end = (start - t0) / 1e3, (end - t0) / 1e3  # us
        took = np.zeros(n)
        took[unit] = blocks[:, 3].astype(float) / hz * 1e6  # us by the SM clock
        # The last frame's cycles of each unit on its own tile (the keys before the neighbours).
        u = np.arange(n)
        r = u % (gx * gy)
        ox, oy = t["origin"]
        own = t["whole"][((r // gx + oy) * t["wholeX"] + (r % gx + ox)) * gz + u // (gx * gy)].astype(float) / hz * 1e6
        sms = sm.max() + 1
        per_sm = np.array([blocks[:, 0][sm == s].size for s in range(sms)])
        resident = int(round(np.median([np.max(np.sum((start[sm == s][:, None] <= start[sm == s][None, :]) &
                                                       (end[sm == s][:, None] > start[sm == s][None, :]), axis=0))
                                        for s in range(min(sms, 8))])))
        slots = sms * resident
        sm_end = np.array([end[sm == s].max() for s in range(sms)])
        print(f"{path}: {n} blocks, grid {gx} x {gy} x {gz}, {sms} SMs x {resident} resident")
        print(f"  kernel {end.max():.1f} us; SMs end at {sm_end.mean():.1f} us on average, "
              f"{np.percentile(sm_end, 50):.1f} median, {sm_end.max():.1f} last; blocks per SM {per_sm.min()}-{per_sm.max()}")
        slowest = int(np.argmax(end - start))
        print(f"  slowest block {end[slowest] - start[slowest]:.1f} us (started {start[slowest]:.1f} us, "
              f"launch position {slowest}); its own tile's cycles the frame before {own[unit[slowest]]:.1f} us")
        last = int(np.argmax(end))
        print(f"  block that ended last: started {start[last]:.1f} us, took {end[last] - start[last]:.1f} us, "
              f"launch position {last}; its own tile's cycles the frame before {own[unit[last]]:.1f} us")
        print(f"  the blocks' time over the slots {took.sum() / slots:.1f} us (the frame if nothing waited)")
        orders = {
            "as traced": unit,
            "row-major": np.arange(n),
            "own tile, last frame": np.argsort(-own, kind="stable"),
            "3x3 tiles, last frame": np.argsort(-neighbourhood_max(own, gz, gy, gx, 1), kind="stable"),
            "5x5 tiles, last frame": np.argsort(-neighbourhood_max(own, gz, gy, gx, 2), kind="stable"),
            "this frame's times (ideal)": np.argsort(-took, kind="stable"),
        }
        for name, order in orders.items():
            print(f"  scheduled, {name:27s} {schedule(order, took, slots):7.1f} us")
        counts(path, t, took, first, dict(sm=sm, unit=unit, start=start, end=end))


def counts(path, t, took, first=0, trace=None):
    """With TRACE.counts (each pixel's samples and march iterations in each segment): what the
    slowest blocks' rays did against the median block's. A warp is two rows of a 16 x 8 tile."""
    try:
        c = np.fromfile(path + ".counts", np.uint32)
    except OSError:
        return
    w, h = (int(v) for v in path.rsplit("trace-", 1)[1].split(".")[0].split("x"))
    gx, gy, gz = t["grid"]
    ox, oy = t["origin"]
    layers = gz * h * w
    samples = c[:layers].reshape(gz, h, w).astype(float)
    iters = c[layers:2 * layers].reshape(gz, h, w).astype(float)

    def block(u):
        r = u % (gx * gy)
        x0, y0, z = (r % gx + ox) * 16, (r // gx + oy) * 8, u // (gx * gy)

        def tile(a):  # the unit's 16 x 8 pixels, zeros beyond the frame's edge
            t = np.zeros((8, 16))
            v = a[z, y0:y0 + 8, x0:x0 + 16]
            t[:v.shape[0], :v.shape[1]] = v
            return t

        return tile(samples), tile(iters)

    order = np.argsort(-took)
    rows = [("slowest", int(order[k])) for k in range(5)] + [("median", int(order[len(order) // 2]))]
    print("  block         us  segment  samples max/mean  iterations max/mean  warp max iterations"
          "  cycles per warp iteration")
    def warps(u, i):  # the unit's warps' most iterations, and its cycles over the slowest's
        warp = i.reshape(4, 32).max(axis=1)
        return f"{' '.join(f'{v:.0f}' for v in warp):>20s}  {took[u] * t['hz'] / 1e6 / max(warp.max(), 1):9.0f}"

    for name, u in rows:
        s, i = block(u)
        print(f"  {name:8s} {took[u]:8.1f}  {u // (gx * gy):7d}  {s.max():8.0f} / {s.mean():7.1f}"
              f"  {i.max():9.0f} / {i.mean():7.1f}  {warps(u, i)}")
    if first and trace is not None:
        sm, unit, start, end = trace["sm"], trace["unit"], trace["start"], trace["end"]
        print(f"  the first {first} launch positions: position  SM  start us  took us  blocks beside"
              "  warp max iterations  cycles per warp iteration")
        for p in range(min(first, len(unit))):
            u = int(unit[p])
            beside = int(np.sum((sm == sm[p]) & (start < end[p]) & (end > start[p]))) - 1
            print(f"  {p:8d} {sm[p]:4d} {start[p]:9.1f} {end[p] - start[p]:8.1f} {beside:6d}  {warps(u, block(u)[1])}")
    total_s, total_i = samples.sum(), iters.sum()
    print(f"  frame: {total_s:.0f} samples, {total_i:.0f} iterations; "
          f"{(samples > 0).sum()} pixel segments with samples of {layers}")


if __name__ == "__main__":
    args = sys.argv[1:]
    first = 0
    if args[:1] == ["--first"] and len(args) > 1:
        first, args = int(args[1]), args[2:]
    if not args:
        sys.exit(__doc__)
    main(args, first)
