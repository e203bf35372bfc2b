// vtkSpaceSkipPropertyTranslator: VTK's volume property, mapper settings, lights and camera ->
// Core's parameters, as vtkGPUVolumeRayCastMapper reads them.
#include "vtkSpaceSkipPropertyTranslator.h"

#include "vtkColorTransferFunction.h"
#include "vtkContourValues.h"
#include "vtkDataArray.h"
#include "vtkImageData.h"
#include "vtkImageResize.h"
#include "vtkImplicitFunction.h"
#include "vtkLight.h"
#include "vtkLightCollection.h"
#include "vtkMath.h"
#include "vtkMatrix3x3.h"
#include "vtkMatrix4x4.h"
#include "vtkNew.h"
#include "vtkOpenGLCamera.h"
#include "vtkPiecewiseFunction.h"
#include "vtkPlane.h"
#include "vtkPlaneCollection.h"
#include "vtkPointData.h"
#include "vtkRenderer.h"
#include "vtkSpaceSkipSettings.h"
#include "vtkVolume.h"
#include "vtkVolumeMapper.h"
#include "vtkVariant.h"
#include "vtkVersionMacros.h"
#include "vtkVolumeProperty.h"

#include "spaceskip/Engine.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <limits>
#include <array>
#include <vector>

namespace
{
// Table resolution of the transfer function, sampled over the data's scalar range (what
// vtkGPUVolumeRayCastMapper does by default, ColorRangeType == SCALAR).
constexpr int kTableSize = 1024;
// Entries of the gradient-opacity table: vtkOpenGLVolumeGradientOpacityTable's texture width.
constexpr int kGradientTableSize = 1024;
// Opacity at which a ray stops when EarlyRayTermination is on: 1 - 1/255, the threshold of
// vtkGPUVolumeRayCastMapper's shaders (g_opacityThreshold). What a stopped ray leaves out is below
// one 8-bit step, so the image stays within 1/255 of the unterminated one, and pieces drawn apart
// (MPI ranks, blocks) composite to the single image within 1/255; at 0.99 a piece behind a
// terminated one still added up to 1 % (2/255 between 2 ranks and 1 on the N-body ramp).
constexpr double kErtThreshold = 1.0 - 1.0 / 255.0;

static_assert(static_cast<int>(spaceskip::BlendMode::Isosurface) == vtkVolumeMapper::ISOSURFACE_BLEND &&
    static_cast<int>(spaceskip::BlendMode::MaximumIntensity) == vtkVolumeMapper::MAXIMUM_INTENSITY_BLEND,
  "spaceskip::BlendMode out of step with vtkVolumeMapper's blend modes");

// Core's column-major mat4 from a row-major vtkMatrix4x4.
spaceskip::mat4 ToCore(const vtkMatrix4x4* m)
{
  spaceskip::mat4 out;
  for (int r = 0; r < 4; ++r)
  {
    for (int c = 0; c < 4; ++c)
    {
      out.m[c * 4 + r] = m->GetElement(r, c);
    }
  }
  return out;
}

} // namespace

//------------------------------------------------------------------------------
vtkImageData* vtkSpaceSkipPropertyTranslator::Usable2D(vtkVolumeProperty* prop)
{
  if (prop->GetTransferFunctionMode() != vtkVolumeProperty::TF_2D)
  {
    return nullptr;
  }
  vtkImageData* img = prop->GetTransferFunction2D(0);
  if (!img)
  {
    return nullptr;
  }
  int dims[3];
  img->GetDimensions(dims);
  vtkDataArray* a = img->GetPointData() ? img->GetPointData()->GetScalars() : nullptr;
  const bool ok = a && a->GetNumberOfComponents() == 4 && dims[0] >= 1 && dims[1] >= 1 && dims[2] == 1 &&
    int64_t(dims[0]) * dims[1] <= (int64_t(1) << 24) && a->GetNumberOfTuples() == vtkIdType(dims[0]) * dims[1];
  return ok ? img : nullptr;
}

//------------------------------------------------------------------------------
double vtkSpaceSkipPropertyTranslator::EarlyTerminationOpacity(const vtkSpaceSkipSettings& s)
{
  return s.EarlyRayTermination ? kErtThreshold : 2.0;
}

//------------------------------------------------------------------------------
void vtkSpaceSkipPropertyTranslator::UpdateTransferFunction(spaceskip::Engine& engine,
  vtkVolumeProperty* prop, const double scalarRange[2], const double* opacityRange,
  int opacityComponent, bool secondAxis)
{
  const bool gray = prop->GetColorChannels(0) == 1;
  vtkObject* color = gray ? static_cast<vtkObject*>(prop->GetGrayTransferFunction(0))
                          : static_cast<vtkObject*>(prop->GetRGBTransferFunction(0));
  vtkPiecewiseFunction* opacity = prop->GetScalarOpacity(0);
  double lo = scalarRange[0], hi = scalarRange[1];
  if (!(hi > lo))
  {
    hi = lo + 1.0; // constant volume: any non-empty range samples its one value
  }
  double alo = 0, ahi = 0; // dependent components: the opacity component's range
  if (opacityRange)
  {
    alo = opacityRange[0];
    ahi = opacityRange[1] > alo ? opacityRange[1] : alo + 1.0;
  }
  // ParaView and VTK call Modified() on the property for many reasons (its MTime includes its
  // functions'): each part is judged by its own function, range and settings.
  // Any positive unit distance is taken as it is (a volume of spacing 1e-30 needs one that small:
  // a floor of 1e-12 drew it transparent); the engine forms dt / unit in double. Not positive
  // (or NaN): 1e-12, as before.
  const double askedUnit = prop->GetScalarOpacityUnitDistance(opacityComponent);
  const double unit = askedUnit > 0 ? std::min(askedUnit, std::numeric_limits<double>::max()) : 1e-12;
  const double slo = opacityRange ? alo : lo, shi = opacityRange ? ahi : hi;
  const bool colorStale = !this->HaveTF || this->ColorKey != color ||
    this->ColorMTime != color->GetMTime() || this->TableRange[0] != lo || this->TableRange[1] != hi ||
    this->Gray != gray;
  const bool opacityStale = !this->HaveTF || this->OpacityKey != opacity ||
    this->OpacityMTime != opacity->GetMTime() || this->OpacitySampleRange[0] != slo ||
    this->OpacitySampleRange[1] != shi || this->OpacityTableRange[0] != alo ||
    this->OpacityTableRange[1] != ahi || this->OpacityComponent != opacityComponent ||
    this->UnitDistance != unit;
  // The 2-D table (TF_2D) or the gradient opacity (1-D mode, when the user set one and did not
  // disable it), one-component volumes only. HasGradientOpacity first: GetGradientOpacity and
  // GetStoredGradientOpacity both create a default function on the user's property, which then
  // turns gradient opacity on for every other mapper drawing with it (vtkSmartVolumeMapper drew
  // nothing on TestSpaceSkippingVolumeComponents after ours had created one).
  // With a second array as its y axis (`secondAxis`) the 2-D table reads two components.
  vtkImageData* table2D = opacityRange && !secondAxis ? nullptr : Usable2D(prop);
  vtkPiecewiseFunction* gradient = opacityRange || prop->GetTransferFunctionMode() != vtkVolumeProperty::TF_1D ||
      !prop->HasGradientOpacity(0) || prop->GetDisableGradientOpacity(0)
    ? nullptr
    : prop->GetStoredGradientOpacity(0);
  const bool table2DStale = this->Table2DKey != table2D || (table2D && this->Table2DMTime != table2D->GetMTime());
  const bool gradientStale = this->GradientKey != gradient ||
    (gradient &&
      (this->GradientMTime != gradient->GetMTime() || this->GradientRange[0] != lo || this->GradientRange[1] != hi));
  if (!colorStale && !opacityStale && !table2DStale && !gradientStale)
  {
    return;
  }
  if (table2DStale)
  {
    this->Table2D.clear();
    this->Width2D = this->Height2D = 0;
    if (table2D)
    {
      // vtkOpenGLVolumeTransferFunction2D uploads the image resized (vtkImageResize, its default
      // sinc interpolation, corner points aligned) to a texture of max(1024, the next power of
      // two) texels per axis (vtkOpenGLVolumeLookupTable::ComputeIdealTextureSize; one row stays
      // one row): the engine gets that texture, read texel-centred as OpenGL reads it.
      int dims[3];
      table2D->GetDimensions(dims);
      const int w = std::max(1024, vtkMath::NearestPowerOfTwo(dims[0]));
      const int h = dims[1] > 1 ? std::max(1024, vtkMath::NearestPowerOfTwo(dims[1])) : 1;
      vtkNew<vtkImageResize> resize;
      vtkImageData* src = table2D;
      if (w != dims[0] || h != dims[1])
      {
        resize->SetInputData(table2D);
        resize->SetResizeMethodToOutputDimensions();
        resize->SetOutputDimensions(w, h, 1);
        resize->Update();
        src = resize->GetOutput();
        src->GetDimensions(dims);
      }
      vtkDataArray* a = src->GetPointData()->GetScalars();
      this->Width2D = dims[0];
      this->Height2D = dims[1];
      this->Table2D.resize(size_t(dims[0]) * size_t(dims[1]) * 4);
      for (vtkIdType i = 0; i < vtkIdType(dims[0]) * dims[1]; ++i)
      {
        for (int c = 0; c < 4; ++c)
        {
          this->Table2D[size_t(i) * 4 + c] = static_cast<float>(a->GetComponent(i, c));
        }
      }
    }
    this->Table2DKey = table2D;
    this->Table2DMTime = table2D ? table2D->GetMTime() : 0;
  }
  if (gradientStale)
  {
    this->GradientOpacity.clear();
    if (gradient)
    {
      // vtkOpenGLVolumeGradientOpacityTable: the function over [0, (max - min) / 4].
      this->GradientOpacity.resize(kGradientTableSize);
      gradient->GetTable(0, 0.25 * (hi - lo), kGradientTableSize, this->GradientOpacity.data());
      // A factor of 1 everywhere (vtkVolumeProperty's default function) changes nothing.
      if (std::all_of(this->GradientOpacity.begin(), this->GradientOpacity.end(), [](float g) { return g >= 1.f; }))
      {
        this->GradientOpacity.clear();
      }
    }
    this->GradientKey = gradient;
    this->GradientMTime = gradient ? gradient->GetMTime() : 0;
    this->GradientRange[0] = lo;
    this->GradientRange[1] = hi;
  }
  if (colorStale)
  {
    this->RGB.resize(3 * kTableSize);
    if (gray)
    {
      std::vector<float> g(kTableSize);
      static_cast<vtkPiecewiseFunction*>(color)->GetTable(lo, hi, kTableSize, g.data());
      for (int i = 0; i < kTableSize; ++i)
      {
        this->RGB[3 * i] = this->RGB[3 * i + 1] = this->RGB[3 * i + 2] = g[i];
      }
    }
    else
    {
      static_cast<vtkColorTransferFunction*>(color)->GetTable(lo, hi, kTableSize, this->RGB.data());
    }
    ++this->ColorSamples;
    this->ColorKey = color;
    this->ColorMTime = color->GetMTime();
    this->TableRange[0] = lo;
    this->TableRange[1] = hi;
    this->Gray = gray;
  }
  if (opacityStale)
  {
    this->Alpha.resize(kTableSize);
    opacity->GetTable(slo, shi, kTableSize, this->Alpha.data());
    ++this->OpacitySamples;
    this->OpacityKey = opacity;
    this->OpacityMTime = opacity->GetMTime();
    this->OpacitySampleRange[0] = slo;
    this->OpacitySampleRange[1] = shi;
    this->OpacityTableRange[0] = alo;
    this->OpacityTableRange[1] = ahi;
    this->OpacityComponent = opacityComponent;
    this->UnitDistance = unit;
  }
  spaceskip::TransferFunction tf;
  tf.rangeMin = lo;
  tf.rangeMax = hi;
  tf.unitDistance = unit;
  tf.ownOpacityRange = opacityRange != nullptr;
  tf.opacityRangeMin = alo;
  tf.opacityRangeMax = ahi;
  tf.table.resize(kTableSize);
  for (int i = 0; i < kTableSize; ++i)
  {
    tf.table[i] = spaceskip::vec4f{ this->RGB[3 * i], this->RGB[3 * i + 1], this->RGB[3 * i + 2],
      std::min(std::max(this->Alpha[i], 0.f), 1.f) };
  }
  if (!this->Table2D.empty())
  {
    tf.width2D = this->Width2D;
    tf.height2D = this->Height2D;
    tf.table2D.resize(size_t(this->Width2D) * size_t(this->Height2D));
    for (size_t i = 0; i < tf.table2D.size(); ++i)
    {
      const float* e = &this->Table2D[4 * i];
      tf.table2D[i] = spaceskip::vec4f{ e[0], e[1], e[2], std::min(std::max(e[3], 0.f), 1.f) };
    }
  }
  tf.gradientOpacity = this->GradientOpacity;
  // The engine compares only the parts that may differ from what it has (the 2-D and gradient
  // tables always).
  engine.setTransferFunction(std::move(tf), colorStale, opacityStale);
  this->HaveTF = true;
}

//------------------------------------------------------------------------------
void vtkSpaceSkipPropertyTranslator::UpdateParameters(spaceskip::Engine& engine,
  const vtkSpaceSkipSettings& s, vtkRenderer* ren, vtkVolume* vol, const double scalarRange[2],
  const WarnFunction& warnOnce)
{
  const int blendMode = s.EffectiveBlendMode();
  // Features of vtkVolumeProperty/vtkVolumeMapper the engine does not have: said once each.
  auto unsupported = [&](bool used, bool& warned, const char* what) {
    if (used && !warned)
    {
      warnOnce(what);
    }
    warned = warned || used;
  };
  vtkVolumeProperty* prop = vol->GetProperty();
  unsupported(prop->GetTransferFunctionMode() == vtkVolumeProperty::TF_2D && !Usable2D(prop), this->Warned2D,
    "2-D transfer function mode without a 2-D transfer function of 4-component scalars (one slice): "
    "rendering with the 1-D transfer functions");
  unsupported(blendMode < vtkVolumeMapper::COMPOSITE_BLEND || blendMode > vtkVolumeMapper::SLICE_BLEND,
    this->WarnedBlend, "unknown blend mode; rendering with composite blending");

  spaceskip::BuildParams bp;
  bp.builder = static_cast<spaceskip::BuilderKind>(s.Builder);
  bp.leaf = static_cast<spaceskip::LeafCriterion>(s.LeafCriterion);
  bp.maxLeafSize = s.MaxLeafSize;
  bp.bins = s.BinCount;
  // A new size makes the engine recompute the value ranges, re-classify and rebuild.
  bp.brick = s.MacroCellSize;
  engine.setBuildParams(bp);
  spaceskip::RenderParams rp = engine.renderParams();
  rp.sampleDistance = s.SampleDistance;
  rp.ertThreshold = EarlyTerminationOpacity(s);
  rp.jitter = s.UseJittering;
  // vtkVolumeProperty's InterpolationType: nearest samples the nearest voxel (the skipping is the
  // same: that voxel is one of a trilinear sample's corners).
  rp.nearest = vol->GetProperty()->GetInterpolationType() == VTK_NEAREST_INTERPOLATION;
  // The engine's own values (vtkSpaceSkippingVolumeMapper::FilterModeTypes, 1: HardwareFilter);
  // the CPU backend samples exactly whatever this says.
  rp.filter = s.FilterMode == static_cast<int>(spaceskip::FilterMode::Hardware)
    ? spaceskip::FilterMode::Hardware
    : spaceskip::FilterMode::Exact;
  // Cropping: the planes are in the data's coordinates, as the engine's.
  rp.cropping = s.Cropping;
  std::copy(s.CroppingRegionPlanes, s.CroppingRegionPlanes + 6, rp.croppingPlanes);
  rp.croppingFlags = s.CroppingRegionFlags;
  // Clipping planes are in world coordinates; the engine works in the data's, so each plane
  // n.X + d >= 0 becomes (A^T n).x + (n.t + d) >= 0 for X = A x + t, A the volume's matrix.
  rp.clipPlanes.clear();
  if (vtkPlaneCollection* planes = s.ClippingPlanes)
  {
    vtkMatrix4x4* A = vol->GetMatrix();
    planes->InitTraversal();
    while (vtkPlane* plane = planes->GetNextItem())
    {
      double n[3], p[3];
      plane->GetNormal(n);
      plane->GetOrigin(p);
      std::array<double, 4> c{};
      for (int k = 0; k < 3; ++k)
      {
        c[k] = n[0] * A->GetElement(0, k) + n[1] * A->GetElement(1, k) + n[2] * A->GetElement(2, k);
      }
      c[3] = n[0] * (A->GetElement(0, 3) - p[0]) + n[1] * (A->GetElement(1, 3) - p[1]) +
        n[2] * (A->GetElement(2, 3) - p[2]);
      rp.clipPlanes.push_back(c);
    }
  }
  // Where vtkGPUVolumeRayCastMapper samples first: one step in, or the jitter alone.
  rp.firstSampleOffset = s.UseJittering ? 0.0 : 1.0;
  this->SetBlendAndShading(rp, s, ren, vol, scalarRange, warnOnce);
  engine.setRenderParams(rp);
  UpdateLabels(engine, s.LabelMap, s.LabelSampling, s.LabelEdits, vol->GetProperty(), scalarRange);
}

//------------------------------------------------------------------------------
// Blend mode, iso values, the slice plane and shading from the settings, the volume property and
// the renderer's lights, as vtkGPUVolumeRayCastMapper reads them.
void vtkSpaceSkipPropertyTranslator::SetBlendAndShading(spaceskip::RenderParams& rp,
  const vtkSpaceSkipSettings& s, vtkRenderer* ren, vtkVolume* vol, const double scalarRange[2],
  const WarnFunction& warnOnce)
{
  const int mode = s.EffectiveBlendMode();
  rp.blend = mode >= vtkVolumeMapper::COMPOSITE_BLEND && mode <= vtkVolumeMapper::SLICE_BLEND
    ? static_cast<spaceskip::BlendMode>(mode)
    : spaceskip::BlendMode::Composite; // warned above
  rp.isoValues.clear();
  vtkVolumeProperty* prop = vol->GetProperty();
  if (rp.blend == spaceskip::BlendMode::Isosurface)
  {
    vtkContourValues* iso = prop->GetIsoSurfaceValues();
    for (int i = 0; i < iso->GetNumberOfContours(); ++i)
    {
      rp.isoValues.push_back(iso->GetValue(i));
    }
  }
  rp.scalarRange[0] = scalarRange[0];
  rp.scalarRange[1] = scalarRange[1];
  rp.averageRange[0] = s.AverageIPScalarRange[0];
  rp.averageRange[1] = s.AverageIPScalarRange[1];

  if (rp.blend == spaceskip::BlendMode::Slice)
  {
    this->SetSlicePlane(rp, s, vol, warnOnce);
  }

  rp.shade = prop->GetShade(0) != 0;
  rp.ambient = prop->GetAmbient(0);
  rp.diffuse = prop->GetDiffuse(0);
  rp.specular = prop->GetSpecular(0);
  rp.specularPower = prop->GetSpecularPower(0);
  rp.lightDirection[0] = rp.lightDirection[1] = rp.lightDirection[2] = 0; // headlight
  rp.useLights = false;
  rp.lights.clear();
  rp.twoSidedLighting = ren->GetTwoSidedLighting() != 0;
  // Volumetric shadows and scattering (the engine draws them in shaded composite and isosurface
  // frames only, as vtkGPUVolumeRayCastMapper).
  rp.scatteringBlending = s.VolumetricScatteringBlending;
  rp.globalIlluminationReach = s.GlobalIlluminationReach;
  rp.scatteringAnisotropy = prop->GetScatteringAnisotropy();
  // Four dependent components are lit by the gradient of component 0 in VTK 9.2 and 9.3's
  // vtkGPUVolumeRayCastMapper, of component 3 from VTK 9.4 on: the same as the VTK at hand.
#if VTK_VERSION_NUMBER >= VTK_VERSION_CHECK(9, 4, 0)
  rp.rgbaLightingComponent = 3;
#else
  rp.rgbaLightingComponent = 0;
#endif
  if (!rp.shade)
  {
    return;
  }
  // vtkOpenGLGPUVolumeRayCastMapper: one switched-on headlight of intensity 1 is its "default
  // lighting" (the headlight model); anything else (ParaView's light kit, several lights, a
  // directional or positional light, no light) is shaded with the list of switched-on lights.
  std::vector<vtkLight*> on;
  vtkLightCollection* lights = ren->GetLights();
  vtkCollectionSimpleIterator it;
  lights->InitTraversal(it);
  while (vtkLight* l = lights->GetNextLight(it))
  {
    if (l->GetSwitch())
    {
      on.push_back(l);
    }
  }
  if (on.size() == 1 && on[0]->GetIntensity() == 1.0 && on[0]->LightTypeIsHeadlight())
  {
    return; // the headlight model
  }
  rp.useLights = true;
  if (on.size() > size_t(spaceskip::kMaxLights) && !this->WarnedLight)
  {
    warnOnce("shading with " + std::to_string(on.size()) + " lights: only the first " +
      std::to_string(spaceskip::kMaxLights) + " are used");
    this->WarnedLight = true;
  }
  if (on.size() > size_t(spaceskip::kMaxLights))
  {
    on.resize(size_t(spaceskip::kMaxLights));
  }
  // World -> the volume's physical frame (the engine's world): points through the inverse of the
  // volume's matrix.
  vtkNew<vtkMatrix4x4> inv;
  vtkMatrix4x4::Invert(vol->GetMatrix(), inv);
  auto toData = [&](const double* w, double* out) {
    const double p[4] = { w[0], w[1], w[2], 1.0 };
    double o[4];
    inv->MultiplyPoint(p, o);
    for (int k = 0; k < 3; ++k)
    {
      out[k] = o[k] / o[3];
    }
  };
  for (vtkLight* l : on)
  {
    spaceskip::Light c;
    c.positional = l->GetPositional() != 0;
    toData(l->GetTransformedPosition(), c.position);
    toData(l->GetTransformedFocalPoint(), c.focalPoint);
    const double intensity = l->GetIntensity();
    for (int k = 0; k < 3; ++k)
    {
      c.ambient[k] = l->GetAmbientColor()[k] * intensity;
      c.diffuse[k] = l->GetDiffuseColor()[k] * intensity;
      c.specular[k] = l->GetSpecularColor()[k] * intensity;
      c.attenuation[k] = l->GetAttenuationValues()[k];
    }
    c.coneAngle = l->GetConeAngle();
    c.exponent = l->GetExponent();
    rp.lights.push_back(c);
  }
}

//------------------------------------------------------------------------------
// The slice plane of the slice blend mode: the property's slice function, a vtkPlane in world
// coordinates (as vtkGPUVolumeRayCastMapper reads its origin and normal), into the volume's
// physical frame; anything else: one warning and the plane through the data's centre, normal z.
void vtkSpaceSkipPropertyTranslator::SetSlicePlane(spaceskip::RenderParams& rp,
  const vtkSpaceSkipSettings& s, vtkVolume* vol, const WarnFunction& warnOnce)
{
  vtkImplicitFunction* func = vol->GetProperty()->GetSliceFunction();
  vtkPlane* plane = vtkPlane::SafeDownCast(func);
  if (!plane)
  {
    if (!this->WarnedSlice)
    {
      warnOnce(std::string("slice blend mode: ") +
        (func ? std::string("the slice function is a ") + func->GetClassName() + ", not a vtkPlane"
              : std::string("the volume property has no slice function (a vtkPlane)")) +
        "; slicing through the centre of the volume, normal to z");
      this->WarnedSlice = true;
    }
    const double* b = s.Bounds;
    for (int k = 0; k < 3; ++k)
    {
      rp.sliceOrigin[k] = 0.5 * (b[2 * k] + b[2 * k + 1]);
      rp.sliceNormal[k] = k == 2 ? 1.0 : 0.0;
    }
    return;
  }
  // A plane n.(X - o) = 0 in world; X = A x + t: (A^T n).(x - A^-1 (o - t)) = 0.
  double n[3], o[3];
  plane->GetNormal(n);
  plane->GetOrigin(o);
  vtkMatrix4x4* A = vol->GetMatrix();
  vtkNew<vtkMatrix4x4> inv;
  vtkMatrix4x4::Invert(A, inv);
  const double ow[4] = { o[0], o[1], o[2], 1.0 };
  double od[4];
  inv->MultiplyPoint(ow, od);
  for (int k = 0; k < 3; ++k)
  {
    rp.sliceNormal[k] =
      n[0] * A->GetElement(0, k) + n[1] * A->GetElement(1, k) + n[2] * A->GetElement(2, k);
    rp.sliceOrigin[k] = od[k] / od[3];
  }
}

//------------------------------------------------------------------------------
spaceskip::Camera vtkSpaceSkipPropertyTranslator::ToCamera(
  vtkRenderer* ren, vtkOpenGLCamera* cam, vtkVolume* vol)
{
  vtkMatrix4x4* wcvc;
  vtkMatrix3x3* norms;
  vtkMatrix4x4* vcdc;
  vtkMatrix4x4* wcdc;
  cam->GetKeyMatrices(ren, wcvc, norms, vcdc, wcdc);
  vtkNew<vtkMatrix4x4> view, proj, viewModel;
  vtkMatrix4x4::Transpose(wcvc, view); // key matrices are stored transposed for OpenGL
  vtkMatrix4x4::Transpose(vcdc, proj);
  vtkMatrix4x4::Multiply4x4(view, vol->GetMatrix(), viewModel);
  spaceskip::Camera camera;
  camera.view = ToCore(viewModel);
  camera.proj = ToCore(proj);
  return camera;
}

//------------------------------------------------------------------------------
void vtkSpaceSkipPropertyTranslator::Reset()
{
  this->ColorKey = this->OpacityKey = nullptr;
  this->ColorMTime = this->OpacityMTime = 0;
  this->HaveTF = false;
}

//------------------------------------------------------------------------------
void vtkSpaceSkipPropertyTranslator::UpdateLabels(spaceskip::Engine& engine, bool labelMap,
  int labelSampling, const vtkSpaceSkipLabelEdits& edits, vtkVolumeProperty* prop,
  const double scalarRange[2])
{
  spaceskip::RenderParams rp = engine.renderParams();
  const spaceskip::LabelSampling sampling =
    labelSampling == 0 ? spaceskip::LabelSampling::Nearest : spaceskip::LabelSampling::Blend;
  if (rp.labelMap != labelMap || rp.labelSampling != sampling)
  {
    rp.labelMap = labelMap;
    rp.labelSampling = sampling;
    engine.setRenderParams(rp);
  }
  if (!labelMap)
  {
    return;
  }
  vtkColorTransferFunction* ctf = prop ? prop->GetRGBTransferFunction(0) : nullptr;
  vtkPiecewiseFunction* otf = prop ? prop->GetScalarOpacity(0) : nullptr;
  std::map<int, spaceskip::Label> labels;
  auto base = [&](int id) {
    spaceskip::Label l;
    l.id = id;
    double rgb[3] = { 1, 1, 1 };
    if (ctf)
    {
      ctf->GetColor(id, rgb);
    }
    l.r = float(rgb[0]);
    l.g = float(rgb[1]);
    l.b = float(rgb[2]);
    l.opacity = otf ? float(otf->GetValue(id)) : 1.f;
    return l;
  };
  if (ctf && ctf->GetIndexedLookup())
  {
    for (int i = 0; i < ctf->GetNumberOfAnnotatedValues(); ++i)
    {
      bool ok = false;
      const double v = ctf->GetAnnotatedValue(i).ToDouble(&ok);
      if (!ok || !(v >= -32768 && v <= 65535) || v != std::floor(v))
      {
        continue; // not an id an 8- or 16-bit label map can hold
      }
      spaceskip::Label l = base(int(v));
      double rgba[4] = { 1, 1, 1, 1 };
      ctf->GetIndexedColor(i, rgba);
      l.r = float(rgba[0]);
      l.g = float(rgba[1]);
      l.b = float(rgba[2]);
      labels[l.id] = l;
    }
  }
  for (const auto& e : edits)
  {
    spaceskip::Label l = labels.count(e.first) ? labels[e.first] : base(e.first);
    const vtkSpaceSkipLabelEdit& x = e.second;
    if (x.HasColor)
    {
      l.r = float(x.Color[0]);
      l.g = float(x.Color[1]);
      l.b = float(x.Color[2]);
    }
    if (x.HasOpacity)
    {
      l.opacity = float(x.Opacity);
    }
    if (x.HasVisible)
    {
      l.visible = x.Visible;
    }
    labels[e.first] = l;
  }
  if (labels.empty() && scalarRange[0] <= scalarRange[1] && scalarRange[1] - scalarRange[0] < 65536)
  {
    for (double v = std::ceil(scalarRange[0]); v <= scalarRange[1]; v += 1)
    {
      labels[int(v)] = base(int(v));
    }
  }
  spaceskip::LabelTable table;
  table.unitDistance = prop ? prop->GetScalarOpacityUnitDistance(0) : 1.0;
  for (const auto& l : labels)
  {
    table.labels.push_back(l.second);
  }
  engine.setLabelTable(table);
}
