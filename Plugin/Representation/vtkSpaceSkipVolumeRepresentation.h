// ParaView's image-data volume representation with vtkSpaceSkippingVolumeMapper installed.
/**
 * @class vtkSpaceSkipVolumeRepresentation
 * @brief "Space Skipping Volume": vtkImageVolumeRepresentation rendering with empty-space skipping.
 *
 * Everything but the mapper comes from vtkImageVolumeRepresentation: input handling, colour and
 * opacity transfer functions, the outline on ranks without data, ordered compositing in parallel
 * (each rank renders its own piece; ParaView composites the pieces in visibility order).
 * The setters forward to the mapper; the getters report its last build and frame.
 *
 * Input: vtkImageData, and the vtkPartitionedDataSet of vtkImageData that ParaView makes of
 * partitioned, multiblock and partitioned-collection image data (the base class keeps those for
 * vtkMultiBlockVolumeMapper; the mapper draws each block with its own hierarchy), and
 * vtkRectilinearGrid (ParaView shows rectilinear grids through the image representation): the
 * mapper draws it as an image (vtkSpaceSkippingVolumeMapper.h).
 */
#ifndef vtkSpaceSkipVolumeRepresentation_h
#define vtkSpaceSkipVolumeRepresentation_h

#include "vtkImageVolumeRepresentation.h"
#include "vtkSpaceSkipRepresentationModule.h" // for export macro

#include <memory> // for std::shared_ptr
#include <string> // for std::string
#include <vector> // for std::vector

class vtkImageData;
class vtkMultiProcessController;
class vtkSpaceSkipMPIExchange;
class vtkSpaceSkippingVolumeMapper;

class VTKSPACESKIPREPRESENTATION_EXPORT vtkSpaceSkipVolumeRepresentation
  : public vtkImageVolumeRepresentation
{
public:
  static vtkSpaceSkipVolumeRepresentation* New();
  vtkTypeMacro(vtkSpaceSkipVolumeRepresentation, vtkImageVolumeRepresentation);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// Mapper parameters (see vtkSpaceSkippingVolumeMapper).
  void SetBuilder(int builder);
  int GetBuilder();
  void SetLeafCriterion(int criterion);
  int GetLeafCriterion();
  void SetMaxLeafSize(int mls);
  int GetMaxLeafSize();
  void SetBinCount(int bins);
  int GetBinCount();
  void SetMacroCellSize(int size);
  int GetMacroCellSize();
  void SetSampleDistance(double distance);
  double GetSampleDistance();
  void SetBackend(int backend);
  int GetBackend();
  void SetDeviceMemoryBudget(int mib);
  void SetEarlyRayTermination(int on);
  int GetEarlyRayTermination();
  void SetUseJittering(int on);
  void SetGPUComposite(int on);
  int GetGPUComposite();
  void SetInteractiveAdjustSampleDistances(int on);
  int GetInteractiveAdjustSampleDistances();
  ///@{
  /// The stock Volume's Global Illumination Reach and Volumetric Scattering Blending (shared
  /// properties; the base class hands them to VTK's mappers only): to our mapper as well. The
  /// anisotropy reaches it through the volume property (ScatteringAnisotropy).
  ///@{
  /// The base class's setters (hidden: the same properties), which also decide whether a piece
  /// under MPI needs its neighbours' points (NeedsNeighbourPoints): when that changes, the
  /// representation asks the pipeline again for its piece, with or without a ghost layer.
  void SetShade(bool shade);
  void SetUseTransfer2D(bool use);
  void SetUseGradientForTransfer2D(bool use);
  ///@}
  void SetGlobalIlluminationReach(float reach);
  void SetVolumetricScatteringBlending(float blending);
  ///@}
  int GetUseJittering();
  void SetFilterMode(int mode);
  int GetFilterMode();
  /// The blend modes ParaView 5.11's Blend Mode menu lacks (vtkSpaceSkippingVolumeMapper's
  /// BlendModeOverride): -1 follows Blend Mode.
  void SetExtraBlendMode(int mode);
  int GetExtraBlendMode();
  /// Under MPI: composite the ranks' pieces in float on rank 0 (the serial image; on by
  /// default) instead of ParaView's 8-bit compositing of the ranks' images (vtkSpaceSkipMPIExchange).
  void SetFloatCompositing(int on);
  vtkGetMacro(FloatCompositing, int);
  /// Label map (docs/labelmaps.md): Off, On, or Auto (default): on when the colour map is
  /// categorical (IndexedLookup, ParaView's "Interpret Values As Categories") and the drawn
  /// array is one component of 8- or 16-bit integers. Decided on every render.
  enum LabelMapModes
  {
    LabelMapOff = 0,
    LabelMapOn = 1,
    LabelMapAuto = 2
  };
  void SetLabelMapMode(int mode);
  vtkGetMacro(LabelMapMode, int);
  /// Whether the mapper draws a label map now (Auto decided).
  int GetLabelMapUsed();
  /// vtkSpaceSkippingVolumeMapper::NearestLabel (0) or BlendedLabel (1, default).
  void SetLabelSampling(int sampling);
  int GetLabelSampling();
  /// Hidden Labels: label ids the label map does not draw (the mapper's SetLabelVisibility);
  /// ParaView sets the list as ShowAllLabels then HideLabel per id.
  void HideLabel(int id);
  void ShowAllLabels();
  ///@}

  ///@{
  /// Statistics of the mapper's last build and frame on this process (rank 0 in parallel).
  double GetLastBuildSeconds();
  double GetLastClassifySeconds();
  double GetLastRenderSeconds();
  double GetSampleDistanceUsed();
  double GetNodeCount();
  int GetTreeHeight();
  double GetLeafCount();
  double GetOccupancy();
  const char* GetBackendUsed();
  /// The CUDA device the mapper drew with ("none" when not the CUDA backend): "device N of M",
  /// under MPI followed by "(node rank r of k)" (one rank per GPU).
  const char* GetCudaDeviceUsed();
  /// How the last frame reached the window: "gpu (blend B)" (CUDA-GL interop; B "cuda" or
  /// "gl"), "host (blend gl)" (through host memory) or "none".
  const char* GetCompositePathUsed();
  /// Under MPI, how the ranks' pieces met (the mapper's GetPieceCompositingUsed): "none" alone.
  const char* GetPieceCompositingUsed();
  const char* GetBuilderUsed();
  const char* GetBuilderChoice();
  const char* GetResidency();
  int GetBuildCount();
  int GetClassifyCount();
  int GetColorUpdateCount();
  int GetFrameCount();
  ///@}

  /// The mapper itself (for C++ callers and tests).
  vtkSpaceSkippingVolumeMapper* GetSpaceSkippingMapper() { return this->SpaceSkipMapper; }

protected:
  vtkSpaceSkipVolumeRepresentation();
  ~vtkSpaceSkipVolumeRepresentation() override;

  /// The base class hands the colour map's Magnitude/Component choice only to VTK's own
  /// mappers; this passes it to ours as well.
  void UpdateMapperParameters() override;

  /// With float compositing under MPI: asks the view to draw every rank in every frame
  /// (RENDER_EMPTY_IMAGES), as the exchange needs, and keeps the view's FXAA off (see
  /// KeepFXAAOffVolumes).
  int ProcessViewRequest(vtkInformationRequestKey* request_type, vtkInformation* inInfo,
    vtkInformation* outInfo) override;
  int FloatCompositing = 1;
  std::shared_ptr<vtkSpaceSkipMPIExchange> Exchange;
  // Creates the exchange and gathers the bounds of all ranks' data (DataBounds, set first) for
  // the mapper (collective: every rank's RequestData).
  void UpdateExchange(vtkMultiProcessController* controller);
  /// Under MPI: this rank's number among its node's ranks (-1: not asked yet), given to the
  /// mapper as its CUDA device (one rank per GPU), and how many ranks share the node.
  int NodeRank = -1;
  int RanksOnNode = 1;

  ///@{
  /// In pieces (MPI): the whole extent and the whole data's scalar range go to the mapper, which
  /// samples the whole image's lattice and draws its own cells only; the pieces then composite
  /// to the serial image. Pieces share their face points, so a piece needs no ghost layer unless
  /// a sample reads a gradient (NeedsNeighbourPoints: one layer, kept, where the base class crops
  /// it away) or it is a rectilinear grid (three: resampled on the whole grid's lattice). A ghost
  /// layer costs the first frame: the reader runs again for it, VTK's pipeline marks every point
  /// and cell of the piece in a ghost array and ParaView then takes the new arrays' ranges, one
  /// value at a time (a first frame of 8.4 s against 0.6 s at 512^3 on 2 ranks of the 2-core
  /// machine).
  int RequestUpdateExtent(vtkInformation* request, vtkInformationVector** inputVector,
    vtkInformationVector* outputVector) override;
  int RequestData(vtkInformation* request, vtkInformationVector** inputVector,
    vtkInformationVector* outputVector) override;
  /// Finite ranges of the colour array over all ranks (lo, hi per component, then the
  /// magnitude's); empty in a serial run.
  std::vector<double> WholeRanges;
  // Color Array 2's range over all ranks, as WholeRanges (MPI; empty: none).
  std::vector<double> SecondWholeRanges;
  ///@}
  /// vtkPartitionedDataSet input, which the base class renders only with
  /// vtkMultiBlockVolumeMapper: the same cache of partitions for our mapper (it accepts composite
  /// input), with the outline and data size of the whole.
  int RequestPartitionedData(vtkInformation*, vtkInformationVector**, vtkInformationVector*);
  /// An image piece with ghost layers (under MPI): the base class's RequestData without its crop
  /// of the ghost cells (the mapper draws the piece's own cells; the crop copied every tuple).
  int RequestPieceWithGhosts(vtkImageData* input, vtkInformation*, vtkInformationVector**,
    vtkInformationVector*);
  /// Whether a sample reads points beyond its cell's corners: a gradient (shading, or a 2-D
  /// transfer function over the gradient magnitude).
  bool NeedsNeighbourPoints();
  /// Under MPI, after a change of NeedsNeighbourPoints: the piece is requested again.
  void NeighbourNeedMayHaveChanged(bool before);

  int LabelMapMode = LabelMapAuto;
  std::vector<int> HiddenLabels; ///< HideLabel's ids
  /// Sets the mapper's LabelMap from LabelMapMode, the colour map and the drawn array.
  void UpdateLabelMap();

  ///@{
  /// FXAA under MPI: serially VTK's renderer applies FXAA before it draws volumes (volumes are
  /// never smoothed); ParaView 5.11's parallel (IceT) path applies it to the composited frame,
  /// volumes included, so a volume under `mpiexec -n N pvbatch` differed from the serial image
  /// by up to 121/255 over the whole object (ParaView's own Volume alike). With the float
  /// exchange on, the representation turns the view's FXAA off on every rank (said once) and
  /// gives it back when it leaves the view; the exchange's image is then the serial one.
  void KeepFXAAOffVolumes(vtkView* view);
  bool RemoveFromView(vtkView* view) override;
  bool TurnedFXAAOff = false;
  bool WarnedFXAA = false;
  ///@}

  /// The base class re-assigns the mapper to the actor on every render; owned by VolumeMapper.
  vtkSpaceSkippingVolumeMapper* SpaceSkipMapper = nullptr;
  std::string BackendUsedName;
  std::string CudaDeviceUsedName;
  std::string CompositePathText;
  std::string PieceCompositingText;
  std::string BuilderUsedName;
  std::string BuilderChoiceText;
  std::string ResidencyText;

private:
  vtkSpaceSkipVolumeRepresentation(const vtkSpaceSkipVolumeRepresentation&) = delete;
  void operator=(const vtkSpaceSkipVolumeRepresentation&) = delete;
};

#endif
