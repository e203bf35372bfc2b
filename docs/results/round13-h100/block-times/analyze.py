# Block timing analysis: per frame, kernel span, SM busy fraction, active blocks over time,
# the longest blocks and where they are.
import struct, sys, glob, statistics as st
for path in sorted(glob.glob(sys.argv[1] + '.*.bin'), key=lambda p: int(p.split('.')[-2])):
    data = open(path, 'rb').read()
    gx, gy, bx, by = struct.unpack('4I', data[:16])
    n = gx * gy
    v = struct.unpack('%dQ' % (3 * n), data[16:16 + 24 * n])
    t0 = [v[3*i] for i in range(n)]; t1 = [v[3*i+1] for i in range(n)]; sm = [v[3*i+2] for i in range(n)]
    base = min(t0); end = max(t1); span = (end - base) / 1e3
    dur = [(t1[i] - t0[i]) / 1e3 for i in range(n)]
    # per SM busy time: union of its block intervals
    bysm = {}
    for i in range(n): bysm.setdefault(sm[i], []).append((t0[i], t1[i]))
    busy = []
    for s_, iv in bysm.items():
        iv.sort(); tot = 0; cs, ce = iv[0]
        for a, b in iv[1:]:
            if a > ce: tot += ce - cs; cs, ce = a, b
            else: ce = max(ce, b)
        tot += ce - cs; busy.append(tot / 1e3)
    # SM finish times
    smend = sorted((max(b for a, b in iv) - base) / 1e3 for iv in bysm.values())
    # active blocks over time in 10 slices
    slices = []
    for k in range(10):
        a = base + (end - base) * k / 10; b = base + (end - base) * (k + 1) / 10
        slices.append(sum(1 for i in range(n) if t0[i] < b and t1[i] > a))
    sd = sorted(range(n), key=lambda i: -dur[i])
    print('%s: grid %dx%d block %dx%d span %.1f us; block dur mean %.1f median %.1f max %.1f us; SMs %d busy mean %.1f us (%.0f%% of span); SM finish min %.0f median %.0f max %.0f us' % (
        path.split('/')[-1], gx, gy, bx, by, span, st.mean(dur), st.median(dur), max(dur), len(bysm), st.mean(busy), 100 * st.mean(busy) / span, smend[0], smend[len(smend)//2], smend[-1]))
    print('   blocks in flight per tenth of the span:', slices)
    print('   longest blocks (us, tile x,y, start us):', [('%.0f' % dur[i], i % gx, i // gx, '%.0f' % ((t0[i]-base)/1e3)) for i in sd[:8]])
    # what fraction of the span is after the 90th-percentile SM finished
    print('   time after 90%% of SMs finished: %.0f us; blocks starting in the last 30%% of span: %d' % (smend[-1] - smend[int(0.9*len(smend))], sum(1 for i in range(n) if (t0[i]-base)/1e3 > 0.7*span)))
