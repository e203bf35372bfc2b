// vtkSpaceSkipSettings: the settings of a vtkSpaceSkippingVolumeMapper as plain values (its own
// properties and the vtkVolumeMapper ones it reads), what its helpers take instead of the mapper:
// the property translator (build and render parameters) and the composite mapper (its blocks'
// mappers get the same). Internal to the module (not wrapped, not installed).
#ifndef vtkSpaceSkipSettings_h
#define vtkSpaceSkipSettings_h

#include "vtkAbstractMapper.h" // For VTK_SCALAR_MODE_USE_POINT_DATA, VTK_GET_ARRAY_BY_ID
#include "vtkType.h"           // For vtkIdType
#include "vtkVolumeMapper.h"   // For the blend modes

#include "spaceskip/Tuning.h" // For Tuning
#include "vtkSpaceSkipPropertyTranslator.h" // For vtkSpaceSkipLabelEdits

#include <algorithm> // For std::copy_n
#include <string>    // For ArrayName

class vtkPlaneCollection;

struct vtkSpaceSkipSettings
{
  // vtkSpaceSkippingVolumeMapper's properties (same values and defaults).
  int Builder = 9;
  int LeafCriterion = 1;
  int MaxLeafSize = 0;
  int BinCount = 4;
  int MacroCellSize = 8;
  double SampleDistance = 0.0;
  int Backend = 0;
  int FilterMode = 0;
  bool EarlyRayTermination = true;
  bool EightBitComposite = true;
  bool GPUComposite = true;
  bool UseJittering = false;
  float GlobalIlluminationReach = 0.0f;
  float VolumetricScatteringBlending = 0.0f;
  vtkIdType DeviceMemoryBudget = 0;
  int VectorMode = 1;
  int VectorComponent = 0;
  std::string Transfer2DYAxisArray; // empty: none
  int Transfer2DYAxisComponent = 0;
  int BlendModeOverride = -1;
  int WholeExtent[6] = { 0, -1, 0, -1, 0, -1 };
  double WholeOrigin[3] = { 0, 0, 0 };
  double WholeScalarRange[2] = { 1, 0 };
  double WholeSecondAxisRange[2] = { 1, 0 }; // empty: the input's own (all blocks')
  spaceskip::Tuning Tuning;
  bool LabelMap = false;        // label maps (issue 37)
  int LabelSampling = 1;
  vtkSpaceSkipLabelEdits LabelEdits;

  // vtkVolumeMapper's (and vtkAbstractMapper's) settings the mapper reads.
  int BlendMode = 0;
  double AverageIPScalarRange[2] = { VTK_DOUBLE_MIN, VTK_DOUBLE_MAX };
  int ScalarMode = 0;
  int ArrayAccessMode = 0;
  int ArrayId = -1;
  std::string ArrayName;
  bool Cropping = false;
  int CroppingRegionFlags = 0;
  double CroppingRegionPlanes[6] = { 0, 1, 0, 1, 0, 1 };
  vtkPlaneCollection* ClippingPlanes = nullptr; // the mapper's, not owned
  /// The mapper's bounds (slice mode's plane through the centre); filled in slice mode only.
  double Bounds[6] = { 0, -1, 0, -1, 0, -1 };

  // The mapper's settings as values, for its helpers (the translator, the composite mapper).
  template <typename Mapper>
  static vtkSpaceSkipSettings From(Mapper* m)
  {
    vtkSpaceSkipSettings s;
    s.Builder = m->GetBuilder();
    s.LeafCriterion = m->GetLeafCriterion();
    s.MaxLeafSize = m->GetMaxLeafSize();
    s.BinCount = m->GetBinCount();
    s.MacroCellSize = m->GetMacroCellSize();
    s.SampleDistance = m->GetSampleDistance();
    s.Backend = m->GetBackend();
    s.FilterMode = m->GetFilterMode();
    s.EarlyRayTermination = m->GetEarlyRayTermination() != 0;
    s.EightBitComposite = m->GetEightBitComposite() != 0;
    s.GPUComposite = m->GetGPUComposite() != 0;
    s.UseJittering = m->GetUseJittering() != 0;
    s.GlobalIlluminationReach = m->GetGlobalIlluminationReach();
    s.VolumetricScatteringBlending = m->GetVolumetricScatteringBlending();
    s.DeviceMemoryBudget = m->GetDeviceMemoryBudget();
    s.VectorMode = m->GetVectorMode();
    s.VectorComponent = m->GetVectorComponent();
    s.Transfer2DYAxisArray = m->GetTransfer2DYAxisArray() ? m->GetTransfer2DYAxisArray() : "";
    s.Transfer2DYAxisComponent = m->GetTransfer2DYAxisComponent();
    s.BlendModeOverride = m->GetBlendModeOverride();
    m->GetWholeExtent(s.WholeExtent);
    m->GetWholeOrigin(s.WholeOrigin);
    m->GetWholeScalarRange(s.WholeScalarRange);
    m->GetWholeSecondAxisRange(s.WholeSecondAxisRange);
    s.Tuning = m->GetTuning();
    s.LabelMap = m->GetLabelMap() != 0;
    s.LabelSampling = m->GetLabelSampling();
    s.LabelEdits = m->GetLabelEdits();
    s.BlendMode = m->GetBlendMode();
    std::copy_n(m->GetAverageIPScalarRange(), 2, s.AverageIPScalarRange);
    s.ScalarMode = m->GetScalarMode();
    s.ArrayAccessMode = m->GetArrayAccessMode();
    s.ArrayId = m->GetArrayId();
    s.ArrayName = m->GetArrayName() ? m->GetArrayName() : "";
    s.Cropping = m->GetCropping() != 0;
    s.CroppingRegionFlags = m->GetCroppingRegionFlags();
    std::copy_n(m->GetCroppingRegionPlanes(), 6, s.CroppingRegionPlanes);
    s.ClippingPlanes = m->GetClippingPlanes();
    if (s.EffectiveBlendMode() == vtkVolumeMapper::SLICE_BLEND)
    {
      std::copy_n(m->GetBounds(), 6, s.Bounds);
    }
    return s;
  }

  // A block's mapper takes its owner's settings, as vtkMultiBlockVolumeMapper hands its own to
  // each block's. `padded`: the block is a copy holding the drawn scalars alone, as its active
  // point scalars. The whole extent and origin are the block's own (set apart).
  template <typename Mapper>
  void ApplyTo(Mapper* to, bool padded) const
  {
    const vtkSpaceSkipSettings& s = *this;
    to->SetBuilder(s.Builder);
    to->SetLeafCriterion(s.LeafCriterion);
    to->SetMaxLeafSize(s.MaxLeafSize);
    to->SetBinCount(s.BinCount);
    to->SetMacroCellSize(s.MacroCellSize);
    to->SetSampleDistance(s.SampleDistance);
    to->SetBackend(s.Backend);
    to->SetFilterMode(s.FilterMode);
    to->SetEarlyRayTermination(s.EarlyRayTermination);
    to->SetEightBitComposite(s.EightBitComposite);
    to->SetGPUComposite(s.GPUComposite);
    to->SetUseJittering(s.UseJittering);
    to->SetGlobalIlluminationReach(s.GlobalIlluminationReach);
    to->SetVolumetricScatteringBlending(s.VolumetricScatteringBlending);
    to->SetDeviceMemoryBudget(s.DeviceMemoryBudget);
    to->SetTuning(s.Tuning);
    to->SetLabelMap(s.LabelMap);
    to->SetLabelSampling(s.LabelSampling);
    to->SetLabelEdits(s.LabelEdits);
    to->SetVectorMode(s.VectorMode);
    to->SetVectorComponent(s.VectorComponent);
    to->SetTransfer2DYAxisArray(s.Transfer2DYAxisArray.empty() ? nullptr : s.Transfer2DYAxisArray.c_str());
    to->SetTransfer2DYAxisComponent(s.Transfer2DYAxisComponent);
    to->SetWholeSecondAxisRange(s.WholeSecondAxisRange);
    to->SetBlendModeOverride(s.BlendModeOverride);
    to->SetBlendMode(s.BlendMode);
    to->SetAverageIPScalarRange(s.AverageIPScalarRange[0], s.AverageIPScalarRange[1]);
    to->SetScalarMode(padded ? VTK_SCALAR_MODE_USE_POINT_DATA : s.ScalarMode);
    if (!padded && s.ArrayAccessMode == VTK_GET_ARRAY_BY_ID)
    {
      to->SelectScalarArray(s.ArrayId);
    }
    else if (!padded)
    {
      to->SelectScalarArray(s.ArrayName.empty() ? nullptr : s.ArrayName.c_str());
    }
    to->SetCropping(s.Cropping);
    to->SetCroppingRegionFlags(s.CroppingRegionFlags);
    to->SetCroppingRegionPlanes(s.CroppingRegionPlanes);
    if (to->GetClippingPlanes() != s.ClippingPlanes)
    {
      to->SetClippingPlanes(s.ClippingPlanes);
    }
  }

  /// BlendModeOverride when set, else BlendMode.
  int EffectiveBlendMode() const
  {
    return this->BlendModeOverride >= 0 ? this->BlendModeOverride : this->BlendMode;
  }
  /// Whether the effective blend mode accumulates opacity along the ray (composite and
  /// isosurface): pieces drawn apart then compose front to back, a ray's stop included. The
  /// other modes' pieces are blended over one another.
  bool AccumulatesOpacity() const
  {
    const int mode = this->EffectiveBlendMode();
    return mode == vtkVolumeMapper::COMPOSITE_BLEND || mode == vtkVolumeMapper::ISOSURFACE_BLEND;
  }
  /// Whether WholeExtent names an image (the input is a piece of it).
  bool HasWholeExtent() const
  {
    const int* w = this->WholeExtent;
    return w[0] <= w[1] && w[2] <= w[3] && w[4] <= w[5];
  }
};

#endif
