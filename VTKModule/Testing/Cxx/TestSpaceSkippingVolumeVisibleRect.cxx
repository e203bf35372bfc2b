// The compositor blends only the rectangle of the window the volume's rays can colour
// (vtkSpaceSkipCompositor::VisibleRect): the image must equal the whole-window blend
// (SPACESKIP_COMPOSITE_FULL=1) exactly, for orthographic and perspective cameras, a volume partly
// outside the window, an eye inside the box, a rotated and translated volume with a direction
// matrix and anisotropic spacing, a large jittered sample distance and a renderer viewport that
// is part of the window. The opacity function leaves no value transparent, so every ray that
// meets the box colours its pixel up to the box's silhouette.
#include "vtkCamera.h"
#include "vtkMatrix3x3.h"
#include "vtkNew.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkSpaceSkippingVolumeMapper.h"
#include "vtkTransform.h"
#include "vtkVolume.h"
#include "vtkVolumeProperty.h"

#include "SpaceSkipTestHelpers.h"
#include "spaceskip/Tuning.h"

#include <cstdlib>
#include <string>

int TestSpaceSkippingVolumeVisibleRect(int, char*[])
{
  auto image = sstest::MakeWavelet(40);
  double range[2];
  image->GetScalarRange(range);
  vtkNew<vtkVolumeProperty> prop;
  sstest::SetFunctions(prop,
    { { range[0], 0.1, 0.2, 0.9 }, { 0.5 * (range[0] + range[1]), 0.9, 0.9, 0.9 },
      { range[1], 0.9, 0.3, 0.1 } },
    { { range[0], 0.08 }, { range[1], 0.5 } });
  prop->SetInterpolationTypeToLinear();
  prop->ShadeOff();

  auto mapper = sstest::NewMapper(image, vtkSpaceSkippingVolumeMapper::Grid);
  mapper->SetBackend(vtkSpaceSkippingVolumeMapper::CPU);
  vtkNew<vtkVolume> volume;
  volume->SetMapper(mapper);
  volume->SetProperty(prop);
  vtkNew<vtkRenderer> ren;
  ren->SetBackground(0.3, 0.2, 0.1);
  ren->AddVolume(volume);
  vtkSmartPointer<vtkRenderWindow> win = sstest::NewTestWindow();
  win->SetMultiSamples(0);
  win->SetSize(160, 120);
  win->AddRenderer(ren);

  int failures = 0, cases = 0;
  // `smaller`: the volume leaves part of the viewport uncovered, so the rectangle must be
  // smaller than the viewport (the blend skips pixels).
  auto check = [&](const std::string& what, bool smaller) {
    ++cases;
    volume->VisibilityOff();
    win->Render();
    auto background = sstest::Capture(win);
    volume->VisibilityOn();
    spaceskip::Tuning wholeViewport;
    wholeViewport.compositeFull = true;
    mapper->SetTuning(wholeViewport);
    win->Render();
    auto full = sstest::Capture(win);
    mapper->SetTuning(spaceskip::Tuning{});
    win->Render();
    auto rect = sstest::Capture(win);
    int r[4], vw, vh, vx, vy;
    mapper->GetLastCompositeRect(r);
    ren->GetTiledSizeAndOrigin(&vw, &vh, &vx, &vy);
    const int diff = sstest::MaxDiff(full, rect);
    // Pixels the volume coloured in the whole-viewport blend, and those outside the rectangle.
    int dims[3];
    full->GetDimensions(dims);
    const unsigned char* p = sstest::Pixels(full);
    const unsigned char* bg = sstest::Pixels(background);
    vtkIdType drawn = 0, outside = 0;
    for (int y = vy; y < vy + vh; ++y)
    {
      for (int x = vx; x < vx + vw; ++x)
      {
        const vtkIdType i = 3 * (static_cast<vtkIdType>(y) * dims[0] + x);
        if (p[i] != bg[i] || p[i + 1] != bg[i + 1] || p[i + 2] != bg[i + 2])
        {
          ++drawn;
          const int lx = x - vx, ly = y - vy;
          outside += lx < r[0] || lx >= r[0] + r[2] || ly < r[1] || ly >= r[1] + r[3];
        }
      }
    }
    const bool tight = r[2] * r[3] < vw * vh;
    std::cout << what << ": max diff " << diff << "/255, " << drawn << " pixels coloured, "
              << outside << " outside the rectangle " << r[0] << "," << r[1] << " " << r[2] << "x"
              << r[3] << " of " << vw << "x" << vh << "\n";
    if (diff != 0 || drawn == 0 || outside != 0 || (smaller && !tight))
    {
      std::cerr << "FAILED: " << what << ": "
                << (drawn == 0 ? "nothing drawn"
                      : diff != 0 || outside != 0 ? "the rectangle's blend differs from the whole viewport's"
                                                  : "the rectangle is the whole viewport")
                << "\n";
      ++failures;
    }
  };

  vtkCamera* cam = ren->GetActiveCamera();
  auto orbit = [&](double azimuth, double elevation, bool parallel, double zoom) {
    ren->ResetCamera();
    cam->SetParallelProjection(parallel);
    cam->Azimuth(azimuth);
    cam->Elevation(elevation);
    cam->OrthogonalizeViewUp();
    cam->Zoom(zoom);
    ren->ResetCameraClippingRange();
  };
  for (double az : { 0.0, 35.0, 100.0 })
  {
    orbit(az, 20, true, 1.0);
    check("orthographic, azimuth " + std::to_string(int(az)), true);
  }
  orbit(30, -25, false, 1.0);
  check("perspective", true);
  orbit(30, -25, false, 2.5);
  check("perspective, volume partly outside the window", false);
  ren->ResetCamera();
  cam->SetParallelProjection(false);
  cam->SetPosition(3, 2, 4);
  cam->SetFocalPoint(10, 0, -5);
  ren->ResetCameraClippingRange();
  cam->SetClippingRange(0.1, 200);
  check("perspective, eye inside the box", false);

  // Rotated, translated, anisotropic, with a direction matrix.
  vtkNew<vtkTransform> rot;
  rot->RotateZ(25);
  rot->RotateX(-35);
  vtkNew<vtkMatrix3x3> dir;
  for (int i = 0; i < 3; ++i)
  {
    for (int j = 0; j < 3; ++j)
    {
      dir->SetElement(i, j, rot->GetMatrix()->GetElement(j, i));
    }
  }
  image->SetSpacing(1.0, 1.5, 0.7);
  image->SetOrigin(4, -3, 2);
  image->SetDirectionMatrix(dir);
  volume->SetOrientation(10, 40, -20);
  volume->SetPosition(7, 1, -4);
  orbit(60, 10, true, 1.3);
  check("direction matrix, anisotropic spacing, volume matrix (orthographic)", true);
  orbit(-40, 30, false, 1.8);
  check("direction matrix, anisotropic spacing, volume matrix (perspective)", true);

  // Large jittered steps: the last samples lie farthest outside the box.
  mapper->SetSampleDistance(4.0);
  mapper->UseJitteringOn();
  orbit(15, 15, true, 1.0);
  check("sample distance 4, jittering", true);
  mapper->SetSampleDistance(0.0);
  mapper->UseJitteringOff();

  // The renderer in part of the window (the rectangle is in its viewport).
  ren->SetViewport(0.15, 0.2, 0.9, 0.95);
  orbit(70, -10, false, 1.2);
  check("renderer viewport inside the window", true);

  std::cout << cases - failures << " of " << cases << " cases passed\n";
  return failures == 0 ? EXIT_SUCCESS : EXIT_FAILURE;
}
