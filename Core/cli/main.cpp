// spaceskip: command-line renderer, generator and benchmark over Core (no VTK). This file
// dispatches; each command lives in its own file (Commands.h).
#include "Commands.h"
#include "spaceskip/Builders.h"

#include <tbb/global_control.h>

#include <cstdio>
#include <cstring>
#include <memory>
#include <new>
#include <string>

using namespace spaceskip;
using namespace spaceskip::cli;

namespace {

const char* kUsage = R"(usage:
  spaceskip generate SHAPE --dims X Y Z [--seed N] -o FILE(.nrrd|_XxYxZ_TYPE.raw)
      SHAPE: menger nbody shell noise rm vessels, and the paper's data sets: aneurism xmas_tree
      magnetic stag_beetle kingsnake richtmyer_meshkov; labels (256 labelled blobs, uint16) or
      labelsN (N labels, uint8 up to 255)
  spaceskip render VOLUME -o out.png [options]
  spaceskip accuracy VOLUME [--builder B] [--size WxH] [--csv FILE] [options]
      speed/accuracy trade: sample distance 0.25-4 voxels x filter x ERT x jitter vs PSNR/SSIM
      against a fine reference, and fps (scripts/plot_pareto.py draws the Pareto fronts)
  spaceskip bench VOLUME... [--builders b1,b2,...] [--frames N] [--json FILE] [--csv FILE] [options]
      each builder may carry suffixes overriding --leaf/--mls/--bins/--brick, e.g.
      --builders naive,grid,lbvh-cpu,kdtree-cpu:shallow,kdtree-cpu:deep:mls32,kdtree-cpu:deep:mls128,hybrid
      or kdtree-gpu-fast:deep:mls32:bins0 (the sweep: the kdtree-cpu:deep:mls32 tree)
      --build-reps N: report the fastest of N rebuilds (default 1)
      bench-only suffixes: :hw / :exact (filter for this item), :cold (time the first build only),
      :resN (CUDA: persistent launch with N blocks per SM; res0 = plain), :whole (no sub-brick
      masks: occupied bricks marched whole), :partsN (bricks with <= N of 64 parts set walked by parts,
      on the CPU backend too, which marches whole bricks by default)
      --edits N [--edit-cut C]: after an item's frames, N opacity edits at a still view, alternately
      zeroing the TF's opacity below C of the range (default 0.3: bricks empty) and restoring it
      (bricks occupied again), each timed to its first frame finished on the device (the image
      left there, as the mapper's window path does), with a frame after each; the line
      "edits:" gives each kind's mean: classification (of it the wait for the device), build, frame
  spaceskip bench --paper [--scale F] [--datasets a,b] [--builders k1,k2] [--frames N] [--time-limit S]
                  [--csv FILE] [--json FILE] [options]
      the paper's whole benchmark: stand-ins for its 11 data sets (dims x F), every builder and
      parameter set of its table (naive lbvh cpu_shallow cpu_mls32 cpu_mls128 gpu_shallow gpu_mls32
      gpu_mls128 hybrid) plus ours (grid distance_grid kdtree_gpu_fast kdtree_empty auto), 1024x1024,
      rotating orthographic camera, no ERT; progress on stderr; --time-limit S stops starting new
      items after S seconds (the rest are written as skipped). Figures: scripts/plot-paper-bench.py

  spaceskip bench VOLUME --label-map blend|nearest [--builder B] [--frames N] [--toggles N]
                  [--visible-every K] [options]
      the label-map benchmark (one VOLUME of 8/16-bit ids, e.g. gen:labels:512 or gen:labelsN:512):
      first frame (upload, label sets, classification, build), fps with every label visible and
      with the ids % K == 0 (default 10) against Naive, and N (default 20) hide/show toggles of one
      label at a still view, each setLabelTable + its frame (median, max) against a plain frame,
      with the counters (no voxel pass); exit 4 when a toggle read the voxels

  spaceskip bench gen:nbody:N|gen:rm:N --time-series STEPS [--steps-held K] [--step-type uint8|float32] [--step-memory pageable|pinned]
                  [--builder B] [--check] [options]
      time-series playback: K (default min(STEPS, 10)) generated steps of the advected N-body
      stand-in (or of the mixing layer rm, widening over its first 25 steps: hold 25 to see it
      grow) held in memory, STEPS played (cycling), each step's upload, ranges, classification,
      build and frame at an orbiting camera waited for; beside the upload bound (bytes over the
      measured pinned host-to-device rate), Naive and a fresh engine per step; --check compares
      each held step played with its static render (exit 3 above 1/255); --step-memory pinned
      holds the steps in the engine's step memory (page-locked on CUDA: one DMA a step)

  spaceskip sparse VOLUME --memory-budget N[K|M|G] [--pool-brick N] [--builders b1,b2] [--edit-tf PRESET]
                   [--no-in-core] [--frames N] [options]
      sparse residency: only the bricks a frame needs on the device, within the budget; per
      builder the in-core and the sparse run side by side (kernel fps, max difference of every
      frame), and the TF edit --tf -> --edit-tf (default ramp) timed to its first frame

  VOLUME: NAME_XxYxZ_TYPE.raw, FILE.nrrd, or gen:SHAPE:N / gen:SHAPE:XxYxZ (generated in memory)
options:
  --builder B        auto (default: a frame with each of naive, grid, distance-grid and a
                     k-d tree, one more for those within 1.5x of the fastest, then the fastest)
                     or one of the builders listed at the end
  --leaf shallow|deep|empty  --mls N  --bins N  --brick N
      empty: deep, but leaves are kept or split by their empty space, not their size (MLS ignored)
      --bins (kdtree-gpu, kdtree-gpu-fast; default 4): N >= 2 tries N-1 planes per node;
      0 sweeps every brick boundary, the kdtree-cpu tree (kdtree-cpu always sweeps)
  --backend auto|cpu|cuda     --threads N (oneTBB worker limit)
  --cuda-block WxH   CUDA launch shape: threads per block (32..256; default 16x8; also
                     SPACESKIP_CUDA_BLOCK; the other SPACESKIP_* knobs: docs/tuning.md)
  --tf PRESET|FILE   presets: ramp grayscale coolwarm band spike opaque zero
  --tf2d ROWS        a 2-D transfer function (value x gradient magnitude, as VTK's TF_2D): the
                     --tf table's colours, its opacity times a ramp over the gradient magnitude
                     (0 at none, 1 from half the largest); 256 columns x ROWS rows
  --size WxH         (render default 512x512, bench default 1024x1024)
  --max-image-bytes N[K|M|G|T]  largest image (16 bytes a pixel; default 1G: 8192x8192)
  --camera AZ,EL[,ZOOM]  orbit angles in degrees  --perspective
  --sample-distance D  (world units; default half the smallest spacing)
  --ert T  --jitter  --filter exact|hardware
  --blend composite|mip|minip|average|additive|iso   --iso V1,V2,...  (iso values)
  --shade on|AMBIENT,DIFFUSE,SPECULAR,POWER  gradient shading with a headlight (on: 0,0.7,0.2,10)
  --scatter BLENDING,REACH,ANISOTROPY  volumetric shadows and scattering as VTK's GPU mapper
                       (VolumetricScatteringBlending 0..2, GlobalIlluminationReach 0..1,
                       ScatteringAnisotropy -1..1); shades with the headlight
  --nearest          nearest-voxel sampling instead of trilinear
  --rectilinear      the volume's points as a rectilinear grid over the same bounds (x steps
                     growing 1:3, z steps varying ~1:2), drawn through its coordinates
  --label-map nearest|blend  8/16-bit integer voxels as label ids: every id but 0 a label of its
                     own colour, opacity 0.5 (render); blend: smooth borders, never a label that
                     is not among the 8 voxels around a sample   --hide-labels ID1,ID2,...
  --compare REF.png  print max difference and PSNR against a reference image
  --max-diff N       with --compare: exit 3 when the max difference exceeds N/255
  --memory-budget N[K|M|G|T]  the most memory the voxels may take on the device (default: free
                     device memory less what the rest needs); above it the volume stays sparse:
                     only the pool bricks a frame needs are resident (--pool-brick N cells, 16)
  --max-volume-bytes N[K|M|G|T]  largest volume read or generated (default: the environment's
                     SPACESKIP_MAX_VOLUME_BYTES, else min(64 GiB, physical memory))
builders:
)";

/// The usage text and the registry's builders (Builders.cpp), one per line.
void printUsage(FILE* to) {
  std::fputs(kUsage, to);
  int n = 0;
  const BuilderInfo* rows = builderRegistry(&n);
  for (int i = 0; i < n; ++i) std::fprintf(to, "  %-18s %s\n", rows[i].cliName, rows[i].summary);
}


}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || !std::strcmp(argv[1], "-h") || !std::strcmp(argv[1], "--help")) {
    printUsage(argc < 2 ? stderr : stdout);
    return argc < 2 ? 2 : 0;
  }
  try {
    std::string cmd = argv[1];
    Options o = parseArgs(argc, argv, 2);
    // Checked before any work: a bad value is reported even when no volume is loaded.
    (void)maxVolumeBytes(o);
    std::unique_ptr<tbb::global_control> threads;
    if (o.has("--threads"))
      threads = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                      size_t(o.getInt("--threads", 1, 1, 65536)));
    if (cmd == "generate") return cmdGenerate(o);
    if (cmd == "render") return cmdRender(o);
    if (cmd == "bench") return cmdBench(o);
    if (cmd == "accuracy") return cmdAccuracy(o);
    if (cmd == "sparse") return cmdSparse(o);
    std::fprintf(stderr, "unknown command '%s'\n", cmd.c_str());
    printUsage(stderr);
    return 2;
  } catch (const std::bad_alloc&) {
    // The large allocations (volumes, frames, PNGs) name themselves (Commands.h, allocating);
    // this is what is left: an acceleration structure or a buffer of the engine.
    std::fprintf(stderr, "spaceskip: error: out of memory in '%s' (std::bad_alloc); the volume is bounded by "
                 "--max-volume-bytes and the image by --size and --max-image-bytes\n", argv[1]);
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "spaceskip: error: %s\n", e.what());
    return 1;
  }
}
