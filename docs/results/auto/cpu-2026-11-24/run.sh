set -e
VOLS="gen:menger:256 gen:nbody:256 gen:shell:256 gen:noise:256 gen:rm:256 gen:vessels:256 gen:aneurism:256 gen:xmas_tree:256 gen:magnetic:256 gen:stag_beetle:256 gen:kingsnake:256 gen:richtmyer_meshkov:256"
B=naive,grid,distance-grid,lbvh,lbvh-cpu,kdtree-cpu:deep:mls32,kdtree-cpu:deep:mls128,kdtree-cpu:empty,hybrid,auto
for which in after before; do
  if [ $which = after ]; then BIN=build/Core/spaceskip; else BIN=before/build/Core/spaceskip; fi
  ( uptime; /usr/bin/time -v $BIN bench $VOLS --builders $B --size 256x256 --frames 8 --backend cpu --csv $which.csv; uptime ) > $which.log 2>&1
done
