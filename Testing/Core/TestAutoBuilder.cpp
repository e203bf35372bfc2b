// Builder Auto: every candidate (Naive among them) measured in turn, the close ones again (short
// frames up to 3 times in a row), then the cheapest (frame time + build time / 30); every frame
// equals Naive's image; measured again only when the occupancy moves or the size changes (Grid
// first after an edit), and re-checked against its contenders at a new view where the camera rests.
// The protocol is tested on the user's frames (autoProbe 0, CUDA's default) and on probes inside
// one frame (autoProbe 1, the CPU backend's default).
#include "TestUtil.h"
#include "spaceskip/AutoBuilder.h"
#include "spaceskip/Builders.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <regex>

using namespace spaceskip;

namespace {
/// Auto measuring on the user's frames, one candidate a frame (BuildParams::autoProbe 0).
BuildParams perFrame() {
  BuildParams p = test::builder(BuilderKind::Auto);
  p.autoProbe = 0;
  return p;
}

/// The structure a Builder Choice line says Auto chose ("Auto chose Grid: ...").
std::string keptOf(const std::string& choice) {
  const std::string head = "Auto chose ";
  if (choice.rfind(head, 0) != 0) return "";
  return choice.substr(head.size(), choice.find(':') - head.size());
}

/// The line's measured costs per candidate, in seconds: a frame + build/30.
std::vector<std::pair<std::string, double>> costsOf(const std::string& choice) {
  std::vector<std::pair<std::string, double>> costs;
  const size_t at = choice.find("build/30):");
  if (at == std::string::npos) return costs;
  const std::string list = choice.substr(at + 10);
  const std::regex entry(R"(([A-Za-z]+) ([0-9.e+-]+) (s|ms)(?: \+ ([0-9.e+-]+) (s|ms))?)");
  for (std::sregex_iterator it(list.begin(), list.end(), entry), end; it != end; ++it) {
    const std::smatch& m = *it;
    double c = std::stod(m[2]) * (m[3] == "ms" ? 1e-3 : 1.0);
    if (m[4].matched) c += std::stod(m[4]) * (m[5] == "ms" ? 1e-3 : 1.0);
    costs.emplace_back(m[1], c);
  }
  return costs;
}

struct Scene {
  Volume v = generateVolume("nbody", vec3l{64, 64, 64});
  TransferFunction tf = TransferFunction::preset("ramp", 0, 255);
  Camera cam = test::orbit(v, 30, 20);
  Engine e{BackendKind::CPU};  // on this scene with Builder Auto
  Image img;
  Scene() { test::load(e, v, tf, perFrame()); }
  /// Frames of `w` x `h` until Auto has measured its candidates and settled.
  void settle(int w, int h) {
    while (e.exploring()) e.render(cam, w, h, img);
  }
};
}  // namespace

TEST(AutoBuilder, EveryFrameEqualsNaiveAndTheFastestIsKept) {
  Scene s;
  Image naive = test::renderWith(s.v, s.tf, test::builder(BuilderKind::Naive), 30, 20, false, 64);
  Engine& e = s.e;
  Image& img = s.img;
  std::vector<BuilderKind> used;
  int frames = 0;
  while (e.exploring() && frames < 20) {
    e.render(s.cam, 64, 64, img);
    ++frames;
    used.push_back(e.buildStats().builder);
    EXPECT_LE(compareImages(naive, img).maxAbs, 1.f / 255.f) << "frame " << frames;
  }
  ASSERT_FALSE(e.exploring());
  // The first pass: each of the 4 CPU candidates once, in order; the second: those within 1.5x
  // of the cheapest (the cheapest at least) again, in the reverse order, each 1 to 3 frames in a
  // row (until 2 ms), so at most 4 + 4 * 3 frames.
  ASSERT_GE(frames, 5);
  ASSERT_LE(frames, 16);
  const std::vector<BuilderKind> firstPass{BuilderKind::Naive, BuilderKind::Grid, BuilderKind::DistanceGrid,
                                        BuilderKind::KdTreeCPU};
  EXPECT_TRUE(std::equal(firstPass.begin(), firstPass.end(), used.begin()));  // Naive, the reference, first
  auto rank = [&](BuilderKind k) { return std::find(firstPass.begin(), firstPass.end(), k) - firstPass.begin(); };
  int run = 1;
  for (size_t i = 5; i < used.size(); ++i) {
    EXPECT_LE(rank(used[i]), rank(used[i - 1])) << "the second pass runs in the reverse order";
    run = used[i] == used[i - 1] ? run + 1 : 1;
    EXPECT_LE(run, 3) << "at most 3 frames of a candidate in the second pass";
  }
  const std::string choice = e.buildStats().choice;
  EXPECT_EQ(choice.rfind("Auto chose ", 0), 0u) << choice;
  EXPECT_NE(choice.find("Naive"), std::string::npos) << choice;
  // The kept one is the cheapest by the line's own numbers (a frame + build / 30), unless it is
  // Naive kept within its 5% margin.
  {
    const auto costs = costsOf(choice);
    ASSERT_EQ(costs.size(), 4u) << choice;
    const std::string kept = keptOf(choice);
    double keptCost = -1, cheapest = 1e30, naiveCost = -1;
    for (const auto& c : costs) {
      if (c.first == kept) keptCost = c.second;
      if (c.first == "Naive") naiveCost = c.second;
      if (c.second > 0) cheapest = std::min(cheapest, c.second);
    }
    ASSERT_GT(keptCost, 0) << choice;
    // Two significant digits printed: a relative rounding of up to ~5%.
    if (kept == "Naive") EXPECT_LE(naiveCost, cheapest * 1.05 * 1.05) << choice;
    else EXPECT_LE(keptCost, cheapest * 1.05) << choice;
  }
  // The kept structure is the one the line names first, and the next frame draws with it.
  e.render(s.cam, 64, 64, img);
  EXPECT_EQ(keptOf(choice), builderName(e.buildStats().builder)) << choice;
  EXPECT_LE(compareImages(naive, img).maxAbs, 1.f / 255.f);
  // Settled: more frames of the same view build at most what a running-time switch needs
  // (timings on a shared CI machine are noisy), never measure everything again, and every frame
  // is still the Naive image.
  const int builds = e.counters().builds;
  for (int i = 0; i < 3; ++i) {
    e.render(s.cam, 64, 64, img);
    EXPECT_LE(compareImages(naive, img).maxAbs, 1.f / 255.f);
  }
  EXPECT_LE(e.counters().builds, builds + 3);
  EXPECT_FALSE(e.exploring());
}

TEST(AutoBuilder, SmallOccupancyChangesRebuildOnlyTheChoiceLargeOnesMeasureAgain) {
  Scene s;
  Engine& e = s.e;
  Image& img = s.img;
  s.settle(48, 48);
  // A slightly higher threshold: a few cells change, the chosen structure is rebuilt once.
  auto tf1 = TransferFunction::fromPoints({{0, 1, 1, 1, 0.f}, {30, 1, 1, 1, 0.f}, {255, 1, 0, 0, 0.8f}}, 0, 255, 256);
  auto tf2 = TransferFunction::fromPoints({{0, 1, 1, 1, 0.f}, {34, 1, 1, 1, 0.f}, {255, 1, 0, 0, 0.8f}}, 0, 255, 256);
  e.setTransferFunction(tf1);
  e.render(s.cam, 48, 48, img);
  s.settle(48, 48);
  const double occ1 = e.buildStats().occupancy;
  const int builds1 = e.counters().builds;
  e.setTransferFunction(tf2);
  e.render(s.cam, 48, 48, img);
  const double occ2 = e.buildStats().occupancy;
  ASSERT_LT(std::fabs(occ2 - occ1), 0.1) << "test premise: a small change";
  EXPECT_FALSE(e.exploring());
  EXPECT_LE(e.counters().builds, builds1 + 1);
  // Opaque everywhere: every cell occupied, a large change: measured again.
  e.setTransferFunction(TransferFunction::preset("opaque", 0, 255, 256));
  e.render(s.cam, 48, 48, img);
  ASSERT_GT(std::fabs(e.buildStats().occupancy - occ2), 0.1) << "test premise: a large change";
  EXPECT_TRUE(e.exploring());
  // The edit's own frame is Grid's (nothing to build beyond the classification), not Naive's.
  EXPECT_EQ(e.buildStats().builder, BuilderKind::Grid);
}

TEST(AutoBuilder, ANewViewSizeOrParametersMeasureAgain) {
  Scene s;
  Engine& e = s.e;
  Image& img = s.img;
  s.settle(48, 48);
  e.render(s.cam, 64, 48, img);
  EXPECT_TRUE(e.exploring()) << "a frame time at another size is not comparable";
  s.settle(64, 48);
  BuildParams p = perFrame();
  p.brick = 4;
  e.setBuildParams(p);
  EXPECT_TRUE(e.exploring());
}

TEST(AutoBuilder, AfterAnEditGridStandsInForOneFrameThenTheKeptStructureIsRebuilt) {
  // Progressive refinement: a kept structure slower to build than autoQuickBuildSeconds (0 here:
  // any build) gives way to Grid for the first frame after an occupancy-changing edit; the frame
  // after rebuilds it. Every frame is Naive's image.
  Scene s;
  Engine& e = s.e;
  Image& img = s.img;
  BuildParams p = perFrame();
  p.autoQuickBuildSeconds = 0;
  e.setBuildParams(p);
  e.setTransferFunction(TransferFunction::fromPoints({{0, 1, 1, 1, 0.f}, {30, 1, 1, 1, 0.f}, {255, 1, 0, 0, 0.8f}}, 0, 255, 256));
  s.settle(64, 64);
  e.render(s.cam, 64, 64, img);
  s.settle(64, 64);
  // The kept structure: the one the choice line names first (a running-time switch may have
  // just changed it).
  auto keptName = [&] {
    const std::string c = e.buildStats().choice;
    return keptOf(c);
  };
  const std::string kept = keptName();
  // An edit that changes the occupancy, but by less than Auto's re-measuring threshold (0.1).
  auto ramp = [](float zeroUpTo) {
    return TransferFunction::fromPoints({{0, 1, 1, 1, 0.f}, {zeroUpTo, 1, 1, 1, 0.f}, {255, 1, 0, 0, 0.8f}}, 0, 255, 256);
  };
  auto occupancyWith = [&](const TransferFunction& tf) {
    Engine g{BackendKind::CPU};
    test::load(g, s.v, tf, test::builder(BuilderKind::Grid));
    g.update();
    return g.buildStats().occupancy;
  };
  const double occ1 = occupancyWith(ramp(30));
  TransferFunction tf2 = ramp(30);
  for (float t : {34.f, 40.f, 48.f, 56.f, 64.f, 80.f, 96.f}) {
    const double o = occupancyWith(ramp(t));
    if (o != occ1 && std::fabs(o - occ1) < 0.1) {
      tf2 = ramp(t);
      break;
    }
  }
  ASSERT_NE(occupancyWith(tf2), occ1) << "test premise: an edit that changes the occupied cells";
  // Settled at tf2, the edit lowers the threshold back to 30: it occupies bricks (an edit that
  // only empties some draws with the structure built before it: the next test).
  e.setTransferFunction(tf2);
  e.render(s.cam, 64, 64, img);
  s.settle(64, 64);
  e.render(s.cam, 64, 64, img);
  ASSERT_EQ(keptName(), kept) << "test premise: the same choice at tf2";
  const Image naive = test::renderWith(s.v, ramp(30), test::builder(BuilderKind::Naive), 30, 20, false, 64);
  const int builds = e.counters().builds;
  e.setTransferFunction(ramp(30));
  e.render(s.cam, 64, 64, img);
  ASSERT_FALSE(e.exploring()) << "test premise: a small occupancy change";
  EXPECT_LE(compareImages(naive, img).maxAbs, 1.f / 255.f);
  const std::string choice = e.buildStats().choice;
  if (kept == "Grid" || kept == "Naive") {
    // Nothing to refine when the kept structure is Grid itself, or Naive (it builds nothing).
    EXPECT_EQ(builderName(e.buildStats().builder), kept);
    EXPECT_EQ(choice.find("this frame: Grid"), std::string::npos) << choice;
  } else {
    EXPECT_EQ(e.buildStats().builder, BuilderKind::Grid) << choice;
    EXPECT_NE(choice.find("this frame: Grid"), std::string::npos) << choice;
    e.render(s.cam, 64, 64, img);
    EXPECT_EQ(builderName(e.buildStats().builder), kept) << "the frame after the edit draws with the kept structure";
    EXPECT_LE(compareImages(naive, img).maxAbs, 1.f / 255.f);
    EXPECT_EQ(e.counters().builds, builds + 2);
  }
  // Refinement off: the kept structure is rebuilt for the first frame after the edit.
  p.autoQuickBuildSeconds = -1;
  e.setBuildParams(p);
  s.settle(64, 64);
  e.render(s.cam, 64, 64, img);
  const std::string kept2 = keptName();
  const int stale = e.counters().staleFrames;
  e.setTransferFunction(tf2);
  e.render(s.cam, 64, 64, img);
  ASSERT_FALSE(e.exploring()) << "test premise: a small occupancy change";
  EXPECT_EQ(builderName(e.buildStats().builder), kept2);
  EXPECT_EQ(e.counters().staleFrames, stale) << "refinement off: nothing drawn with a stale structure";
}

TEST(AutoBuilder, AnEditThatOnlyEmptiesBricksDrawsWithTheStructureBuiltBeforeIt) {
  // Raising the opacity threshold only empties bricks: the structure Auto holds still covers
  // every occupied brick, so the edit's frame builds nothing and draws with it (Naive's image),
  // and the next frame rebuilds it. Lowering the threshold again occupies bricks: rebuilt at once.
  // The scene: a ball whose value falls off from its centre, far from everything else in a
  // large empty volume, where the grid's DDA walks many empty bricks and a distance field or a
  // tree leaps over them (so Auto keeps a structure that is built, whatever the machine).
  const int n = 192;
  const Volume v = test::makeVolume<uint8_t>(n, n, n, VoxelType::UInt8, [](int x, int y, int z) {
    const double r = std::sqrt(double((x - 40) * (x - 40) + (y - 50) * (y - 50) + (z - 60) * (z - 60))) / 14.0;
    return r < 1 ? 255 * (1 - r) : 0;
  });
  auto ramp = [](float zeroUpTo) {
    return TransferFunction::fromPoints({{0, 1, 1, 1, 0.f}, {zeroUpTo, 1, 1, 1, 0.f}, {255, 1, 0, 0, 0.8f}}, 0, 255, 256);
  };
  const Camera cam = test::orbit(v, 30, 20);
  Engine e{BackendKind::CPU};
  test::load(e, v, ramp(30), perFrame());
  Image img;
  auto settle = [&] {
    while (e.exploring()) e.render(cam, 128, 128, img);
    e.render(cam, 128, 128, img);
  };
  settle();
  const BuilderKind kept = e.buildStats().builder;
  if (!buildsBeyondClassification(kept))  // seen once on a 16-core host under compute-sanitizer
    GTEST_SKIP() << "test premise: Auto keeps a built structure here, but measured " << e.buildStats().choice;
  const int builds = e.counters().builds, stale = e.counters().staleFrames;
  const double occ = e.buildStats().occupancy;
  e.setTransferFunction(ramp(90));
  e.render(cam, 128, 128, img);
  ASSERT_FALSE(e.exploring()) << "test premise: a small occupancy change";
  ASSERT_LT(e.buildStats().occupancy, occ) << "test premise: the edit empties bricks";
  auto naive = [&](float cut) { return test::renderWith(v, ramp(cut), test::builder(BuilderKind::Naive), 30, 20, false, 128); };
  EXPECT_LE(compareImages(naive(90), img).maxAbs, 1.f / 255.f);
  EXPECT_EQ(e.counters().builds, builds) << "no build on the edit's frame";
  EXPECT_EQ(e.counters().staleFrames, stale + 1);
  EXPECT_EQ(e.buildStats().builder, kept);
  EXPECT_NE(e.buildStats().choice.find("built before the edit"), std::string::npos) << e.buildStats().choice;
  e.render(cam, 128, 128, img);
  EXPECT_EQ(e.counters().builds, builds + 1) << "the frame after rebuilds it";
  EXPECT_EQ(e.buildStats().builder, kept);
  EXPECT_EQ(e.buildStats().choice.find("built before the edit"), std::string::npos);
  EXPECT_LE(compareImages(naive(90), img).maxAbs, 1.f / 255.f);
  // Back to 30: bricks become occupied, which the structure built at 90 misses: rebuilt at once
  // (or Grid stands in), never drawn stale.
  e.setTransferFunction(ramp(30));
  e.render(cam, 128, 128, img);
  EXPECT_EQ(e.counters().staleFrames, stale + 1);
  EXPECT_LE(compareImages(naive(30), img).maxAbs, 1.f / 255.f);
}

TEST(AutoBuilder, AStillCameraAtAFarViewReChecksTheChoiceAnOrbitDoesNot) {
  // A re-check measures the kept structure against its contenders, at least the runner-up.
  Scene s;
  Engine& e = s.e;
  Image& img = s.img;
  const TransferFunction& tf = s.tf;
  s.settle(48, 48);
  e.render(s.cam, 48, 48, img);  // the kept one's build, when measuring ended on another
  const int measuringBuilds = e.counters().builds;
  // An orbit, 45 degrees a frame: frame times at different views are not compared, so no
  // re-check and no build, however the times change.
  for (int az = 45; az < 360; az += 45) {
    e.render(test::orbit(s.v, az, 20), 48, 48, img);
    EXPECT_FALSE(e.exploring()) << "azimuth " << az;
  }
  EXPECT_EQ(e.counters().builds, measuringBuilds);
  EXPECT_EQ(e.buildStats().choice.find("re-checked"), std::string::npos) << e.buildStats().choice;
  // A small move from the measured view and rest there: still the measured view.
  const Camera nearby = test::orbit(s.v, 40, 22);
  e.render(nearby, 48, 48, img);
  e.render(nearby, 48, 48, img);
  EXPECT_FALSE(e.exploring());
  // Rest at a view 90 degrees away: the second frame there starts a re-check; every frame is
  // Naive's image; it ends with a decision and says so.
  const Camera side = test::orbit(s.v, 120, 20);
  const Image naive = test::renderWith(s.v, tf, test::builder(BuilderKind::Naive), 120, 20, false, 48);
  e.render(side, 48, 48, img);
  EXPECT_FALSE(e.exploring()) << "the camera was still moving";
  e.render(side, 48, 48, img);
  EXPECT_TRUE(e.exploring()) << "a still camera far from the measured view re-checks";
  int frames = 0;
  while (e.exploring() && frames < 20) {
    e.render(side, 48, 48, img);
    ++frames;
    EXPECT_LE(compareImages(naive, img).maxAbs, 1.f / 255.f) << "frame " << frames;
  }
  EXPECT_FALSE(e.exploring());
  EXPECT_LE(frames, 8) << "the contenders twice each, then the kept one";
  EXPECT_NE(e.buildStats().choice.find("re-checked 1x"), std::string::npos) << e.buildStats().choice;
  // Resting at the re-checked view: nothing more.
  const int builds = e.counters().builds;
  for (int i = 0; i < 3; ++i) e.render(side, 48, 48, img);
  EXPECT_FALSE(e.exploring());
  EXPECT_LE(e.counters().builds, builds + 1);  // the kept one, when the re-check ended on another
  // A re-check cancelled by a camera that moves on: the kept structure draws the next frame.
  const Camera back = test::orbit(s.v, 0, 20);
  e.render(back, 48, 48, img);
  e.render(back, 48, 48, img);
  ASSERT_TRUE(e.exploring());
  const std::string kept = e.buildStats().choice;
  e.render(test::orbit(s.v, 200, 20), 48, 48, img);
  EXPECT_FALSE(e.exploring()) << "the camera moved during the re-check";
  e.render(test::orbit(s.v, 200, 20), 48, 48, img);
  EXPECT_EQ(keptOf(kept), builderName(e.buildStats().builder)) << kept;
}

TEST(AutoBuilder, EditsAtAStillNewViewBuildNoContender) {
  // A user who turned the view and rests there while editing the TF: the frames showing edits
  // draw with the kept structure (or Grid standing in for it) and build nothing else; a re-check
  // the camera's rest started is cancelled by the edit, never finished on edit frames.
  Scene s;
  Engine& e = s.e;
  Image& img = s.img;
  auto ramp = [](float zeroUpTo, float red) {
    return TransferFunction::fromPoints({{0, 1, 1, 1, 0.f}, {zeroUpTo, 1, 1, 1, 0.f}, {255, red, 0, 0, 0.8f}}, 0, 255, 256);
  };
  e.setTransferFunction(ramp(30, 1));
  s.settle(48, 48);
  e.render(s.cam, 48, 48, img);  // the kept one's build, when measuring ended on another
  const std::string choice = e.buildStats().choice;
  const std::string kept = keptOf(choice);
  const Camera side = test::orbit(s.v, 120, 20);
  e.render(side, 48, 48, img);
  e.render(side, 48, 48, img);
  ASSERT_TRUE(e.exploring()) << "test premise: a still camera far from the measured view re-checks";
  // Edits, each followed by a quiet frame (which may start a re-check again): opacity edits that
  // move the occupancy a little, an opacity edit that keeps it, a colour-only edit.
  const TransferFunction edits[] = {ramp(40, 1), ramp(30, 1), ramp(31, 1), ramp(31, 0.5f), ramp(44, 0.5f)};
  for (const TransferFunction& tf : edits) {
    const Image naive = test::renderWith(s.v, tf, test::builder(BuilderKind::Naive), 120, 20, false, 48);
    const int builds = e.counters().builds;
    e.setTransferFunction(tf);
    e.render(side, 48, 48, img);
    const std::string used = builderName(e.buildStats().builder);
    EXPECT_TRUE(used == kept || used == "Grid") << used << " drew an edit frame; kept " << kept;
    EXPECT_LE(e.counters().builds, builds + 1) << "the kept structure's rebuild at most";
    EXPECT_FALSE(e.exploring()) << "an edit frame starts no re-check";
    EXPECT_LE(compareImages(naive, img).maxAbs, 1.f / 255.f);
    e.render(side, 48, 48, img);  // the quiet frame after it
    EXPECT_LE(compareImages(naive, img).maxAbs, 1.f / 255.f);
  }
  // Left alone at that view, the re-check runs to its end.
  for (int i = 0; i < 20 && e.exploring(); ++i) e.render(side, 48, 48, img);
  EXPECT_FALSE(e.exploring());
}

TEST(AutoBuilder, NeverSlowerThanNaiveOnEveryShapeAt256) {
  // Issue 13's CPU rule: on every generated shape at 256^3 (the paper's stand-ins among them),
  // Auto's settled frames are at least 0.95x as fast as Naive's. Ratios of frame times taken
  // alternately in this one process (medians of 7), never absolute times.
  // Other tests run beside this one (ctest -j): a measurement disturbed by them is taken again,
  // up to 3 times (Auto measures afresh each time); a structure Auto keeps that is really slower
  // fails every attempt.
  auto ratioFor = [](const std::string& shape, const Volume& v, std::string& choice) {
    double lo = 0, hi = 1;
    EXPECT_TRUE(v.scalarRange(lo, hi)) << shape;
    const TransferFunction tf = TransferFunction::preset("ramp", lo, hi);
    const Camera cam = test::orbit(v, 30, 20);
    Engine naive{BackendKind::CPU}, autoE{BackendKind::CPU};
    test::load(naive, v, tf, test::builder(BuilderKind::Naive));
    test::load(autoE, v, tf, test::builder(BuilderKind::Auto));
    Image img;
    const int size = 128;
    // No warm-up frame: a cold first Naive frame is one of the 7 and the median drops it.
    // Up to 40 measuring frames, as the CLI's bench allows: where the candidates' frames are
    // about 1 ms (kingsnake on the H100 host's CPU), the second pass repeats each of three candidates up
    // to 3 times, and Auto was still measuring after 10 frames there.
    for (int i = 0; i < 40 && autoE.exploring(); ++i) autoE.render(cam, size, size, img);
    EXPECT_FALSE(autoE.exploring()) << shape;
    autoE.render(cam, size, size, img);  // the kept structure's build
    std::vector<double> tn, ta;
    // Each engine first in every other pair, so that neither always runs right after the
    // other (on the H100 host's 16 cores Auto-kept-Naive once measured 0.89-0.95x Naive itself
    // with Auto always second): medians of 7.
    for (int i = 0; i < 7; ++i) {
      for (int k = 0; k < 2; ++k) {
        Engine& e = (i + k) % 2 == 0 ? naive : autoE;
        e.render(cam, size, size, img);
        (&e == &naive ? tn : ta).push_back(e.frameStats().seconds);
      }
    }
    std::sort(tn.begin(), tn.end());
    std::sort(ta.begin(), ta.end());
    choice = autoE.buildStats().choice;
    return tn[3] / ta[3];
  };
  // An attempt in which Auto kept Naive passes whatever its ratio: Auto then draws with Naive
  // itself, and the ratio is the two engines' own noise (CI's 2-core machine, 2026-11-30, the
  // fully occupied noise shape: Auto keeping Naive measured 0.92x Naive; 0.89-0.95x on the H100
  // host, above).
  auto keptNaive = [](const std::string& choice) { return choice.rfind("Auto chose Naive:", 0) == 0; };
  for (const std::string& shape : generatorShapes()) {
    const Volume v = generateVolume(shape, vec3l{256, 256, 256});  // once, not per attempt
    std::string choice;
    double ratio = 0;
    for (int attempt = 0; attempt < 3 && ratio < 0.95 && !keptNaive(choice); ++attempt) {
      ratio = ratioFor(shape, v, choice);
      std::printf("  %-10s Auto %.2fx naive (%s)\n", shape.c_str(), ratio, choice.c_str());
    }
    if (!keptNaive(choice)) EXPECT_GE(ratio, 0.95) << shape << ": " << choice;
  }
}

TEST(AutoBuilder, OnProbesOneFrameDecidesAndDrawsWithTheChoice) {
  // The CPU backend's default: Auto measures on probes inside the frame that needs a decision,
  // so no user frame is ever drawn with a slow candidate and measuring never spans frames.
  Scene s;
  Engine& e = s.e;
  Image& img = s.img;
  e.setBuildParams(test::builder(BuilderKind::Auto));  // autoProbe -1: probes on the CPU
  const Image naive = test::renderWith(s.v, s.tf, test::builder(BuilderKind::Naive), 30, 20, false, 256);
  e.render(s.cam, 256, 256, img);
  EXPECT_FALSE(e.exploring());
  EXPECT_EQ(e.counters().frames, 1);
  EXPECT_EQ(e.counters().autoProbeMeasurings, 1);
  // The first pass (4 candidates) and the second (at most 3 probes each): at most 16 probes, each of
  // 64 x 64 pixels (1/16 of the frame).
  EXPECT_GE(e.counters().autoProbeFrames, 5);
  EXPECT_LE(e.counters().autoProbeFrames, 16);
  const std::string choice = e.buildStats().choice;
  EXPECT_EQ(keptOf(choice), builderName(e.buildStats().builder)) << choice;
  // The times are the probes' scaled by the kept structure's own frame: the kept one's is the
  // frame just drawn (two significant digits printed, a build term at most a few percent).
  EXPECT_NE(choice.find("scaled by the kept structure's own frame"), std::string::npos) << choice;
  for (const auto& c : costsOf(choice))
    if (c.first == keptOf(choice)) EXPECT_NEAR(c.second / e.frameStats().seconds, 1.0, 0.1) << choice;
  EXPECT_EQ(costsOf(choice).size(), 4u) << choice;
  EXPECT_LE(compareImages(naive, img).maxAbs, 1.f / 255.f);
  // The same view again: no measuring, no build.
  const int builds = e.counters().builds;
  e.render(s.cam, 256, 256, img);
  EXPECT_EQ(e.counters().autoProbeMeasurings, 1);
  EXPECT_EQ(e.counters().builds, builds);
  EXPECT_LE(compareImages(naive, img).maxAbs, 1.f / 255.f);
  // Another frame size measures again, within that frame.
  e.render(s.cam, 200, 120, img);
  EXPECT_FALSE(e.exploring());
  EXPECT_EQ(e.counters().autoProbeMeasurings, 2);
  // An opacity edit that moves the occupancy by more than 0.1: measured again in its frame.
  const double before = e.buildStats().occupancy;
  e.setTransferFunction(TransferFunction::fromPoints({{0, 1, 1, 1, 0.02f}, {255, 1, 0, 0, 0.8f}}, 0, 255, 256));
  e.render(s.cam, 200, 120, img);
  ASSERT_GT(std::fabs(e.buildStats().occupancy - before), 0.1) << "test premise";
  EXPECT_FALSE(e.exploring());
  EXPECT_EQ(e.counters().autoProbeMeasurings, 3) << e.buildStats().choice;
  // A still camera at a far view re-checks there, on probes, in one frame.
  const Camera side = test::orbit(s.v, 140, 20);
  e.render(side, 200, 120, img);
  e.render(side, 200, 120, img);
  EXPECT_FALSE(e.exploring());
  EXPECT_EQ(e.counters().autoProbeMeasurings, 4) << e.buildStats().choice;
  EXPECT_NE(e.buildStats().choice.find("re-checked 1x"), std::string::npos) << e.buildStats().choice;
}

TEST(AutoBuilder, TheMeasuringsFirstFramePaysItsWarmUpAndPrunesNothing) {
  // The measuring's first frame also pays its warm-up (cold caches, the thread pool waking): once
  // Naive's first probe of the dense Wavelet took 46 ms against its usual 16, which pruned it from
  // the second pass, and Auto kept Grid (20 ms), slower than Naive. Scripted probe times: Naive
  // first at 3x its time, then its own; the others steady.
  AutoBuilder ab;
  ab.start(test::builder(BuilderKind::Auto), BackendKind::CPU);
  AutoBuilder::ViewKey view;
  view.dir[2] = 1;
  view.zoom = view.distance = 1;
  view.valid = true;
  std::vector<int> drawn;
  auto naiveFrames = [&] {
    return std::count_if(drawn.begin(), drawn.end(), [&](int c) { return ab.candidate(c).builder == BuilderKind::Naive; });
  };
  auto drawProbe = [&](int, int) {
    const int c = ab.chooseBuild(false, false, -1);
    if (ab.needsBuild()) ab.builtCandidate(c, 0.0);
    const BuilderKind k = ab.candidate(c).builder;
    const bool firstNaive = k == BuilderKind::Naive && naiveFrames() == 0;
    drawn.push_back(c);
    if (k == BuilderKind::Naive) return firstNaive ? 46e-3 : 16e-3;
    return k == BuilderKind::Grid ? 20e-3 : 40e-3;
  };
  bool decided = false;
  ASSERT_TRUE(ab.measureOnProbes(256, 256, view, drawProbe, [](double) {}, [] { return 0.5; }, decided));
  ASSERT_TRUE(decided);
  EXPECT_EQ(keptOf(ab.choice()), "Naive") << ab.choice();
  ASSERT_EQ(ab.candidate(drawn.front()).builder, BuilderKind::Naive) << "test premise: Naive is measured first";
  // Naive drew one frame more, and no candidate that the first pass pruned fairly (40 ms > 1.5 x
  // 20 ms) drew again.
  EXPECT_EQ(naiveFrames(), 2);
  EXPECT_EQ(drawn.size(), size_t(ab.candidates(test::builder(BuilderKind::Auto), BackendKind::CPU).size()) + 2)
      << "the first pass, Grid once (20 ms: 1 frame reaches 2 ms) and Naive once more";
}
