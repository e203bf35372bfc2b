// `spaceskip accuracy`: the speed/accuracy trade of sample distance, filter, ERT and jitter.
#include "Commands.h"
#include "spaceskip/Builders.h"
#include "spaceskip/ImageIO.h"

#include <algorithm>
#include <cstdio>
#include <stdexcept>
#include <vector>

namespace spaceskip::cli {

// The speed/accuracy trade: image error against a reference at 1/8 of the smallest spacing
// (exact trilinear, no ERT), and frame rate, for coarser sample distances, both filter modes
// (hardware filtering exists on the CUDA backend only) and early ray termination.
int cmdAccuracy(const Options& o) {
  if (o.positional.size() != 1) throw std::invalid_argument("accuracy needs one VOLUME");
  const std::unique_ptr<OutputFile> csvFile = outputOption(o, "--csv");  // fails before any work
  Volume v = openVolume(o.positional[0], o);
  int w = 512, h = 512;
  imageSize(o, w, h);
  const double minSpacing = std::min({v.spacing[0], v.spacing[1], v.spacing[2]});
  Engine engine(backendKind(o));
  engine.setLogger([](const std::string& m) { std::fprintf(stderr, "  note: %s\n", m.c_str()); });
  engine.setTuning(tuning(o));
  engine.setVolume(v);
  engine.setTransferFunction(makeTF(o, v));
  engine.setBuildParams(buildParams(o, o.get("--builder", "auto")));
  Camera cam = makeCamera(o, v, w, h);
  RenderParams ref;
  ref.sampleDistance = minSpacing / 8;
  engine.setRenderParams(ref);
  Image reference;
  allocating(frameText(w, h), frameBytes(w, h), [&] { engine.render(cam, w, h, reference); });
  std::printf("reference: sample distance %g (1/8 voxel), exact filtering, no ERT, backend %s\n",
              ref.sampleDistance, engine.backendName());
  std::printf("%-10s %-9s %-5s %-6s %10s %10s %8s %9s %9s %9s\n", "dt/voxel", "filter", "ert", "jitter", "max_diff",
              "psnr_db", "ssim", "fps", "kern_fps", "Msmp/frm");
  if (csvFile) {
    csvFile->stream() << "dataset,backend,builder,dt_voxel,filter,ert,jitter,max_diff,psnr_db,ssim,fps,kernel_fps,msamples\n";
  }
  std::vector<FilterMode> filters{FilterMode::Exact};
  if (std::string(engine.backendName()) == "cuda") filters.push_back(FilterMode::Hardware);
  for (double f : {0.25, 0.5, 1.0, 2.0, 4.0}) {
    for (FilterMode fm : filters) {
      for (bool ert : {false, true}) {
        for (bool jitter : {false, true}) {
          RenderParams rp;
          rp.sampleDistance = f * minSpacing;
          rp.filter = fm;
          rp.ertThreshold = ert ? 0.99 : 2.0;
          rp.jitter = jitter;
          engine.setRenderParams(rp);
          Image img;
          engine.render(cam, w, h, img);  // warm-up
          double t = 0, tk = 0;
          const int frames = 3;
          for (int i = 0; i < frames; ++i) {
            engine.render(cam, w, h, img);
            t += engine.frameStats().seconds;
            tk += engine.frameStats().deviceSeconds > 0 ? engine.frameStats().deviceSeconds : engine.frameStats().seconds;
          }
          rp.countSamples = true;
          engine.setRenderParams(rp);
          engine.render(cam, w, h, img);
          ImageDiff d = compareImages(reference, img);
          const double s = ssim(reference, img), ms = double(engine.frameStats().samples) * 1e-6;
          const char* fname = fm == FilterMode::Exact ? "exact" : "hardware";
          std::printf("%-10.2f %-9s %-5s %-6s %10.4f %10.2f %8.4f %9.2f %9.2f %9.2f\n", f, fname, ert ? "0.99" : "off",
                      jitter ? "on" : "off", d.maxAbs, d.psnr, s, frames / t, frames / tk, ms);
          std::fflush(stdout);
          if (csvFile)
            csvFile->stream() << o.positional[0] << ',' << engine.backendName() << ',' << builderName(engine.buildStats().builder) << ','
                << f << ',' << fname << ',' << (ert ? "0.99" : "off") << ',' << (jitter ? "on" : "off") << ','
                << d.maxAbs << ',' << d.psnr << ',' << s << ',' << frames / t << ',' << frames / tk << ',' << ms << '\n';
        }
      }
    }
  }
  if (csvFile) csvFile->commit();
  return 0;
}

}  // namespace spaceskip::cli
