import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
by = {}
for r in rows:
    by.setdefault(r['dataset'], []).append(r)
print("| shape (occupancy) | naive fps | best fixed (fps) | Auto kept | Auto fps | Auto / naive | Auto / best |")
print("|---|---:|---|---|---:|---:|---:|")
for ds, rs in by.items():
    naive = float([r for r in rs if r['variant'] == 'naive'][0]['fps'])
    fixed = [r for r in rs if not r['variant'].startswith('auto')]
    best = max(fixed, key=lambda r: float(r['fps']))
    a = [r for r in rs if r['variant'].startswith('auto')][0]
    af = float(a['fps'])
    print("| %s (%.3f) | %.2f | %s (%.2f) | %s | %.2f | %.2fx | %.2fx |" % (
        ds.replace('gen:', '').replace(':256', ''), float(a['occupancy']), naive, best['variant'], float(best['fps']),
        a['builder'], af, af / naive, af / float(best['fps'])))
