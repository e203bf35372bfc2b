// One MPI rank per GPU: each rank renders its slab of one volume with the engine (the whole
// volume's sample lattice, its own cells only: VolumePiece.h), the ranks composite the float
// images by direct send (each rank blends one band of rows from every rank in visibility
// order, PieceOrder.h) and rank 0 gathers the bands. Frames are waited for; the frame time is
// the slowest rank's render, the exchange, the blend and the gather.
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
//       [--composite gpu|host] [--balance occupancy|equal]
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
  std::string balance = "occupancy";  // or equal
  int64_t dims = 256;
  int size = 512, frames = 20;
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
    else if (k == "--check") a.check = true;
    else if (k == "--slabs") a.slabs = true;
    else {
      std::fprintf(stderr, "unknown option %s\n", k.c_str());
      MPI_Abort(MPI_COMM_WORLD, 2);
    }
  }
  if (a.balance != "occupancy" && a.balance != "equal") {
    std::fprintf(stderr, "--balance takes occupancy or equal\n");
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
  const bool balanced = !a.slabs && a.balance != "equal";
  if (balanced) cuts = balancedCuts(whole, tf, ranks);
  const int64_t z0 = cuts[size_t(rank)], z1 = cuts[size_t(rank) + 1];
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
  engine.setVolume(piece);
  engine.setPiece(vp);
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
  for (int r = 0; r < ranks; ++r)
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
  };
#endif
  auto frame = [&](int f, Times& t) {
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
  Times t;
  for (int f = 0; f < a.frames; ++f) frame(f, t);
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
    std::printf("ranks %d shape %s dims %lld size %dx%d frames %d backend %s composite %s slabs %s\n", ranks,
                a.shape.c_str(), (long long)a.dims, w, h, a.frames, engine.backendName(),
                gpuComposite ? "gpu (CUDA IPC, blended on the GPUs into rank 0's)" : "host (MPI through host memory)",
                balanced ? "balanced by visible voxels" : "equal cells");
    std::printf("setup_s %.3f first_frame_s %.4f device_GiB(max rank) %.2f volume_GiB %.2f\n", setup, first,
                deviceGiBMax, double(wdims.x) * double(wdims.y) * double(wdims.z) * double(voxelSize(piece.type)) / double(1ull << 30));
    std::printf("tf_edit_frame_ms %.3f tf_edit_back_frame_ms %.3f\n", 1e3 * e1.frame, 1e3 * e2.frame);
    std::printf("frame_ms %.3f fps %.1f render_ms(rank0) %.3f render_ms(max) %.3f render_ms(min) %.3f "
                "exchange_ms %.3f blend_ms %.3f gather_ms %.3f last_kernel_ms %.3f\n",
                1e3 * t.frame / n, n / t.frame, 1e3 * t.render / n, 1e3 * renderMax / n, 1e3 * renderMin / n,
                1e3 * t.exchange / n, 1e3 * t.blend / n, 1e3 * t.gather / n, 1e3 * kernel);
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
