// Label map (LabelMap on, issue 37): touching uint8 blobs whose ids are far apart (1 next to 5,
// 2 next to 9), coloured by a vtkColorTransferFunction with IndexedLookup (annotated values and
// indexed colours, ParaView's categorical colour map) and one mapper-level label. Opaque and
// unshaded, every pixel is the background or one label's colour (the ordinary volume through the
// same colours invents others at the borders); hiding a label re-classifies without a rebuild
// of anything but the structure; then shaded and translucent, the regression image.
#include "SpaceSkipTestHelpers.h"

#include "vtkColorTransferFunction.h"
#include "vtkVariant.h"

#include <set>

namespace
{
// Pixels whose colour is neither the background nor one of `colours` (8-bit, +-1).
vtkIdType Unexplained(vtkImageData* img, const std::vector<std::array<int, 3>>& colours)
{
  const unsigned char* p = sstest::Pixels(img);
  const vtkIdType n = sstest::ByteCount(img) / 3;
  vtkIdType bad = 0;
  for (vtkIdType i = 0; i < n; ++i)
  {
    bool ok = false;
    for (const auto& c : colours)
    {
      ok = ok || (std::abs(p[3 * i] - c[0]) <= 1 && std::abs(p[3 * i + 1] - c[1]) <= 1 &&
                   std::abs(p[3 * i + 2] - c[2]) <= 1);
    }
    bad += ok ? 0 : 1;
  }
  return bad;
}
}

int TestSpaceSkippingVolumeLabelMap(int argc, char* argv[])
{
  struct Blob
  {
    double x, y, z, r;
    int label;
  };
  const Blob blobs[] = { { 14, 14, 14, 8, 1 }, { 24, 15, 15, 7, 5 }, { 16, 25, 18, 7, 9 },
    { 26, 26, 26, 6, 2 } };
  auto image = sstest::MakePointField<vtkUnsignedCharArray>(40, 40, 40, "labels", [&](int x, int y, int z) {
    int l = 0;
    for (const Blob& b : blobs)
    {
      if ((x - b.x) * (x - b.x) + (y - b.y) * (y - b.y) + (z - b.z) * (z - b.z) <= b.r * b.r)
      {
        l = b.label;
      }
    }
    return static_cast<unsigned char>(l);
  });

  vtkNew<vtkSpaceSkippingVolumeMapper> mapper;
  mapper->SetInputData(image);
  mapper->SetBackendToCPU();
  mapper->SetBuilderToKdTreeCPU();
  mapper->LabelMapOn();
  sstest::Scene scene(mapper, 300, 300, sstest::kNavy, true);
  vtkVolumeProperty* prop = scene.Property;
  // Categorical colours for 1, 5 and 9; label 2 is the mapper's own.
  vtkNew<vtkColorTransferFunction> ctf;
  ctf->IndexedLookupOn();
  const double colours[3][3] = { { 1, 0.2, 0.2 }, { 0.2, 0.9, 0.2 }, { 0.3, 0.4, 1 } };
  const int ids[3] = { 1, 5, 9 };
  for (int i = 0; i < 3; ++i)
  {
    ctf->AddRGBPoint(ids[i], colours[i][0], colours[i][1], colours[i][2]);
    ctf->SetAnnotation(vtkVariant(ids[i]), std::to_string(ids[i]));
  }
  // (With IndexedLookup the indexed colours are the nodes' colours, in order.)
  mapper->SetLabelColor(2, 1, 0.9, 0.1);
  vtkNew<vtkPiecewiseFunction> otf;
  otf->AddPoint(0, 1);
  otf->AddPoint(9, 1);
  prop->SetColor(ctf);
  prop->SetScalarOpacity(otf);
  prop->ShadeOff();
  scene.View(30, 20);

  // Opaque, unshaded: one label's colour or the background per pixel.
  std::vector<std::array<int, 3>> explained{ { 26, 26, 51 } }; // kNavy in 8 bits
  for (const auto& c : colours)
  {
    explained.push_back({ int(c[0] * 255 + 0.5), int(c[1] * 255 + 0.5), int(c[2] * 255 + 0.5) });
  }
  explained.push_back({ 255, int(0.9 * 255 + 0.5), int(0.1 * 255 + 0.5) });
  for (int sampling : { vtkSpaceSkippingVolumeMapper::NearestLabel, vtkSpaceSkippingVolumeMapper::BlendedLabel })
  {
    mapper->SetLabelSampling(sampling);
    auto shot = scene.Shot();
    const vtkIdType drawn = sstest::CountNonBackground(shot, sstest::kNavy);
    const vtkIdType bad = Unexplained(shot, explained);
    std::cout << "sampling " << sampling << ": drawn " << drawn << ", unexplained " << bad << "\n";
    SS_CHECK(drawn > 5000);
    SS_CHECK(bad == 0);
  }
  // The same data as an ordinary volume through a continuous map of the same colours: the
  // borders show colours of no label (the check above can fail).
  {
    vtkNew<vtkColorTransferFunction> ramp;
    ramp->AddRGBPoint(1, colours[0][0], colours[0][1], colours[0][2]);
    ramp->AddRGBPoint(2, 1, 0.9, 0.1);
    ramp->AddRGBPoint(5, colours[1][0], colours[1][1], colours[1][2]);
    ramp->AddRGBPoint(9, colours[2][0], colours[2][1], colours[2][2]);
    vtkNew<vtkPiecewiseFunction> step;
    step->AddPoint(0, 0);
    step->AddPoint(0.5, 1);
    step->AddPoint(9, 1);
    prop->SetColor(ramp);
    prop->SetScalarOpacity(step);
    mapper->LabelMapOff();
    const vtkIdType bad = Unexplained(scene.Shot(), explained);
    std::cout << "ordinary volume: unexplained " << bad << "\n";
    SS_CHECK(bad > 100);
    prop->SetColor(ctf);
    prop->SetScalarOpacity(otf);
    mapper->LabelMapOn();
  }

  // Hiding a label: a re-classification, the colour function sampled no more.
  scene.Shot();
  const int classified = mapper->GetClassifyCount();
  const int colourSamples = mapper->GetColorTableSampleCount();
  mapper->SetLabelVisibility(5, 0);
  auto hidden = scene.Shot();
  std::cout << "hide label 5: classifications " << mapper->GetClassifyCount() - classified << "\n";
  SS_CHECK(mapper->GetClassifyCount() == classified + 1);
  SS_CHECK(mapper->GetColorTableSampleCount() == colourSamples);
  const std::array<int, 3> green{ int(0.2 * 255 + 0.5), int(0.9 * 255 + 0.5), int(0.2 * 255 + 0.5) };
  SS_CHECK(Unexplained(hidden, { green }) == sstest::ByteCount(hidden) / 3); // no pixel of label 5
  mapper->SetLabelVisibility(5, 1);

  // Shaded and translucent: the regression image.
  otf->RemoveAllPoints();
  otf->AddPoint(0, 0.5);
  otf->AddPoint(9, 0.5);
  prop->ShadeOn();
  prop->SetAmbient(0.3);
  prop->SetDiffuse(0.7);
  mapper->SetLabelSampling(vtkSpaceSkippingVolumeMapper::BlendedLabel);
  const vtkIdType drawn = sstest::CountNonBackground(scene.Shot(), sstest::kNavy);
  SS_CHECK(drawn > 5000);
  return scene.Regression(argc, argv);
}
