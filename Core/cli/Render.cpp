// `spaceskip render`: one image, with timings, optionally compared against a reference.
#include "Commands.h"
#include "spaceskip/Builders.h"
#include "spaceskip/ImageIO.h"

#include <cstdio>
#include <stdexcept>

namespace spaceskip::cli {

int cmdRender(const Options& o) {
  if (o.positional.size() != 1 || !o.has("-o")) throw std::invalid_argument("render needs VOLUME -o out.png");
  // Opened first: a path that cannot be written fails before any work, and the PNG replaces what
  // is there only once it is written whole (OutputFile).
  const std::unique_ptr<OutputFile> png = outputOption(o, "-o");
  auto t0 = Clock::now();
  Volume v = openVolume(o.positional[0], o);
  double load = since(t0);
  int w = 512, h = 512;
  imageSize(o, w, h);
  Engine engine(backendKind(o));
  engine.setTuning(tuning(o));
  engine.setMemoryBudget(memoryBudget(o), poolBrick(o));
  const auto tFirst = Clock::now();  // first frame: from the voxels in host memory to an image
  engine.setVolume(v);
  engine.setTransferFunction(makeTF(o, v));
  engine.setBuildParams(buildParams(o, o.get("--builder", "auto")));
  engine.setRenderParams(renderParams(o));
  if (o.has("--label-map")) engine.setLabelTable(labelTable(o, v));
  auto t1 = Clock::now();
  engine.update();
  double prep = since(t1);
  Image img;
  Camera cam = makeCamera(o, v, w, h);
  double first = 0;
  allocating(frameText(w, h), frameBytes(w, h), [&] {
    engine.render(cam, w, h, img);  // first frame (warm-up)
    first = since(tFirst);
    for (int i = 0; i < 40 && engine.exploring(); ++i) engine.render(cam, w, h, img);  // Auto measures
    engine.render(cam, w, h, img);
  });
  const BuildStats& s = engine.buildStats();
  if (!s.choice.empty()) std::printf("%s\n", s.choice.c_str());
  std::printf("volume %s: %lldx%lldx%lld %s, load %.3f s\n", o.positional[0].c_str(), (long long)v.dims.x,
              (long long)v.dims.y, (long long)v.dims.z, voxelTypeName(v.type), load);
  std::printf("backend %s, builder %s: ranges+classify+build %.3f s (classify %.4f s, build %.4f s), "
              "nodes %lld, height %d, leaves %lld, occupied bricks %.2f%%\n",
              engine.backendName(), builderName(s.builder), prep, s.classifySeconds, s.seconds,
              (long long)s.nodes, s.height, (long long)s.leaves, 100.0 * s.occupancy);
  std::printf("render %dx%d: %.4f s (%.2f fps), sample distance %g\n", w, h, engine.frameStats().seconds,
              1.0 / engine.frameStats().seconds, engine.sampleDistance());
  std::printf("first frame %.3f s (upload, ranges, classification, build, the frame read back)\n", first);
  printResidency(engine.frameStats().residency);
  png->stream() << allocating("encoding the PNG", uint64_t(w) * uint64_t(h) * 4, [&] { return encodePng(img); });
  png->commit();
  std::printf("wrote %s\n", o.get("-o", "").c_str());
  if (o.has("--compare")) {
    ImageDiff d = compareImages(img, loadPng(o.get("--compare", "")));
    std::printf("compare: max diff %.5f (%.2f/255), PSNR %.2f dB, %lld pixels > 1/255\n", d.maxAbs, d.maxAbs * 255,
                d.psnr, (long long)d.differing);
    if (o.has("--max-diff") && d.maxAbs * 255.0 > o.getDouble("--max-diff", 1, 0, 255)) {
      std::fprintf(stderr, "spaceskip: max difference %.2f/255 exceeds --max-diff %s\n", d.maxAbs * 255.0,
                   o.get("--max-diff", "").c_str());
      return 3;
    }
  }
  return 0;
}

}  // namespace spaceskip::cli
