import csv,sys
rows=[]
for f in sys.argv[1:]:
    rows+=list(csv.DictReader(open(f)))
by={}
for r in rows:
    if r['status']!='ok': continue
    by.setdefault(r['dataset'],[]).append(r)
print("| data set | naive | best fixed (which) | Auto (chose) | Auto / best | Auto / naive |")
print("|---|---:|---:|---:|---:|---:|")
for d,rs in by.items():
    naive=[float(r['kernel_fps']) for r in rs if r['variant']=='naive'][0]
    fixed=[(float(r['kernel_fps']),r['variant']) for r in rs if r['variant'] not in ('naive','auto')]
    best=max(fixed)
    a=[r for r in rs if r['variant']=='auto'][0]
    af=float(a['kernel_fps'])
    print("| %s | %.1f | %.1f (%s) | %.1f (%s) | %.3f | %.2f |"%(d,naive,best[0],best[1],af,a['builder'],af/best[0],af/naive))
