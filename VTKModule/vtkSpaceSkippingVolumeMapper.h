/**
 * @class   vtkSpaceSkippingVolumeMapper
 * @brief   Volume mapper for vtkImageData that ray-marches with empty-space skipping (SpaceSkip).
 *
 * A drop-in for vtkSmartVolumeMapper: point scalars of one component (unsigned/signed char,
 * unsigned/signed short, float, double; int/unsigned int/long are converted to float with a
 * warning), the volume property's colour and scalar-opacity functions and its
 * ScalarOpacityUnitDistance, its Shade/Ambient/Diffuse/Specular/SpecularPower (VTK's headlight or
 * one directional light) and IsoSurfaceValues, and every blend mode of vtkVolumeMapper but slice
 * (composite, maximum/minimum/average intensity with AverageIPScalarRange, additive,
 * isosurface), with vtkGPUVolumeRayCastMapper's semantics. The hierarchy over the occupied macro cells is built by `Builder`
 * (the builders of Morrical/Zellmann et al.); a colour-only transfer-function edit only updates
 * the lookup table, an opacity edit re-classifies and rebuilds only when the occupied cells changed.
 * The image is marched by the CUDA backend when a device is usable (Backend Auto), else by the
 * oneTBB CPU backend, clipped by the depth of opaque geometry already drawn, and blended into
 * the render window as premultiplied RGBA.
 *
 * Bad input (no/cell scalars, several components, unsupported type, empty extent) raises one
 * vtkErrorMacro and draws nothing; backend failures (no device, out of device memory) fall back
 * to the CPU backend with a warning.
 */
#ifndef vtkSpaceSkippingVolumeMapper_h
#define vtkSpaceSkippingVolumeMapper_h

#include "vtkSpaceSkipModule.h" // For export macro
#include "vtkVolumeMapper.h"

#include <memory> // For std::unique_ptr

class vtkOpenGLRenderWindow;
class vtkRenderer;
class vtkVolume;
class vtkWindow;

class VTKSPACESKIP_EXPORT vtkSpaceSkippingVolumeMapper : public vtkVolumeMapper
{
public:
  static vtkSpaceSkippingVolumeMapper* New();
  vtkTypeMacro(vtkSpaceSkippingVolumeMapper, vtkVolumeMapper);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// Same order as spaceskip::BuilderKind.
  enum BuilderTypes
  {
    Naive = 0,
    Grid,
    LBVH,
    LBVHCPU,
    KdTreeCPU,
    KdTreeGPU,
    KdTreeGPUFast,
    Hybrid,
    DistanceGrid
  };
  enum LeafCriterionTypes
  {
    Shallow = 0,
    Deep = 1
  };
  enum BackendTypes
  {
    Auto = 0,
    CPU = 1,
    CUDA = 2
  };

  ///@{
  /**
   * The hierarchy builder (default Grid). Builders a backend cannot run fall back, with a
   * logged warning, to the closest one it can (see GetBuilderUsed()). DistanceGrid is the Grid
   * DDA leaping through empty space with a capped Chebyshev distance field over the macro cells
   * (CPU and CUDA); it is fastest on very sparse data with MacroCellSize 4.
   */
  vtkSetClampMacro(Builder, int, Naive, DistanceGrid);
  vtkGetMacro(Builder, int);
  void SetBuilderToNaive() { this->SetBuilder(Naive); }
  void SetBuilderToGrid() { this->SetBuilder(Grid); }
  void SetBuilderToLBVH() { this->SetBuilder(LBVH); }
  void SetBuilderToLBVHCPU() { this->SetBuilder(LBVHCPU); }
  void SetBuilderToKdTreeCPU() { this->SetBuilder(KdTreeCPU); }
  void SetBuilderToKdTreeGPU() { this->SetBuilder(KdTreeGPU); }
  void SetBuilderToKdTreeGPUFast() { this->SetBuilder(KdTreeGPUFast); }
  void SetBuilderToHybrid() { this->SetBuilder(Hybrid); }
  void SetBuilderToDistanceGrid() { this->SetBuilder(DistanceGrid); }
  const char* GetBuilderAsString();
  ///@}

  ///@{
  /**
   * k-d tree halting: Shallow (node volume < 10% of the root) or Deep (leaf volume <= 8^3).
   */
  vtkSetClampMacro(LeafCriterion, int, Shallow, Deep);
  vtkGetMacro(LeafCriterion, int);
  void SetLeafCriterionToShallow() { this->SetLeafCriterion(Shallow); }
  void SetLeafCriterionToDeep() { this->SetLeafCriterion(Deep); }
  ///@}

  ///@{
  /**
   * Maximum leaf edge in cells (0: unlimited; the paper uses 32 and 128).
   */
  vtkSetClampMacro(MaxLeafSize, int, 0, VTK_INT_MAX);
  vtkGetMacro(MaxLeafSize, int);
  ///@}

  ///@{
  /**
   * Bins of the k-d tree split search (KdTreeGPU/KdTreeGPUFast), default 4: 2..64 tries
   * bins - 1 planes per node (the paper's binned method); 0 sweeps every macro-cell boundary
   * along the node's longest axis, which builds exactly the KdTreeCPU tree (KdTreeCPU always
   * sweeps and ignores this value). Negative values set 0, 1 sets 2, above 64 sets 64.
   */
  virtual void SetBinCount(int bins);
  vtkGetMacro(BinCount, int);
  ///@}

  ///@{
  /**
   * Edge of the macro cells in voxels used for classification and skipping (default 8, the
   * paper's; clamped to [1, 64]); 4 suits very sparse data with DistanceGrid. A change redoes the
   * per-cell value ranges, the classification and the hierarchy (the image stays the same).
   */
  vtkSetClampMacro(MacroCellSize, int, 1, 64);
  vtkGetMacro(MacroCellSize, int);
  ///@}

  ///@{
  /**
   * Distance between samples along a ray, in the volume's data coordinates (before the
   * vtkVolume's matrix). <= 0 (default): half the smallest spacing.
   */
  vtkSetMacro(SampleDistance, double);
  vtkGetMacro(SampleDistance, double);
  ///@}

  ///@{
  /**
   * Auto (default): CUDA when a usable device exists, else CPU.
   */
  vtkSetClampMacro(Backend, int, Auto, CUDA);
  vtkGetMacro(Backend, int);
  void SetBackendToAuto() { this->SetBackend(Auto); }
  void SetBackendToCPU() { this->SetBackend(CPU); }
  void SetBackendToCUDA() { this->SetBackend(CUDA); }
  ///@}

  ///@{
  /**
   * Stop a ray once its opacity reaches 0.99 (default on).
   */
  vtkSetMacro(EarlyRayTermination, vtkTypeBool);
  vtkGetMacro(EarlyRayTermination, vtkTypeBool);
  vtkBooleanMacro(EarlyRayTermination, vtkTypeBool);
  ///@}

  ///@{
  /**
   * When >= 0, the blend mode used instead of vtkVolumeMapper::BlendMode (same values). -1
   * (default): BlendMode. For front ends whose BlendMode menu lacks modes this mapper has
   * (ParaView 5.11 offers composite, isosurface and slice only).
   */
  vtkSetClampMacro(BlendModeOverride, int, -1, vtkVolumeMapper::ISOSURFACE_BLEND);
  vtkGetMacro(BlendModeOverride, int);
  ///@}

  ///@{
  /**
   * Statistics of the last build and frame.
   */
  double GetLastBuildSeconds();
  double GetLastClassifySeconds();
  double GetLastRenderSeconds();
  vtkIdType GetNodeCount();
  int GetTreeHeight();
  vtkIdType GetLeafCount();
  /// Fraction of occupied macro cells in the last classification.
  double GetOccupancy();
  /// "cpu" or "cuda": the backend that drew the last frame ("none" before the first one).
  const char* GetBackendUsed();
  /// The builder that actually ran (after fallbacks), as a name; "none" before the first build.
  const char* GetBuilderUsed();
  ///@}

  ///@{
  /**
   * How often each stage ran since this mapper was created (counts survive backend changes).
   * Tests use them to check that a colour-only edit neither re-classifies nor rebuilds.
   */
  int GetBuildCount();
  int GetClassifyCount();
  int GetColorUpdateCount();
  int GetFrameCount();
  ///@}

  void Render(vtkRenderer* ren, vtkVolume* vol) override;
  void ReleaseGraphicsResources(vtkWindow*) override;

protected:
  vtkSpaceSkippingVolumeMapper();
  ~vtkSpaceSkippingVolumeMapper() override;

  int Builder = Grid;
  int LeafCriterion = Deep;
  int MaxLeafSize = 0;
  int BinCount = 4;
  int MacroCellSize = 8;
  double SampleDistance = 0.0;
  int Backend = Auto;
  vtkTypeBool EarlyRayTermination = 1;
  int BlendModeOverride = -1;

private:
  vtkSpaceSkippingVolumeMapper(const vtkSpaceSkippingVolumeMapper&) = delete;
  void operator=(const vtkSpaceSkippingVolumeMapper&) = delete;

  // Reads the window depth of the viewport into the internal buffer (resolving MSAA if needed).
  bool ReadDepth(vtkOpenGLRenderWindow* renWin, int x0, int y0, int width, int height);
  /// BlendModeOverride when set, else BlendMode.
  int EffectiveBlendMode() const
  {
    return this->BlendModeOverride >= 0 ? this->BlendModeOverride : this->BlendMode;
  }

  struct vtkInternals;
  std::unique_ptr<vtkInternals> Internals;
};

#endif
