// `spaceskip generate`: a generated volume written as .nrrd or .raw.
#include "Commands.h"
#include "spaceskip/Generators.h"
#include "spaceskip/VolumeIO.h"

#include <cstdio>
#include <stdexcept>

namespace spaceskip::cli {

int cmdGenerate(const Options& o) {
  if (o.positional.size() != 1 || !o.has("--dims") || !o.has("-o"))
    throw std::invalid_argument("generate needs SHAPE --dims X Y Z -o FILE");
  vec3l d = parseDims(o.get("--dims", ""), "--dims");
  checkGeneratorSize(o.positional[0], d, maxVolumeBytes(o));
  const unsigned seed = unsigned(o.getInt("--seed", 1, 0, 4294967295LL));
  auto t0 = Clock::now();
  Volume v = generateVolume(o.positional[0], d, seed);
  double gen = since(t0);
  std::string out = o.get("-o", "");
  if (out.size() > 5 && out.substr(out.size() - 5) == ".nrrd") saveNrrd(v, out);
  else {
    vec3l pd;
    VoxelType pt;
    if (!parseRawName(out, pd, pt) || pd.x != d.x || pd.y != d.y || pd.z != d.z || pt != v.type)
      throw std::invalid_argument(std::string("output must end in .nrrd or be named NAME_") + std::to_string(d.x) + "x" +
                                  std::to_string(d.y) + "x" + std::to_string(d.z) + "_" + voxelTypeName(v.type) + ".raw");
    saveRaw(v, out);
  }
  std::printf("generated %s %lldx%lldx%lld %s in %.3f s -> %s\n", o.positional[0].c_str(), (long long)d.x,
              (long long)d.y, (long long)d.z, voxelTypeName(v.type), gen, out.c_str());
  return 0;
}

}  // namespace spaceskip::cli
