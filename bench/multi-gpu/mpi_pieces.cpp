// One MPI rank per GPU, two ways to split the work (--split):
// - `slabs` (sort-last, ParaView's way): each rank renders its slab of one volume with the
//   engine (the whole volume's sample lattice, its own cells only: VolumePiece.h), the ranks
//   composite the float images by direct send (each rank blends one band of rows from every rank
//   in visibility order, PieceOrder.h) and rank 0 gathers the bands.
// - `image` (sort-first, for volumes every GPU holds whole): each rank renders one band of the
//   image's rows over the whole volume (the same rays as the whole image: the band's projection
//   is the whole one's, cut in y) and rank 0 gathers the bands; no blend. The bands' heights
//   follow the last frame's render times (--balance frame-time, the default here), since a
//   row's cost varies over the image.
// Frames are waited for; the frame time is the slowest rank's render, the exchange, the blend
// and the gather.
// Two ways to composite (--composite): `host` downloads every image and exchanges it with MPI
// through host memory (MPI_Alltoallv, then MPI_Gatherv to rank 0); `gpu` (the default where the
// ranks have CUDA devices on one host) keeps the images on the GPUs: each rank copies its frame
// into an exchange buffer that the other ranks map through CUDA IPC, and blends its band from all
// of them straight into rank 0's final image on rank 0's GPU (gpu_composite.cu); MPI carries only
// two barriers a frame. It falls back to `host`, and says why, where IPC or peer access fails.
//
// This is the benchmark's stand-in for ParaView's engine (pvbatch with float compositing does
// the same steps: each rank draws its piece into a float image, the images are blended in
// visibility order), made because pvbatch and its closure (414 libraries, 650 MB) cannot travel
// to the GPU machines in one call. Not part of the product.
//
//   mpiexec -n N spaceskip_mpi_pieces [--shape nbody] [--dims 2048] [--size 1024] [--frames 30]
//       [--builder Auto] [--backend auto|cpu|cuda] [--tf ramp] [--check] [--png out.png]
//       [--composite gpu|host] [--split slabs|image] [--balance occupancy|equal|frame-time]
//       [--ray-segments N] [--resident N] [--heaviest-first 0|1]
// --check: rank 0 also renders the whole volume alone and prints the largest difference of
// the composited image from it (8-bit units). --slabs: each rank makes only its slab (volumes
// larger than one host's share or one GPU: no rank holds the whole; with --check rank 0 makes
// it for the reference alone).
// After the orbit every rank edits the transfer function (the ramp over the upper 3/4 of the
// range) and back: each edit's frame is timed (classification, rebuild, render, composite).
#include "spaceskip/Camera.h"
#include "spaceskip/Engine.h"
#include "spaceskip/Generators.h"
#include "spaceskip/ImageIO.h"
#include "spaceskip/PieceOrder.h"
#include "spaceskip/Volume.h"

#include <mpi.h>
#include "gpu_composite.h"

#ifdef SPACESKIP_MPI_PIECES_CUDA
#include <cuda_runtime.h>
#endif

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

using namespace spaceskip;
using Clock = std::chrono::steady_clock;

namespace {

struct Args {
  std::string shape = "nbody", builder = "Auto", backend = "auto", tf = "ramp", png;
  std::string composite;  // gpu or host; empty: gpu where every rank has a CUDA device on one host
  std::string split = "slabs";  // or image
  std::string balance;          // slabs: occupancy (default) or equal; image: frame-time (default) or equal
  int64_t dims = 256;
  int size = 512, frames = 20;
  int raySegments = 0;  // Tuning::raySegments (0: the engine's choice)
  int heaviestFirst = -1;  // Tuning::heaviestFirst (-1: the engine's default)
  int resident = -1;    // Tuning::resident (-1: the engine's choice)
  bool check = false, slabs = false;
};

Args parse(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    std::string k = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "%s needs a value\n", k.c_str());
        MPI_Abort(MPI_COMM_WORLD, 2);
      }
      return argv[++i];
    };
    if (k == "--shape") a.shape = next();
    else if (k == "--dims") a.dims = std::atoll(next().c_str());
    else if (k == "--size") a.size = std::atoi(next().c_str());
    else if (k == "--frames") a.frames = std::atoi(next().c_str());
    else if (k == "--builder") a.builder = next();
    else if (k == "--backend") a.backend = next();
    else if (k == "--tf") a.tf = next();
    else if (k == "--png") a.png = next();
    else if (k == "--composite") a.composite = next();
    else if (k == "--balance") a.balance = next();
    else if (k == "--split") a.split = next();
    else if (k == "--ray-segments") a.raySegments = std::atoi(next().c_str());
    else if (k == "--heaviest-first") a.heaviestFirst = std::atoi(next().c_str());
    else if (k == "--resident") a.resident = std::atoi(next().c_str());
    else if (k == "--check") a.check = true;
    else if (k == "--slabs") a.slabs = true;
    else {
      std::fprintf(stderr, "unknown option %s\n", k.c_str());
      MPI_Abort(MPI_COMM_WORLD, 2);
    }
  }
  if (a.split != "slabs" && a.split != "image") {
    std::fprintf(stderr, "--split takes slabs or image\n");
    MPI_Abort(MPI_COMM_WORLD, 2);
  }
  const bool image = a.split == "image";
  if (a.balance.empty()) a.balance = image ? "frame-time" : "occupancy";
  if (a.balance != "equal" && a.balance != (image ? "frame-time" : "occupancy")) {
    std::fprintf(stderr, "--balance takes %s or equal with --split %s\n", image ? "frame-time" : "occupancy",
                 a.split.c_str());
    MPI_Abort(MPI_COMM_WORLD, 2);
  }
  if (image && a.slabs) {
    std::fprintf(stderr, "--split image draws the whole volume on every rank: no --slabs\n");
    MPI_Abort(MPI_COMM_WORLD, 2);
  }
  if (!a.composite.empty() && a.composite != "gpu" && a.composite != "host") {
    std::fprintf(stderr, "--composite takes gpu or host\n");
    MPI_Abort(MPI_COMM_WORLD, 2);
  }
  if (a.dims < 8 || a.size < 8 || a.frames < 1) {
    std::fprintf(stderr, "--dims and --size must be >= 8, --frames >= 1\n");
    MPI_Abort(MPI_COMM_WORLD, 2);
  }
  return a;
}

double seconds(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

BackendKind backendOf(const std::string& s) {
  if (s == "cpu") return BackendKind::CPU;
  if (s == "cuda") return BackendKind::CUDA;
  return BackendKind::Auto;
}

/// `back` blended behind `acc`, pixel by pixel (gpu_composite.h, as the GPU path's kernel).
void over(vec4f* acc, const vec4f* back, size_t n) {
  for (size_t i = 0; i < n; ++i) acc[i] = mpi::behind(acc[i], back[i]);
}

int to8(float v) { return int(std::lround(std::min(1.f, std::max(0.f, v)) * 255.f)); }

/// Slab cuts (cells along z: rank r draws [cuts[r], cuts[r + 1])) that give each rank about the
/// same number of visible voxels (the transfer function's opacity > 0 at the voxel's value;
/// every other voxel in x and y counted) plus 1/16 of a slice's voxels per slice, for the cost
/// every ray pays in a slab whatever it holds. Integer counts: every rank finds the same cuts.
/// uint8 and float32 volumes; others get equal slabs.
std::vector<int64_t> balancedCuts(const Volume& v, const TransferFunction& tf, int ranks) {
  const int64_t cells = v.dims.z - 1;
  std::vector<int64_t> cuts(size_t(ranks) + 1);
  for (int r = 0; r <= ranks; ++r) cuts[size_t(r)] = cells * r / ranks;
  if ((v.type != VoxelType::UInt8 && v.type != VoxelType::Float32) || v.components != 1 || tf.table.empty() ||
      !(tf.rangeMax > tf.rangeMin))
    return cuts;
  const int n = int(tf.table.size());
  auto visible = [&](double x) {
    const double u = (x - tf.rangeMin) / (tf.rangeMax - tf.rangeMin) * (n - 1);
    const int i = int(std::lround(std::min(double(n - 1), std::max(0.0, u))));
    return tf.table[size_t(i)].w > 0.f;
  };
  bool lut[256];
  for (int i = 0; i < 256; ++i) lut[i] = visible(i);
  const int64_t nx = v.dims.x, ny = v.dims.y, slice = nx * ny;
  std::vector<int64_t> count(size_t(v.dims.z), 0);
  tbb::parallel_for(int64_t(0), int64_t(v.dims.z), [&](int64_t z) {
    int64_t c = 0;
    for (int64_t y = 0; y < ny; y += 2)
      for (int64_t x = 0; x < nx; x += 2) {
        const size_t i = size_t(z * slice + y * nx + x);
        c += v.type == VoxelType::UInt8 ? lut[static_cast<const uint8_t*>(v.data)[i]]
                                        : visible(static_cast<const float*>(v.data)[i]);
      }
    count[size_t(z)] = c + (slice / 4) / 16;
  });
  // Cell z spans the slices z and z + 1.
  std::vector<int64_t> prefix(size_t(cells) + 1, 0);
  for (int64_t z = 0; z < cells; ++z) prefix[size_t(z) + 1] = prefix[size_t(z)] + count[size_t(z)] + count[size_t(z) + 1];
  const int64_t total = prefix.back();
  for (int r = 1; r < ranks; ++r) {
    const int64_t want = total / ranks * r;
    const auto it = std::lower_bound(prefix.begin(), prefix.end(), want);
    cuts[size_t(r)] = std::clamp<int64_t>(int64_t(it - prefix.begin()), cuts[size_t(r) - 1] + 1, cells - (ranks - r));
  }
  return cuts;
}

/// The camera that draws rows [lo, hi) of an image `h` rows high (row 0 at the bottom) as an image
/// of its own: the projection followed by the map of that band's NDC y range onto [-1, 1], so
/// that the band's pixel centres unproject to the whole image's rays.
Camera bandCamera(const Camera& whole, int lo, int hi, int h) {
  const double a = double(hi - lo) / h, b = double(lo + hi) / h - 1.0;  // y_ndc = a * y_band + b
  mat4 cut = identity4();  // clip y' = (y - b w) / a
  cut.m[1 * 4 + 1] = 1.0 / a;
  cut.m[3 * 4 + 1] = -b / a;
  Camera c = whole;
  c.proj = multiply(cut, whole.proj);
  return c;
}

/// Row cuts (rank r draws rows [cuts[r], cuts[r + 1])) for the next frame from this frame's
/// cuts and the ranks' render times: each band's time spread evenly over its rows, the new cuts
/// at equal shares of the total, half way from the old ones (damped: a camera moves between
/// frames), at least `minRows` rows a band. Every rank computes the same cuts from the same times.
std::vector<int> rebalancedRows(const std::vector<int>& cuts, const std::vector<double>& times, int minRows) {
  const int n = int(times.size()), h = cuts.back();
  double total = 0;
  for (double t : times) total += std::max(t, 0.0);
  if (!(total > 0)) return cuts;
  std::vector<int> next(cuts);
  int r = 0;
  double before = 0;  // the time of bands [0, r)
  for (int k = 1; k < n; ++k) {
    const double want = total * k / n;
    while (r < n - 1 && before + std::max(times[size_t(r)], 0.0) < want) before += std::max(times[size_t(r)], 0.0), ++r;
    const double t = std::max(times[size_t(r)], 0.0);
    const double rows = double(cuts[size_t(r) + 1] - cuts[size_t(r)]);
    const double target = cuts[size_t(r)] + (t > 0 ? (want - before) / t * rows : 0.0);
    const int moved = int(std::lround(0.5 * (cuts[size_t(k)] + target)));
    next[size_t(k)] = std::clamp(moved, next[size_t(k) - 1] + minRows, h - (n - k) * minRows);
  }
  return next;
}

#ifdef SPACESKIP_MPI_PIECES_CUDA
/// The GPU compositing's buffers: this rank's exchange buffer (its frame's copy), every rank's
/// mapped into this process through CUDA IPC, and rank 0's final image (mapped here too).
struct GpuExchange {
  void* mine = nullptr;
  void* final0 = nullptr;  // rank 0: the final image it owns
  void* finalMapped = nullptr;
  std::vector<void*> peers;
  cudaStream_t stream = nullptr;
  std::string why;  // why it cannot be used (empty: ready)
};

/// Sets up `g` on every rank; true on every rank or on none (then `why` says why, on the rank
/// that failed and on rank 0).
bool setupGpuExchange(GpuExchange& g, int rank, int ranks, size_t bytes, MPI_Comm node) {
  int nodeSize = 0;
  MPI_Comm_size(node, &nodeSize);
  auto fail = [&](const std::string& w) {
    if (g.why.empty()) g.why = w;
  };
  auto ck = [&](cudaError_t e, const char* what) {
    if (e != cudaSuccess) fail(std::string(what) + ": " + cudaGetErrorString(e));
    return e == cudaSuccess;
  };
  if (nodeSize != ranks) fail("the ranks are not all on one host (CUDA IPC maps memory of one host)");
  if (ranks > spaceskip::mpi::kMaxRanks) fail("more than " + std::to_string(spaceskip::mpi::kMaxRanks) + " ranks");
  if (g.why.empty()) {
    ck(cudaMalloc(&g.mine, bytes), "cudaMalloc (exchange buffer)");
    if (rank == 0 && g.why.empty()) ck(cudaMalloc(&g.final0, bytes), "cudaMalloc (final image)");
    if (g.why.empty()) ck(cudaStreamCreateWithFlags(&g.stream, cudaStreamNonBlocking), "cudaStreamCreate");
  }
  // Every rank takes part in each collective below, failed or not.
  cudaIpcMemHandle_t h{}, hf{};
  if (g.why.empty()) ck(cudaIpcGetMemHandle(&h, g.mine), "cudaIpcGetMemHandle");
  if (rank == 0 && g.why.empty()) ck(cudaIpcGetMemHandle(&hf, g.final0), "cudaIpcGetMemHandle (final)");
  int okHere = g.why.empty() ? 1 : 0, okAll = 0;
  MPI_Allreduce(&okHere, &okAll, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  std::vector<cudaIpcMemHandle_t> all(static_cast<size_t>(ranks));
  MPI_Allgather(&h, sizeof h, MPI_BYTE, all.data(), sizeof h, MPI_BYTE, MPI_COMM_WORLD);
  MPI_Bcast(&hf, sizeof hf, MPI_BYTE, 0, MPI_COMM_WORLD);
  if (okAll) {
    g.peers.assign(size_t(ranks), nullptr);
    for (int r = 0; r < ranks && g.why.empty(); ++r) {
      if (r == rank) g.peers[size_t(r)] = g.mine;
      else ck(cudaIpcOpenMemHandle(&g.peers[size_t(r)], all[size_t(r)], cudaIpcMemLazyEnablePeerAccess),
              "cudaIpcOpenMemHandle (a rank's image)");
    }
    if (g.why.empty()) {
      if (rank == 0) g.finalMapped = g.final0;
      else ck(cudaIpcOpenMemHandle(&g.finalMapped, hf, cudaIpcMemLazyEnablePeerAccess),
              "cudaIpcOpenMemHandle (rank 0's final image)");
    }
  } else if (g.why.empty()) {
    g.why = "another rank could not set up its exchange buffer";
  }
  okHere = g.why.empty() ? 1 : 0;
  MPI_Allreduce(&okHere, &okAll, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  if (!okAll && g.why.empty()) g.why = "another rank could not map the exchange buffers";
  return okAll == 1;
}

void releaseGpuExchange(GpuExchange& g, int rank) {
  for (size_t r = 0; r < g.peers.size(); ++r)
    if (int(r) != rank && g.peers[r]) cudaIpcCloseMemHandle(g.peers[r]);
  if (rank != 0 && g.finalMapped) cudaIpcCloseMemHandle(g.finalMapped);
  if (g.stream) cudaStreamDestroy(g.stream);
  cudaFree(g.mine);
  cudaFree(g.final0);
  g = GpuExchange{};
}
#endif

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  int rank = 0, ranks = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  const Args a = parse(argc, argv);

  // The node-local rank picks the GPU (ranks of one host share its GPUs round-robin).
  MPI_Comm node;
  MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, rank, MPI_INFO_NULL, &node);
  int localRank = 0;
  MPI_Comm_rank(node, &localRank);
  int device = -1;
  std::string deviceName = "cpu";
#ifdef SPACESKIP_MPI_PIECES_CUDA
  int count = 0;
  if (a.backend != "cpu" && cudaGetDeviceCount(&count) == cudaSuccess && count > 0) {
    device = localRank % count;
    cudaSetDevice(device);
    cudaDeviceProp prop{};
    cudaGetDeviceProperties(&prop, device);
    char bus[32] = {};
    cudaDeviceGetPCIBusId(bus, sizeof bus, device);
    deviceName = std::string(prop.name) + " " + bus;
  }
#endif

  // Every rank makes the whole volume (the generators are deterministic; with --slabs only its
  // slab) and draws a slab of it along z: cells [z0, z1), its points with one ghost layer on
  // each side. The slabs hold equal shares of the visible voxels (--balance occupancy, the
  // default with the whole volume at hand) or equal numbers of cells (--balance equal, --slabs).
  const auto t0 = Clock::now();
  const vec3l wdims{a.dims, a.dims, a.dims};
  const int64_t cells = wdims.z - 1;
  std::vector<int64_t> cuts(size_t(ranks) + 1);
  for (int r = 0; r <= ranks; ++r) cuts[size_t(r)] = cells * r / ranks;
  Volume whole, piece;
  double lo = 0, hi = 0;
  auto pointsOf = [&](int64_t c0, int64_t c1, int64_t& p0, int64_t& p1) {
    p0 = std::max<int64_t>(c0 - 1, 0);
    p1 = std::min<int64_t>(c1 + 1, wdims.z - 1);
  };
  int64_t p0 = 0, p1 = 0;
  if (a.slabs) {
    pointsOf(cuts[size_t(rank)], cuts[size_t(rank) + 1], p0, p1);
    piece = generateSlab(a.shape, wdims, p0, p1);
    whole.dims = wdims;  // the header only: bounds and lattice
    whole.type = piece.type;
    std::copy(piece.origin, piece.origin + 3, whole.origin);
    std::copy(piece.spacing, piece.spacing + 3, whole.spacing);
    // The transfer function spans the range over all ranks' pieces (the whole volume's).
    double range[2] = {0, 1};
    if (!piece.scalarRange(range[0], range[1])) range[0] = 1, range[1] = 0;
    MPI_Allreduce(&range[0], &lo, 1, MPI_DOUBLE, MPI_MIN, MPI_COMM_WORLD);
    MPI_Allreduce(&range[1], &hi, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  } else {
    whole = generateVolume(a.shape, wdims);
    if (!whole.scalarRange(lo, hi)) lo = 1, hi = 0;
  }
  if (!(hi >= lo)) lo = 0, hi = 1;
  const TransferFunction tf = TransferFunction::preset(a.tf, lo, hi);
  const TransferFunction edited = TransferFunction::preset(a.tf, lo + 0.25 * (hi - lo), hi);
  const bool image = a.split == "image";
  const bool balanced = !a.slabs && a.balance != "equal";
  if (balanced && !image) cuts = balancedCuts(whole, tf, ranks);
  if (image) cuts = {0, cells};  // every rank draws the whole volume
  const int64_t z0 = cuts[size_t(image ? 0 : rank)], z1 = cuts[size_t(image ? 1 : rank + 1)];
  if (!a.slabs) {
    pointsOf(z0, z1, p0, p1);
    piece = whole;
    piece.storage.reset();
    piece.dims.z = p1 - p0 + 1;
    piece.data = static_cast<const unsigned char*>(whole.data) +
                 size_t(p0) * size_t(whole.dims.x * whole.dims.y) * voxelSize(whole.type);
  }
  piece.origin[2] = whole.origin[2] + whole.spacing[2] * double(p0);
  VolumePiece vp;
  vp.wholeDims = whole.dims;
  std::copy(whole.origin, whole.origin + 3, vp.wholeOrigin);
  vp.offset = vec3l{0, 0, p0};
  vp.ownedLo = vec3l{0, 0, z0};
  vp.ownedHi = vec3l{whole.dims.x - 1, whole.dims.y - 1, z1};

  Engine engine(backendOf(a.backend), [rank](const std::string& m) {
    std::fprintf(stderr, "[rank %d] %s\n", rank, m.c_str());
  });
  BuildParams bp;
  if (!parseBuilder(a.builder, bp.builder)) {
    if (rank == 0) std::fprintf(stderr, "unknown builder %s\n", a.builder.c_str());
    MPI_Abort(MPI_COMM_WORLD, 2);
  }
  engine.setBuildParams(bp);
  if (a.raySegments > 0 || a.resident >= 0 || a.heaviestFirst >= 0) {  // the GPU launch's knobs (Tuning.h)
    Tuning tu = engine.tuning();
    if (a.raySegments > 0) tu.raySegments = a.raySegments;
    if (a.heaviestFirst >= 0) tu.heaviestFirst = a.heaviestFirst != 0;
    if (a.resident >= 0) tu.resident = a.resident;
    engine.setTuning(tu);
  }
  engine.setVolume(image ? whole : piece);
  if (!image) engine.setPiece(vp);
  engine.setTransferFunction(tf);

  double b6[6];
  whole.worldBounds(b6);
  const int w = a.size, h = a.size;
  auto camera = [&](int f) { return orbitCamera(b6, 360.0 * f / a.frames, 15, 1, false, double(w) / h); };

  // Bands of rows: rank r blends rows [rowLo(r), rowLo(r + 1)).
  auto rowLo = [&](int r) { return int(int64_t(h) * r / ranks); };
  std::vector<int> counts(ranks), displs(ranks);
  for (int r = 0; r < ranks; ++r) {
    counts[r] = (rowLo(r + 1) - rowLo(r)) * w * 4;
    displs[r] = rowLo(r) * w * 4;
  }
  const int myRows = rowLo(rank + 1) - rowLo(rank);
  std::vector<vec4f> recv(size_t(myRows) * w * ranks), band(size_t(myRows) * w);
  std::vector<int> recvCounts(ranks, myRows * w * 4), recvDispls(ranks);
  for (int r = 0; r < ranks; ++r) recvDispls[r] = r * myRows * w * 4;
  std::vector<PieceBox> boxes(ranks);
  for (int r = 0; r < ranks && !image; ++r)
    boxes[r] = {0.0, double(whole.dims.x - 1), 0.0, double(whole.dims.y - 1), double(cuts[size_t(r)]),
                double(cuts[size_t(r) + 1])};
  Image img, final;
  if (rank == 0) final.width = w, final.height = h, final.rgba.resize(size_t(w) * h);
  [[maybe_unused]] const size_t imageBytes = size_t(w) * size_t(h) * sizeof(vec4f);

  // Compositing on the GPUs (the default where every rank has a CUDA device on one host).
  bool gpuComposite = false;
  std::string noGpuWhy;
#ifdef SPACESKIP_MPI_PIECES_CUDA
  GpuExchange gx;
  {
    int have = device >= 0 ? 1 : 0, haveAll = 0;
    MPI_Allreduce(&have, &haveAll, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    const bool want = a.composite == "gpu" || (a.composite.empty() && haveAll);
    if (want && haveAll) {
      const bool ok = setupGpuExchange(gx, rank, ranks, imageBytes, node);
      int dev = ok && engine.setImageOnDevice(true) ? 1 : 0, devAll = 0;
      MPI_Allreduce(&dev, &devAll, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
      gpuComposite = devAll == 1;
      if (!gpuComposite) {
        noGpuWhy = ok ? "an engine cannot keep its image on the device" : gx.why;
        engine.setImageOnDevice(false);
        if (ok) releaseGpuExchange(gx, rank);
      }
    } else if (want) {
      noGpuWhy = "a rank has no CUDA device";
    }
  }
#else
  if (a.composite == "gpu") noGpuWhy = "built without CUDA";
#endif
  if (!noGpuWhy.empty())
    std::fprintf(stderr, "[rank %d] GPU compositing not used (%s): compositing through host memory\n", rank,
                 noGpuWhy.c_str());

  struct Times {
    double render = 0, exchange = 0, blend = 0, gather = 0, frame = 0;
    double call = 0, kernel = 0;  // render()'s return on the host; the engine's kernel (device) time
  };
  // The view direction in the volume's index space (spacing 1, axis-aligned generators).
  auto order = [&](const Camera& cam) {
    const double dir[3] = {-cam.view.m[2], -cam.view.m[6], -cam.view.m[10]};
    const double eye[3] = {0, 0, 0};
    return visibilityOrder(boxes, eye, dir, true);
  };
#ifdef SPACESKIP_MPI_PIECES_CUDA
  // GPU compositing: render (left on the device), copy into the exchange buffer; barrier; blend
  // this rank's band from every rank's buffer into rank 0's final image; barrier. Waited for.
  auto gpuFrame = [&](int f, Times& t) {
    MPI_Barrier(MPI_COMM_WORLD);
    const auto s0 = Clock::now();
    const Camera cam = camera(f);
    engine.render(cam, w, h, img);
    const auto sr = Clock::now();
    const void* di = engine.deviceImage();
    auto* es = static_cast<cudaStream_t>(engine.deviceImageStream());
    if (!di || cudaMemcpyAsync(gx.mine, di, imageBytes, cudaMemcpyDeviceToDevice, es) != cudaSuccess ||
        cudaStreamSynchronize(es) != cudaSuccess) {
      std::fprintf(stderr, "[rank %d] the frame is not on the device (%s)\n", rank,
                   di ? cudaGetErrorString(cudaGetLastError()) : "the engine fell back to the host");
      MPI_Abort(MPI_COMM_WORLD, 3);
    }
    const auto s1 = Clock::now();
    MPI_Barrier(MPI_COMM_WORLD);  // every rank's image is in its exchange buffer
    const auto s2 = Clock::now();
    spaceskip::mpi::BandSources bs{};
    const std::vector<size_t> ord = order(cam);
    for (int r = 0; r < ranks; ++r) {
      bs.src[r] = gx.peers[size_t(r)];
      bs.order[r] = int(ord[size_t(r)]);
    }
    if (spaceskip::mpi::launchBandBlend(bs, ranks, gx.finalMapped, size_t(rowLo(rank)) * size_t(w),
                                        size_t(myRows) * size_t(w), gx.stream) != 0 ||
        cudaStreamSynchronize(gx.stream) != cudaSuccess) {
      std::fprintf(stderr, "[rank %d] the band blend failed: %s\n", rank, cudaGetErrorString(cudaGetLastError()));
      MPI_Abort(MPI_COMM_WORLD, 3);
    }
    const auto s3 = Clock::now();
    MPI_Barrier(MPI_COMM_WORLD);  // rank 0's final image is whole
    const auto s4 = Clock::now();
    t.render += seconds(s0, s1), t.exchange += seconds(s1, s2), t.blend += seconds(s2, s3);
    t.gather += seconds(s3, s4), t.frame += seconds(s0, s4);
    t.call += seconds(s0, sr), t.kernel += std::max(0.0, engine.frameStats().deviceSeconds);
  };
#endif
  // --split image: rank r draws rows [rows[r], rows[r + 1]) over the whole volume, straight into
  // rank 0's final image (GPU: a copy into it through CUDA IPC; host: MPI_Gatherv). No blend.
  std::vector<int> rows(static_cast<size_t>(ranks) + 1);
  for (int r = 0; r <= ranks; ++r) rows[size_t(r)] = rowLo(r);
  std::vector<double> bandTimes(static_cast<size_t>(ranks));
  bool moveBands = false;  // not while Auto measures (a new band height starts its measuring again)
  auto imageFrame = [&](int f, Times& t) {
    MPI_Barrier(MPI_COMM_WORLD);
    const auto s0 = Clock::now();
    const int lo = rows[size_t(rank)], hi = rows[size_t(rank) + 1];
    engine.render(bandCamera(camera(f), lo, hi, h), w, hi - lo, img);
    const auto sr = Clock::now();
    const size_t bandBytes = size_t(hi - lo) * size_t(w) * sizeof(vec4f);
#ifdef SPACESKIP_MPI_PIECES_CUDA
    if (gpuComposite) {
      const void* di = engine.deviceImage();
      auto* es = static_cast<cudaStream_t>(engine.deviceImageStream());
      if (!di || cudaMemcpyAsync(static_cast<vec4f*>(gx.finalMapped) + size_t(lo) * size_t(w), di, bandBytes,
                                 cudaMemcpyDeviceToDevice, es) != cudaSuccess ||
          cudaStreamSynchronize(es) != cudaSuccess) {
        std::fprintf(stderr, "[rank %d] the band is not on the device (%s)\n", rank,
                     di ? cudaGetErrorString(cudaGetLastError()) : "the engine fell back to the host");
        MPI_Abort(MPI_COMM_WORLD, 3);
      }
    }
#endif
    const auto s1 = Clock::now();
    if (gpuComposite) {
      MPI_Barrier(MPI_COMM_WORLD);  // rank 0's final image is whole
    } else {
      std::vector<int> cnt(static_cast<size_t>(ranks)), dsp(static_cast<size_t>(ranks));
      for (int r = 0; r < ranks; ++r) {
        cnt[size_t(r)] = (rows[size_t(r) + 1] - rows[size_t(r)]) * w * 4;
        dsp[size_t(r)] = rows[size_t(r)] * w * 4;
      }
      MPI_Gatherv(img.rgba.data(), int(bandBytes / sizeof(float)), MPI_FLOAT,
                  rank == 0 ? final.rgba.data() : nullptr, cnt.data(), dsp.data(), MPI_FLOAT, 0, MPI_COMM_WORLD);
    }
    const auto s4 = Clock::now();
    t.render += seconds(s0, s1), t.gather += seconds(s1, s4), t.frame += seconds(s0, s4);
    t.call += seconds(s0, sr), t.kernel += std::max(0.0, engine.frameStats().deviceSeconds);
    // The next frame's bands, from this frame's render times (outside the frame's time).
    if (a.balance == "frame-time" && ranks > 1 && moveBands) {
      const double mine = seconds(s0, s1);
      MPI_Allgather(&mine, 1, MPI_DOUBLE, bandTimes.data(), 1, MPI_DOUBLE, MPI_COMM_WORLD);
      rows = rebalancedRows(rows, bandTimes, std::min(8, h / ranks));
    }
  };
  auto frame = [&](int f, Times& t) {
    if (image) return imageFrame(f, t);
#ifdef SPACESKIP_MPI_PIECES_CUDA
    if (gpuComposite) return gpuFrame(f, t);
#endif
    MPI_Barrier(MPI_COMM_WORLD);
    const auto s0 = Clock::now();
    const Camera cam = camera(f);
    engine.render(cam, w, h, img);  // waited for: the image is on the host
    const auto s1 = Clock::now();
    MPI_Alltoallv(img.rgba.data(), counts.data(), displs.data(), MPI_FLOAT, recv.data(), recvCounts.data(),
                  recvDispls.data(), MPI_FLOAT, MPI_COMM_WORLD);
    const auto s2 = Clock::now();
    std::fill(band.begin(), band.end(), vec4f{0, 0, 0, 0});
    for (size_t r : order(cam)) over(band.data(), recv.data() + r * myRows * w, band.size());  // front first
    const auto s3 = Clock::now();
    MPI_Gatherv(band.data(), myRows * w * 4, MPI_FLOAT, rank == 0 ? final.rgba.data() : nullptr, counts.data(),
                displs.data(), MPI_FLOAT, 0, MPI_COMM_WORLD);
    const auto s4 = Clock::now();
    t.render += seconds(s0, s1), t.exchange += seconds(s1, s2), t.blend += seconds(s2, s3);
    t.gather += seconds(s3, s4), t.frame += seconds(s0, s4);
  };

  Times warm;
  const auto firstStart = Clock::now();
  frame(0, warm);  // first frame: upload, ranges, classification, build
  const double first = seconds(firstStart, Clock::now());
  const double setup = seconds(t0, firstStart);
  for (int i = 0; i < 3; ++i) frame(0, warm);  // Auto measures its candidates
  if (image) {
    // Bands of rows change height from frame to frame, and Builder Auto measures its candidates
    // again at every new frame size: each rank measures on its first band until it decides,
    // then keeps its choice; then the bands settle on the render times before the orbit.
    for (int i = 0; i < 40; ++i) {
      int busy = engine.exploring() ? 1 : 0, any = 0;
      MPI_Allreduce(&busy, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
      if (!any) break;
      frame(0, warm);
    }
    if (bp.builder == BuilderKind::Auto) {
      BuildParams kept = bp;
      kept.builder = engine.buildStats().builder;
      engine.setBuildParams(kept);
    }
    moveBands = true;
    for (int i = 0; i < 10; ++i) frame(0, warm);
  }
  Times t;
  // The orbit's longest block (each frame's statistic is the frame before's; after the orbit
  // come the transfer-function edits, whose frames are not the orbit's).
  double longestBlock = -1;
  for (int f = 0; f < a.frames; ++f) {
    frame(f, t);
    longestBlock = std::max(longestBlock, engine.frameStats().longestBlockSeconds);
  }
  // Device memory in use on this rank's GPU after the orbit (the volume in core, the structure).
  double deviceGiB = 0;
#ifdef SPACESKIP_MPI_PIECES_CUDA
  size_t freeB = 0, totalB = 0;
  if (device >= 0 && cudaMemGetInfo(&freeB, &totalB) == cudaSuccess) deviceGiB = double(totalB - freeB) / double(1ull << 30);
#endif
  double deviceGiBMax = 0;
  MPI_Reduce(&deviceGiB, &deviceGiBMax, 1, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
  // A transfer-function edit and back, each edit's first frame timed (the last camera: the
  // composite that --check compares is the original function's).
  Times e1, e2;
  engine.setTransferFunction(edited);
  frame(a.frames - 1, e1);
  engine.setTransferFunction(tf);
  frame(a.frames - 1, e2);
  // The slowest rank's render is what the frame waited for.
  double renderMax = 0, renderMin = 0;
  MPI_Reduce(&t.render, &renderMax, 1, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
  MPI_Reduce(&t.render, &renderMin, 1, MPI_DOUBLE, MPI_MIN, 0, MPI_COMM_WORLD);
  const double kernel = engine.frameStats().deviceSeconds;

  // Each rank's device and builder, in rank order.
  char line[256];
  if (image)
    std::snprintf(line, sizeof line, "rank %d: local rank %d, device %d (%s), builder %s, image rows [%d, %d)",
                  rank, localRank, device, deviceName.c_str(), builderName(engine.buildStats().builder),
                  rows[size_t(rank)], rows[size_t(rank) + 1]);
  else
    std::snprintf(line, sizeof line, "rank %d: local rank %d, device %d (%s), builder %s, slab z cells [%lld, %lld)",
                  rank, localRank, device, deviceName.c_str(), builderName(engine.buildStats().builder),
                  (long long)z0, (long long)z1);
  std::vector<char> lines(rank == 0 ? size_t(ranks) * sizeof line : 0);
  MPI_Gather(line, sizeof line, MPI_CHAR, lines.data(), sizeof line, MPI_CHAR, 0, MPI_COMM_WORLD);

#ifdef SPACESKIP_MPI_PIECES_CUDA
  // The last composite (the edit back's frame: the original function) to the host on rank 0.
  if (gpuComposite && rank == 0 && cudaMemcpy(final.rgba.data(), gx.final0, imageBytes, cudaMemcpyDeviceToHost) != cudaSuccess) {
    std::fprintf(stderr, "downloading the final image failed\n");
    MPI_Abort(MPI_COMM_WORLD, 3);
  }
#endif
  if (rank == 0) {
    for (int r = 0; r < ranks; ++r) std::printf("%s\n", lines.data() + size_t(r) * sizeof line);
    const double n = a.frames;
    std::printf("ranks %d shape %s dims %lld size %dx%d frames %d backend %s split %s composite %s %s\n", ranks,
                a.shape.c_str(), (long long)a.dims, w, h, a.frames, engine.backendName(), a.split.c_str(),
                gpuComposite ? (image ? "gpu (CUDA IPC, each band copied into rank 0's)"
                                      : "gpu (CUDA IPC, blended on the GPUs into rank 0's)")
                             : "host (MPI through host memory)",
                image ? (balanced ? "bands of rows by the last frame's render times" : "bands of equal rows")
                      : (balanced ? "slabs balanced by visible voxels" : "slabs of equal cells"));
    std::printf("setup_s %.3f first_frame_s %.4f device_GiB(max rank) %.2f volume_GiB %.2f\n", setup, first,
                deviceGiBMax, double(wdims.x) * double(wdims.y) * double(wdims.z) * double(voxelSize(piece.type)) / double(1ull << 30));
    std::printf("tf_edit_frame_ms %.3f tf_edit_back_frame_ms %.3f\n", 1e3 * e1.frame, 1e3 * e2.frame);
    std::printf("frame_ms %.3f fps %.1f render_ms(rank0) %.3f render_ms(max) %.3f render_ms(min) %.3f "
                "exchange_ms %.3f blend_ms %.3f gather_ms %.3f last_kernel_ms %.3f\n",
                1e3 * t.frame / n, n / t.frame, 1e3 * t.render / n, 1e3 * renderMax / n, 1e3 * renderMin / n,
                1e3 * t.exchange / n, 1e3 * t.blend / n, 1e3 * t.gather / n, 1e3 * kernel);
    // Where rank 0's render goes: the render() call's return on the host, and the kernel.
    std::printf("rank0 render_call_ms %.3f kernel_ms %.3f longest_block_ms %.3f\n", 1e3 * t.call / n,
                1e3 * t.kernel / n, 1e3 * longestBlock);
    if (!a.png.empty()) savePng(final, a.png);
  }

  if (a.check) {
    // The last frame's composite against the whole volume drawn alone (rank 0).
    int bad = 0;
    if (rank == 0) {
      Engine ref(backendOf(a.backend));
      ref.setBuildParams(bp);
      if (a.slabs) whole = generateVolume(a.shape, wdims);  // the reference only
      ref.setVolume(whole);
      ref.setTransferFunction(tf);
      Image serial;
      ref.render(camera(a.frames - 1), w, h, serial);
      int maxDiff = 0;
      size_t off = 0;
      for (size_t i = 0; i < serial.rgba.size(); ++i) {
        const vec4f& p = serial.rgba[i];
        const vec4f& q = final.rgba[i];
        const int d = std::max({std::abs(to8(p.x) - to8(q.x)), std::abs(to8(p.y) - to8(q.y)),
                                std::abs(to8(p.z) - to8(q.z)), std::abs(to8(p.w) - to8(q.w))});
        maxDiff = std::max(maxDiff, d);
        off += d > 1;
      }
      std::printf("check: %d ranks vs the whole volume alone: max |diff| %d/255, pixels > 1/255: %zu\n", ranks,
                  maxDiff, off);
      bad = maxDiff > 1;
    }
    MPI_Bcast(&bad, 1, MPI_INT, 0, MPI_COMM_WORLD);
#ifdef SPACESKIP_MPI_PIECES_CUDA
    if (gpuComposite) {
      MPI_Barrier(MPI_COMM_WORLD);  // no rank unmaps a buffer another still reads
      releaseGpuExchange(gx, rank);
    }
#endif
    MPI_Comm_free(&node);
    MPI_Finalize();
    return bad ? 1 : 0;
  }
#ifdef SPACESKIP_MPI_PIECES_CUDA
  if (gpuComposite) {
    MPI_Barrier(MPI_COMM_WORLD);
    releaseGpuExchange(gx, rank);
  }
#endif
  MPI_Comm_free(&node);
  MPI_Finalize();
  return 0;
}
