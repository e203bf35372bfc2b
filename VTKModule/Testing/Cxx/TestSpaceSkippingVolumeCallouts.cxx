// The application runs code in the middle of a frame: the mapper's progress events and warnings
// reach its observers (ParaView's progress bar runs Qt's event loop there, and Qt paints its
// widgets: in the render window's context, behind VTK's GL state cache, or in another context
// it makes current). The frame must still land in the window: here a progress observer binds
// the default framebuffer, shrinks the viewport, sets a scissor box, turns blending off, unbinds
// the program and makes a second window's context current, as such an event loop may. The image
// must equal the same scene's without the observer (max 1/255), with an opaque sphere in it so
// that the depth read from the frame's framebuffer is part of what is checked.
#include "SpaceSkipTestHelpers.h"

#include "vtkCallbackCommand.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkSpaceSkipOpenGL.h"

namespace
{
struct Meddler
{
  vtkRenderWindow* Other = nullptr;
  int Calls = 0;
};

// A progress observer that leaves GL as an application's event loop may leave it.
void Meddle(vtkObject*, unsigned long, void* clientData, void*)
{
  Meddler* m = static_cast<Meddler*>(clientData);
  ++m->Calls;
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glViewport(0, 0, 7, 5);
  glEnable(GL_SCISSOR_TEST);
  glScissor(1, 1, 2, 2);
  glDisable(GL_BLEND);
  glBlendFunc(GL_ZERO, GL_ZERO);
  glDisable(GL_DEPTH_TEST);
  glUseProgram(0);
  glActiveTexture(GL_TEXTURE5);
  m->Other->MakeCurrent();
}

vtkSmartPointer<vtkImageData> Draw(vtkImageData* image, Meddler* meddler)
{
  auto mapper = sstest::NewMapper(image, vtkSpaceSkippingVolumeMapper::Grid);
  mapper->SetBackendToCPU(); // reports its steps' progress
  sstest::Scene scene(mapper, 200, 200, sstest::kNavy);
  sstest::SetupProperty(scene.Property, image);
  auto sphere = sstest::MakeSphereActor();
  scene.Renderer->AddActor(sphere);
  scene.View(30, 20);
  if (meddler)
  {
    vtkNew<vtkCallbackCommand> cb;
    cb->SetCallback(Meddle);
    cb->SetClientData(meddler);
    mapper->AddObserver(vtkCommand::ProgressEvent, cb);
    auto img = scene.Shot();
    // An edit of the opacity: classification again, with its progress, in a later frame.
    scene.Property->GetScalarOpacity()->AddPoint(image->GetScalarRange()[1] * 0.9, 0.9);
    scene.Window->Render();
    scene.Property->GetScalarOpacity()->RemovePoint(image->GetScalarRange()[1] * 0.9);
    return scene.Shot();
  }
  scene.Shot();
  return scene.Shot();
}
}

int TestSpaceSkippingVolumeCallouts(int, char*[])
{
  auto image = sstest::MakeWavelet(48);
  // The other context: a window of its own, drawn once so that it has one.
  vtkNew<vtkRenderer> otherRen;
  vtkSmartPointer<vtkRenderWindow> other = sstest::NewTestWindow();
  other->SetSize(16, 16);
  other->AddRenderer(otherRen);
  other->Render();

  auto reference = Draw(image, nullptr);
  Meddler meddler;
  meddler.Other = other;
  auto meddled = Draw(image, &meddler);
  const int maxDiff = sstest::MaxDiff(reference, meddled);
  const vtkIdType drawn = sstest::CountNonBackground(meddled, sstest::kNavy);
  std::cout << "progress call-outs: " << meddler.Calls << "; max |diff| from the undisturbed scene "
            << maxDiff << "/255; " << drawn << " pixels drawn" << std::endl;
  SS_CHECK(meddler.Calls > 0);
  SS_CHECK(drawn > 2000);
  SS_CHECK(maxDiff <= 1);
  return EXIT_SUCCESS;
}
