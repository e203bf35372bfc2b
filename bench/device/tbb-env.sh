# Sourced by the device scripts after `src` is set: oneTBB from a .deps folder beside or inside
# the source tree (the GPU machine has no system oneTBB), for CMake (TBB_DIR) and at run time.
for d in "$src/../.deps/tbb" "$src/.deps/tbb"; do
  if [ -d "$d" ]; then
    export TBB_DIR=$(cd "$d" && pwd)/usr/lib/x86_64-linux-gnu/cmake/TBB
    export LD_LIBRARY_PATH=$(cd "$d" && pwd)/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
    break
  fi
done
