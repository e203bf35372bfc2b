// Cropping (vtkVolumeMapper's region planes and flags, as ParaView's Use Cropping sets them),
// clipping planes (vtkAbstractMapper) and jittering against VTK's vtkGPUVolumeRayCastMapper in
// the same window: PSNR per case, and every builder's image equal to Naive's (max 1/255).
#include "vtkMatrix4x4.h"
#include "vtkPlane.h"
#include "vtkPlaneCollection.h"
#include "vtkTransform.h"

#include "SpaceSkipTestHelpers.h"

namespace
{
constexpr double kMinPSNR = 40.0;

// The same cropping and clipping on both mappers.
void Configure(vtkVolumeMapper* m, bool crop, int flags, const double planes[6],
  vtkPlaneCollection* clip)
{
  m->SetCropping(crop);
  m->SetCroppingRegionFlags(flags);
  m->SetCroppingRegionPlanes(const_cast<double*>(planes));
  m->SetClippingPlanes(clip);
}
}

int TestSpaceSkippingVolumeCropClip(int argc, char* argv[])
{
  auto image = sstest::MakeWavelet(64);
  double bounds[6];
  image->GetBounds(bounds);
  const double sampleDistance = 0.5;
  auto gpu = sstest::ReferenceGPUMapper(image, sampleDistance);
  auto ours = sstest::NewMapper(image, vtkSpaceSkippingVolumeMapper::AutoBuilder, sampleDistance, false);
  sstest::Scene scene(ours, 256, 256);
  sstest::SetupProperty(scene.Property, image, 0.3);
  vtkVolume* volume = scene.Volume;
  vtkRenderWindow* win = scene.Window;
  // A volume matrix, so that world-space clipping planes must be carried into the data's frame.
  vtkNew<vtkTransform> xf;
  xf->Translate(5, -3, 2);
  xf->RotateZ(20);
  volume->SetUserTransform(xf);
  scene.View(35, 25, 1.4, true);
  const std::string dir = sstest::TempDir(argc, argv);

  // Cropping planes at 30% and 65% of each axis (data coordinates).
  double planes[6];
  for (int a = 0; a < 3; ++a)
  {
    const double lo = bounds[2 * a], w = bounds[2 * a + 1] - lo;
    planes[2 * a] = lo + 0.3 * w;
    planes[2 * a + 1] = lo + 0.65 * w;
  }
  // Clipping planes in world coordinates: an oblique one through the volume's centre (world),
  // and a second one that cuts a slab off the other side.
  double c[3], cw[3];
  image->GetCenter(c);
  {
    double p[4] = { c[0], c[1], c[2], 1 }, q[4];
    volume->GetMatrix()->MultiplyPoint(p, q);
    cw[0] = q[0];
    cw[1] = q[1];
    cw[2] = q[2];
  }
  vtkNew<vtkPlane> oblique;
  oblique->SetOrigin(cw);
  oblique->SetNormal(0.6, -0.48, 0.64);
  vtkNew<vtkPlane> slab;
  slab->SetOrigin(cw[0], cw[1] + 20, cw[2]);
  slab->SetNormal(0, -1, 0);
  vtkNew<vtkPlaneCollection> none, one, two;
  one->AddItem(oblique);
  two->AddItem(oblique);
  two->AddItem(slab);

  struct Case
  {
    const char* name;
    bool crop;
    int flags;
    vtkPlaneCollection* clip;
  };
  const Case cases[] = {
    { "subvolume", true, VTK_CROP_SUBVOLUME, none },
    { "fence", true, VTK_CROP_FENCE, none },
    { "inverted-cross", true, VTK_CROP_INVERTED_CROSS, none },
    { "clip-oblique", false, VTK_CROP_SUBVOLUME, one },
    { "clip-two", false, VTK_CROP_SUBVOLUME, two },
    { "crop-and-clip", true, VTK_CROP_INVERTED_FENCE, one },
  };
  const int builders[] = { vtkSpaceSkippingVolumeMapper::Grid, vtkSpaceSkippingVolumeMapper::LBVH,
    vtkSpaceSkippingVolumeMapper::KdTreeCPU, vtkSpaceSkippingVolumeMapper::Hybrid,
    vtkSpaceSkippingVolumeMapper::DistanceGrid };
  const double bg[3] = { 0, 0, 0 };
  ours->SetBuilderToNaive();
  auto uncut = sstest::RenderWith(win, volume, ours);
  double worst = std::numeric_limits<double>::infinity();
  for (const Case& k : cases)
  {
    Configure(gpu, k.crop, k.flags, planes, k.clip);
    Configure(ours, k.crop, k.flags, planes, k.clip);
    ours->SetBuilderToNaive();
    auto a = sstest::RenderWith(win, volume, gpu);
    auto naive = sstest::RenderWith(win, volume, ours);
    const double psnr = sstest::PrintComparison(k.name, a, naive);
    std::cout << ", PSNR vs uncut " << sstest::PSNR(uncut, naive) << " dB; backend "
              << ours->GetBackendUsed() << "\n";
    const std::string prefix = dir + "/TestSpaceSkippingVolumeCropClip-" + k.name;
    sstest::WritePNG(a, prefix + "-gpu.png");
    sstest::WritePNG(naive, prefix + "-ours.png");
    worst = std::min(worst, psnr);
    SS_CHECK(sstest::CountNonBackground(naive, bg) > 500);
    SS_CHECK(sstest::PSNR(uncut, naive) < 35.0); // the cut is visible
    for (int b : builders)
    {
      ours->SetBuilder(b);
      auto img = sstest::RenderWith(win, volume, ours);
      const int diff = sstest::MaxDiff(naive, img);
      if (diff > 1)
      {
        std::cout << "  builder " << ours->GetBuilderUsed() << ": max |diff| vs Naive " << diff
                  << "/255\n";
      }
      SS_CHECK(diff <= 1);
    }
  }
  std::cout << "worst PSNR " << worst << " dB (threshold " << kMinPSNR << ")\n";
  SS_CHECK(worst >= kMinPSNR);

  // Jittering: changes the image (noise instead of wood grain), stays lossless per builder.
  Configure(ours, false, VTK_CROP_SUBVOLUME, planes, none);
  ours->SetSampleDistance(2.0);
  ours->SetBuilderToNaive();
  auto plain = sstest::RenderWith(win, volume, ours);
  ours->UseJitteringOn();
  auto jittered = sstest::RenderWith(win, volume, ours);
  std::cout << "jittering at sample distance 2: PSNR(plain, jittered) = "
            << sstest::PSNR(plain, jittered) << " dB\n";
  SS_CHECK(sstest::MaxDiff(plain, jittered) > 1);
  SS_CHECK(sstest::PSNR(plain, jittered) > 25.0);
  for (int b : builders)
  {
    ours->SetBuilder(b);
    SS_CHECK(sstest::MaxDiff(jittered, sstest::RenderWith(win, volume, ours)) <= 1);
  }
  return EXIT_SUCCESS;
}
