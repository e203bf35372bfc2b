// `spaceskip sparse`: sparse residency against in core, per builder.
#include "Commands.h"
#include "spaceskip/Backend.h"
#include "spaceskip/BrickPool.h"
#include "spaceskip/Builders.h"
#include "spaceskip/ImageIO.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <vector>

namespace spaceskip::cli {

/// `spaceskip sparse`: the same frames in core and sparse under --memory-budget, per builder:
/// images compared, frame rates side by side, and the TF edit (--tf -> --edit-tf) that makes
/// new bricks visible timed to its first frame. --no-in-core: sparse alone (a volume the device
/// cannot hold).
int cmdSparse(const Options& o) {
  if (o.positional.size() != 1 || !o.has("--memory-budget"))
    throw std::invalid_argument("sparse needs VOLUME --memory-budget N[K|M|G]");
  const std::vector<std::string> builders = split(o.get("--builders", "naive,grid,distance-grid,auto"), ',');
  const int frames = int(o.getInt("--frames", 8, 1, 1000000));
  int w = 1024, h = 1024;
  imageSize(o, w, h);
  const bool inCore = !o.has("--no-in-core");
  auto tg = Clock::now();
  Volume v = openVolume(o.positional[0], o);
  std::printf("volume %s: %lldx%lldx%lld %s, %.2f GiB, ready in %.1f s\n", o.positional[0].c_str(), (long long)v.dims.x,
              (long long)v.dims.y, (long long)v.dims.z, voxelTypeName(v.type), double(v.byteSize()) / 1073741824.0,
              since(tg));
  double lo, hi;
  if (!v.scalarRange(lo, hi)) lo = 0, hi = 1;
  const TransferFunction tf = makeTF(o, v);
  const std::string editName = o.get("--edit-tf", "ramp");
  const TransferFunction edited = TransferFunction::preset(editName, lo, hi);
  double b6[6];
  v.worldBounds(b6);
  auto cam = [&](int f) { return orbitCamera(b6, 360.0 * f / frames, 15, 1, false, double(w) / h); };
  std::printf("%-16s %-7s %9s %9s %9s %10s %9s %9s %9s %10s %11s\n", "builder", "mode", "kern_fps", "fps", "vs_incore",
              "max_diff", "needed", "resident", "pool_MiB", "first_ms", "edit_ms");
  int worst = 0;
  for (const std::string& b : builders) {
    struct Run {
      double kfps = 0, fps = 0, maxDiff = -1, firstMs = 0, editMs = 0;
      std::vector<Image> imgs;
      Image editImg;
      ResidencyStats r, edit;
      std::string backend;
    };
    auto run = [&](bool sparse) {
      Run out;
      Engine e(backendKind(o));
      e.setTuning(tuning(o));
      if (sparse) e.setMemoryBudget(memoryBudget(o), poolBrick(o));
      else e.setMemoryBudget(INT64_MAX);  // in core whatever the default budget says
      e.setLogger([](const std::string& m) { std::fprintf(stderr, "  note: %s\n", m.c_str()); });
      e.setVolume(v);
      e.setTransferFunction(tf);
      e.setBuildParams(buildParams(o, b));
      e.setRenderParams(renderParams(o));
      Image img;
      auto t0 = Clock::now();
      e.render(cam(0), w, h, img);  // ranges, classification, build, residency, one frame
      out.firstMs = 1e3 * since(t0);
      for (int i = 0; i < 40 && e.exploring(); ++i) e.render(cam(0), w, h, img);
      double total = 0, dev = 0;
      for (int f = 0; f < frames; ++f) {
        e.render(cam(f), w, h, img);
        total += e.frameStats().seconds;
        dev += e.frameStats().deviceSeconds;
        out.imgs.push_back(img);
      }
      out.fps = frames / total;
      out.kfps = dev > 0 ? frames / dev : out.fps;
      out.r = e.frameStats().residency;
      out.backend = e.frameStats().backend;
      // The edit: new bricks become visible; its first frame is timed (classification, rebuild,
      // residency update, the frame) and compared.
      e.setTransferFunction(edited);
      t0 = Clock::now();
      e.render(cam(0), w, h, out.editImg);
      out.editMs = 1e3 * since(t0);
      out.edit = e.frameStats().residency;
      return out;
    };
    Run ref;
    if (inCore) ref = run(false);
    Run sp = run(true);
    if (inCore) {
      sp.maxDiff = 0;
      for (int f = 0; f < frames; ++f) sp.maxDiff = std::max(sp.maxDiff, double(compareImages(ref.imgs[size_t(f)], sp.imgs[size_t(f)]).maxAbs));
      sp.maxDiff = std::max(sp.maxDiff, double(compareImages(ref.editImg, sp.editImg).maxAbs));
      std::printf("%-16s %-7s %9.1f %9.1f %9s %10s %9s %9s %9s %10.1f %11.2f\n", b.c_str(), "incore", ref.kfps, ref.fps,
                  "1", "-", "-", "-", "-", ref.firstMs, ref.editMs);
      if (sp.maxDiff * 255.0 > 1.0) worst = 3;
    }
    char diff[32] = "-", ratio[32] = "-";
    if (sp.maxDiff >= 0) std::snprintf(diff, sizeof diff, "%.2f/255", sp.maxDiff * 255.0);
    if (inCore) std::snprintf(ratio, sizeof ratio, "%.3f", sp.kfps / ref.kfps);
    std::printf("%-16s %-7s %9.1f %9.1f %9s %10s %9lld %9lld %9.1f %10.1f %11.2f\n", b.c_str(),
                sp.r.overflow ? "over" : sp.r.sparse ? "sparse" : sp.backend.c_str(), sp.kfps, sp.fps, ratio, diff, (long long)sp.r.needed,
                (long long)sp.r.resident, double(sp.r.poolBytes) / 1048576.0, sp.firstMs, sp.editMs);
    if (sp.edit.sparse)
      std::printf("%-16s %-7s after the edit to %s: %lld bricks needed, %lld uploaded (%.1f MiB), %lld evicted, "
                  "pool %.1f MiB, residency update %.2f ms of the %.2f ms\n",
                  b.c_str(), "", editName.c_str(), (long long)sp.edit.needed, (long long)sp.edit.uploaded,
                  double(sp.edit.uploaded) * double(makePoolLayout(v.dims, buildParams(o, b).brick, poolBrick(o)).slotVoxels()) *
                      double(voxelSize(v.type)) / 1048576.0,
                  (long long)sp.edit.evicted, double(sp.edit.poolBytes) / 1048576.0, 1e3 * sp.edit.updateSeconds,
                  sp.editMs);
    std::fflush(stdout);
  }
  if (worst) std::fprintf(stderr, "spaceskip: a sparse image differs from the in-core one by more than 1/255\n");
  return worst;
}

}  // namespace spaceskip::cli
