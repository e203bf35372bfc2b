/**
 * @class   vtkSpaceSkippingVolumeMapper
 * @brief   Volume mapper for vtkImageData that ray-marches with empty-space skipping (SpaceSkip).
 *
 * A drop-in for vtkSmartVolumeMapper: point scalars of one component (unsigned/signed char,
 * unsigned/signed short, float, double; int/unsigned int/long are converted to float with a
 * warning), the volume property's colour and scalar-opacity functions and its
 * ScalarOpacityUnitDistance, its Shade/Ambient/Diffuse/Specular/SpecularPower (with the
 * renderer's lights: VTK's headlight, or up to 8 directional/positional lights such as
 * vtkLightKit's) and IsoSurfaceValues, and every blend mode of vtkVolumeMapper (composite,
 * maximum/minimum/average intensity with AverageIPScalarRange, additive, isosurface, slice with
 * the property's SliceFunction plane), its 2-D transfer function (TF_2D: value x gradient
 * magnitude) and gradient opacity (composite blending of one component; skipping stays lossless),
 * with vtkGPUVolumeRayCastMapper's semantics. The hierarchy over the occupied macro cells is built by `Builder`
 * (the builders of Morrical/Zellmann et al.); a colour-only transfer-function edit only updates
 * the lookup table, an opacity edit re-classifies and rebuilds only when the occupied cells changed.
 * The image is marched by the CUDA backend when a device is usable (Backend Auto), else by the
 * oneTBB CPU backend, clipped by the depth of opaque geometry already drawn, and blended into
 * the render window as premultiplied RGBA.
 *
 * Composite input (vtkMultiBlockDataSet, vtkPartitionedDataSet, vtkPartitionedDataSetCollection
 * of vtkImageData) draws every image block with a hierarchy of its own, back to front (see
 * GetBounds()).
 *
 * vtkRectilinearGrid input (alone or as blocks): uniformly spaced coordinates (each step within
 * a relative 1e-6 of the mean) are drawn as the image of the same points, the grid's arrays
 * shared, not copied (a descending array: a mirrored direction matrix). A non-uniform grid
 * drawn alone (linear interpolation, one drawn component, no label map, no second y-axis array)
 * is drawn through its coordinates (spaceskip::AxisWarp: the grid's points on a uniform lattice
 * over its bounds, sampled trilinearly in the grid's own cells; no copy, no warning); otherwise
 * (blocks, pieces composited across processes, the other cases) with one warning, resampled
 * trilinearly on a uniform lattice (the smallest step per axis, at most 4x the grid's points)
 * once per change of the grid (docs/rendering.md, Rectilinear grids; docs/limits.md).
 *
 * Bad input (no/cell scalars, several components, unsupported type, empty extent) raises one
 * vtkErrorMacro and draws nothing; backend failures (no device, out of device memory) fall back
 * to the CPU backend with a warning.
 */
#ifndef vtkSpaceSkippingVolumeMapper_h
#define vtkSpaceSkippingVolumeMapper_h

#include "vtkSpaceSkipModule.h"        // For export macro
#include "vtkSpaceSkipPieceExchange.h" // For PieceImage, PieceExchange
#include "vtkVolumeMapper.h"
#include "vtkWrappingHints.h" // For VTK_NEWINSTANCE

#include <map>    // For GetLabelEdits
#include <memory> // For std::unique_ptr
#include <string> // For WarnOnce

class vtkDataArray;
class vtkRenderer;
struct vtkSpaceSkipLabelEdit;
class vtkVolume;
class vtkWindow;
#ifndef __VTK_WRAP__
namespace spaceskip
{
struct Tuning; // Core/spaceskip/Tuning.h
}
#endif

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
    DistanceGrid,
    AutoBuilder ///< measures Naive and a few structures (the close ones twice) and keeps the fastest
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
  /// Same values as spaceskip::FilterMode.
  enum FilterModeTypes
  {
    ExactFilter = 0,
    HardwareFilter = 1
  };

  // The setters of the enumerated and bounded properties below take a value outside their
  // domain (a script, a saved state) as the nearest one in it, with one warning naming the
  // property, the value and what was used (vtkSetClampMacro's rule, said).

  ///@{
  /**
   * The hierarchy builder (default Grid). Builders a backend cannot run fall back, with a
   * logged warning, to the closest one it can (see GetBuilderUsed()). DistanceGrid is the Grid
   * DDA leaping through empty space with a capped Chebyshev distance field over the macro cells
   * (CPU and CUDA); it is fastest on very sparse data with MacroCellSize 4.
   */
  virtual void SetBuilder(int builder);
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
  void SetBuilderToAuto() { this->SetBuilder(AutoBuilder); }
  const char* GetBuilderAsString();
  ///@}

  ///@{
  /**
   * k-d tree halting: Shallow (node volume < 10% of the root) or Deep (leaf volume <= 8^3).
   */
  virtual void SetLeafCriterion(int criterion);
  vtkGetMacro(LeafCriterion, int);
  void SetLeafCriterionToShallow() { this->SetLeafCriterion(Shallow); }
  void SetLeafCriterionToDeep() { this->SetLeafCriterion(Deep); }
  ///@}

  ///@{
  /**
   * Maximum leaf edge in cells (0: unlimited; the paper uses 32 and 128).
   */
  virtual void SetMaxLeafSize(int cells);
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
  virtual void SetMacroCellSize(int cells);
  vtkGetMacro(MacroCellSize, int);
  ///@}

  ///@{
  /**
   * Distance between samples along a ray, in the volume's data coordinates (before the
   * vtkVolume's matrix). 0 (default): half the smallest spacing. Negative, NaN or infinite:
   * one warning, and 0. The engine clamps what would step below 1/16 of the smallest spacing,
   * take too many samples a ray or step over the volume (more than half its diagonal), said once.
   */
  virtual void SetSampleDistance(double distance);
  vtkGetMacro(SampleDistance, double);
  ///@}

  ///@{
  /**
   * Interactive renders (the render window's DesiredUpdateRate at or above
   * InteractiveUpdateRate, as vtkSmartVolumeMapper decides: VTK's interactors raise it while the
   * user drags, ParaView's view sets 5 for its interactive renders and 0.002 for still ones)
   * whose frame at SampleDistance would take more than a quarter of the volume's allocated render
   * time (ParaView allocates 1/5 s among its renderers) step at least one smallest spacing (as
   * vtkGPUVolumeRayCastMapper does while dragged) and, if that does not fit the allocated time,
   * farther, at most 8 smallest spacings, as far as a model of the last two frames' times (a
   * fixed part plus sampling work that goes as 1 / distance) says fits it or gains at least
   * 20 %; faster frames (e.g. on a GPU) keep SampleDistance. Still renders use SampleDistance, so the picture the user stops at
   * is the exact one. On by default (as vtkSmartVolumeMapper's
   * InteractiveAdjustSampleDistances); a piece of a larger image (MPI) keeps SampleDistance, the
   * same on every process.
   */
  vtkSetMacro(InteractiveAdjustSampleDistances, vtkTypeBool);
  vtkGetMacro(InteractiveAdjustSampleDistances, vtkTypeBool);
  vtkBooleanMacro(InteractiveAdjustSampleDistances, vtkTypeBool);
  vtkSetClampMacro(InteractiveUpdateRate, double, 1.0e-10, 1.0e10);
  vtkGetMacro(InteractiveUpdateRate, double);
  /// Whether the last render was interactive, and the sample distance it asked the engine for.
  vtkGetMacro(LastRenderInteractive, bool);
  vtkGetMacro(LastRequestedSampleDistance, double);
  ///@}

  ///@{
  /**
   * Auto (default): CUDA when a usable device exists, else CPU. The environment variable
   * SPACESKIP_BACKEND (cpu, cuda or auto; read once per process, said once as a warning)
   * overrides this property for every mapper of the process (to run the tests on a given
   * backend); SPACESKIP_REPORT (any value) prints one line per mapper with the backend, builder
   * and GL_RENDERER whenever they change (docs/tuning.md).
   */
  virtual void SetBackend(int backend);
  vtkGetMacro(Backend, int);
  void SetBackendToAuto() { this->SetBackend(Auto); }
  void SetBackendToCPU() { this->SetBackend(CPU); }
  void SetBackendToCUDA() { this->SetBackend(CUDA); }
  ///@}

  ///@{
  /**
   * How samples between voxels are interpolated (trilinear either way):
   * - ExactFilter (default): in float from the 8 voxels around the sample, on both backends;
   * - HardwareFilter: CUDA backend, the texture unit's trilinear filter, whose weights have
   *   8 bits of fraction (about 1/256 of a voxel): faster (N-body 2048^3 on an H100, DistanceGrid:
   *   1601 against 1211 kernel fps with Auto's exact choice, docs/results/h100-kernel-ab) at a
   *   small cost in accuracy (PSNR per data set: `spaceskip accuracy`, docs/results/paper-bench).
   *   Skipping stays lossless: the
   *   filtered value lies within the 8 voxels' range like the exact one. The CPU backend has no
   *   texture unit and samples exactly (the image is ExactFilter's); volumes with several
   *   dependent components, and volumes drawn with sparse residency (DeviceMemoryBudget), are
   *   sampled exactly too (one warning).
   * With HardwareFilter the CUDA backend holds a second copy of the volume on the device (the
   * texture's array) from its first frame until the data changes.
   */
  virtual void SetFilterMode(int mode);
  vtkGetMacro(FilterMode, int);
  void SetFilterModeToExact() { this->SetFilterMode(ExactFilter); }
  void SetFilterModeToHardware() { this->SetFilterMode(HardwareFilter); }
  const char* GetFilterModeAsString();
  ///@}

  ///@{
  /**
   * Stop a ray once its opacity reaches 1 - 1/255, as vtkGPUVolumeRayCastMapper does (default
   * on): the light it leaves out is below one 8-bit step.
   */
  vtkSetMacro(EarlyRayTermination, vtkTypeBool);
  vtkGetMacro(EarlyRayTermination, vtkTypeBool);
  vtkBooleanMacro(EarlyRayTermination, vtkTypeBool);
  ///@}

  ///@{
  /**
   * Upload the image to the window rounded to 8 bits per channel (default on: the window's
   * colour buffer has 8 bits, and the upload is a quarter of the 32-bit float image's); off
   * uploads 32-bit floats and blends those. With the image kept on the GPU (GPUComposite) it
   * picks the interop texture's format alike: RGBA8 rounded by CUDA, or 32-bit float.
   */
  vtkSetMacro(EightBitComposite, vtkTypeBool);
  vtkGetMacro(EightBitComposite, vtkTypeBool);
  vtkBooleanMacro(EightBitComposite, vtkTypeBool);
  ///@}

  ///@{
  /**
   * Jittering (vtkGPUVolumeRayCastMapper's UseJittering): each pixel's samples start at a
   * random fraction of the sample distance, trading wood-grain artefacts at large sample
   * distances for noise. Skipping stays lossless (the jittered lattice is the same for every
   * builder). Off by default. Cropping (vtkVolumeMapper's regions) and clipping planes
   * (vtkAbstractMapper) are honoured as well; they cut samples exactly.
   */
  vtkSetMacro(UseJittering, vtkTypeBool);
  vtkGetMacro(UseJittering, vtkTypeBool);
  vtkBooleanMacro(UseJittering, vtkTypeBool);
  ///@}

  ///@{
  /**
   * Volumetric shadows and scattering, as vtkGPUVolumeRayCastMapper (VTK 9.2) draws them:
   * VolumetricScatteringBlending in [0, 2] blends the gradient (Phong) shading with the light
   * each shaded sample scatters towards the eye, lit through one shadow ray per light (0: off,
   * the default; 2: scattering only); GlobalIlluminationReach in [0, 1] is how far the shadow
   * rays reach (0: about one sample, 1: across the whole volume). The anisotropy of the phase
   * function is the volume property's ScatteringAnisotropy. Shaded composite and isosurface
   * frames only, as VTK. The shadow rays skip empty space over the bricks classification found
   * empty, so every builder still draws the image of Naive.
   */
  vtkSetClampMacro(GlobalIlluminationReach, float, 0.0f, 1.0f);
  vtkGetMacro(GlobalIlluminationReach, float);
  vtkSetClampMacro(VolumetricScatteringBlending, float, 0.0f, 2.0f);
  vtkGetMacro(VolumetricScatteringBlending, float);
  ///@}

  ///@{
  /**
   * Keep the image on the GPU (default on): with the CUDA backend and the window's OpenGL on the
   * same NVIDIA device, the frame is copied from CUDA memory into a GL texture (CUDA-GL interop)
   * instead of going down to host memory and up again. The copy is queued on the engine's CUDA
   * stream behind the kernel and GL waits for it on the GPU, so Render() returns without waiting
   * for the frame; only the rectangle of the window the volume's box covers is copied and
   * blended (rounded to 8 bits on the GPU with EightBitComposite, as the host path rounds). When interop is not possible (another GL
   * such as Mesa, another device, a CUDA error) the mapper says so once at INFO verbosity and
   * uses host memory from then on. GetCompositePathUsed(): "gpu", "host" or "none".
   * When the window draws into its own single-sample RGBA8 framebuffer (VTK's default), the
   * image is not copied at all: CUDA blends it into that framebuffer's colour texture as GL's
   * blend would, and GL draws nothing for it. GetCompositeBlendUsed(): "cuda" (that path), "gl"
   * (a texture drawn by GL) or "none".
   * With a PieceExchange that takes device pieces (MPI ranks on one host), a piece's float
   * frame stays on the GPU too: the ranks share their frames through CUDA IPC and the process
   * that composites blends them on its GPU (off: through host memory).
   */
  vtkSetMacro(GPUComposite, vtkTypeBool);
  vtkGetMacro(GPUComposite, vtkTypeBool);
  vtkBooleanMacro(GPUComposite, vtkTypeBool);
  const char* GetCompositePathUsed();
  const char* GetCompositeBlendUsed();
  /**
   * With a PieceExchange (MPI ranks), how the last frame's pieces met: on the process that
   * draws, "N pieces blended on the GPU" or "... on the host", and how many of them came
   * through CUDA IPC ("K shared through CUDA IPC") or as pixels over the exchange; on the
   * others, "piece shared through CUDA IPC" or "piece sent as pixels"; "own frame only" where
   * the exchange is off; "none" without an exchange.
   */
  const char* GetPieceCompositingUsed();
  ///@}

  ///@{
  /**
   * The CUDA device the CUDA backend runs on: -1 (default) the rendering thread's current
   * device, as before (CUDA's default, device 0); N >= 0: device N modulo the number of devices.
   * One rank per GPU: ParaView's representation sets the node-local MPI rank. The rendering
   * thread is bound to it before the engine allocates, and every frame after (other code on
   * that thread may switch devices); the first device bound stays this mapper's (its engine's
   * memory lives there), a later change is said once and ignored. The CPU backend never touches
   * CUDA for it. GetCudaDeviceUsed(): "none" (the last frame was not the CUDA backend's), else
   * "device N of M".
   */
  vtkSetMacro(CudaDevice, int);
  vtkGetMacro(CudaDevice, int);
  const char* GetCudaDeviceUsed();
  /**
   * The rectangle of the renderer's viewport the last frame copied and blended (x, y, width,
   * height in pixels): where the volume's box projects (width or height 0 when it projects
   * nowhere in the viewport), the whole viewport when the box reaches behind the eye.
   */
  void GetLastCompositeRect(int rect[4]);
  ///@}

  ///@{
  /**
   * Multi-component scalars (vtkSmartVolumeMapper's API, set by ParaView's representation from
   * the colour map's Magnitude/Component choice): vtkScalarsToColors::MAGNITUDE renders the
   * Euclidean norm of each tuple, COMPONENT (default) the component VectorComponent. With the
   * volume property's IndependentComponents off (ParaView: Multi Components Mapping, or Map
   * Scalars off) and composite blending, 2 components are drawn as colour value + opacity value
   * and 4 as RGB + opacity value, as vtkGPUVolumeRayCastMapper does (these modes are then
   * ignored); 3 components, or another blend mode: one warning, then the selected component.
   */
  vtkSetMacro(VectorMode, int);
  vtkGetMacro(VectorMode, int);
  vtkSetMacro(VectorComponent, int);
  vtkGetMacro(VectorComponent, int);
  ///@}

  ///@{
  /**
   * A second point array as the y axis of the volume property's 2-D transfer function
   * (vtkGPUVolumeRayCastMapper::SetTransfer2DYAxisArray; ParaView: Use Transfer 2D with Use
   * Gradient For Transfer 2D off and a Color Array 2): the table is read at (the drawn value,
   * component Transfer2DYAxisComponent of this array), each normalised over its own range, and a
   * brick is skipped when its values of this array reach no row of the table with opacity.
   * nullptr (default): the gradient magnitude is the y axis. Composite blending of one drawn
   * component; the two values are drawn as float (8 bytes a voxel).
   */
  vtkSetStringMacro(Transfer2DYAxisArray);
  vtkGetStringMacro(Transfer2DYAxisArray);
  vtkSetClampMacro(Transfer2DYAxisComponent, int, 0, VTK_INT_MAX);
  vtkGetMacro(Transfer2DYAxisComponent, int);
  ///@}

  ///@{
  /**
   * When >= 0, the blend mode used instead of vtkVolumeMapper::BlendMode (same values). -1
   * (default): BlendMode. For front ends whose BlendMode menu lacks modes this mapper has
   * (ParaView 5.11 offers composite, isosurface and slice only).
   */
  virtual void SetBlendModeOverride(int mode);
  vtkGetMacro(BlendModeOverride, int);
  ///@}

  ///@{
  /**
   * The input as one piece of a larger image (ParaView's ranks under MPI; set by
   * vtkSpaceSkipVolumeRepresentation). WholeExtent: the extent of the whole image the input is a
   * piece of; the rays then sample the whole image's lattice, as a serial render of it would, and
   * the mapper draws only the input's own cells: those not marked ghost in its vtkGhostType cell
   * array (ghost layers are read by interpolation and shading), half-open so that composited
   * pieces give the serial image. WholeScalarRange: the whole image's range of the drawn scalars
   * (the transfer function's table spans it on every rank). Empty (the defaults): the input's
   * own extent and range.
   * For composite input (image blocks, each rank holding some of them): WholeExtent and
   * WholeOrigin describe the image the blocks of all ranks make, on the blocks' spacing and
   * orientation, its point WholeExtent[0,2,4] at WholeOrigin (pass the same bits on every rank);
   * the blocks then sample its lattice and their table spans WholeScalarRange. Empty: the image
   * this process's blocks make, and their range.
   */
  vtkSetVector6Macro(WholeExtent, int);
  vtkGetVector6Macro(WholeExtent, int);
  vtkSetVector3Macro(WholeOrigin, double);
  vtkGetVector3Macro(WholeOrigin, double);
  vtkSetVector2Macro(WholeScalarRange, double);
  vtkGetVector2Macro(WholeScalarRange, double);
  ///@}

  /**
   * The point extent of the cells of `image` that its vtkGhostType cell array does not mark as
   * duplicates of another piece's (the cells this mapper draws of a piece): its own extent when
   * none is marked. False (`extent` its own extent) when every cell is marked.
   */
  static bool GetOwnedExtent(vtkImageData* image, int extent[6]);

  /**
   * Fills `array`'s range caches, the per-component ranges vtkDataArray::GetRange and
   * GetFiniteRange return (its PER_COMPONENT and PER_FINITE_COMPONENT information), in one
   * parallel pass per component, where VTK holds none yet; the same values VTK would compute
   * (GetRange skips NaN, GetFiniteRange +-Inf too). VTK 9.2 takes a range one value at a time
   * (about 22 ns a value on one core: 1.5 s for 64 Mi voxels), and ParaView takes both ranges of
   * every array of every new piece it draws. Contiguous arrays of the types the mapper reads
   * natively (8/16-bit integers, float, double) with 1 to 4 components; false (nothing set) for
   * others, for an empty array or one whose caches are already filled.
   */
  static bool FillRangeCaches(vtkDataArray* array);

  ///@{
  /**
   * Time steps: a simulation's steps played as new scalar arrays of the same image.
   *
   * NewTimeStepArray: an array for one step's scalars in host memory that the CUDA backend
   * uploads at the link's full rate, in one DMA with no staging copy (page-locked; ordinary
   * memory with Backend CPU or where none can be locked): `dataType` one the mapper draws in
   * place (VTK_UNSIGNED_CHAR, VTK_CHAR, VTK_SIGNED_CHAR, VTK_SHORT, VTK_UNSIGNED_SHORT,
   * VTK_FLOAT, VTK_DOUBLE), `numberOfComponents` x `numberOfTuples` values, not initialized. A
   * reader or simulation that writes its steps into such arrays spares each step the staging
   * copy that pageable memory takes. Returns a new reference (its memory goes with the last
   * reference), or nullptr with an error for another type or a size that cannot be had.
   *
   * PrefetchTimeStep: the array the input's scalars will be next (drawn in place: the type,
   * components and tuple count of the scalars shown). At the next Render() the CUDA backend
   * starts uploading it on a second stream while that frame is drawn; the Render() that shows
   * it takes it from the device. The mapper holds the array until then: keep its values
   * unchanged meanwhile. One call serves one Render(). The CPU backend reads voxels in place
   * and does nothing here; an array that cannot be drawn in place is said once and uploaded when
   * shown. Image input only (composite input ignores it). nullptr: none.
   */
  VTK_NEWINSTANCE
  vtkDataArray* NewTimeStepArray(int dataType, int numberOfComponents, vtkIdType numberOfTuples);
  void PrefetchTimeStep(vtkDataArray* next);
  ///@}

  ///@{
  /**
   * The range of the 2-D transfer function's y-axis array (Transfer2DYAxisArray, its component
   * Transfer2DYAxisComponent) over the whole data this input is a piece of: the 2-D table's
   * rows span it on every rank, as they span the whole array's range in a serial render (set by
   * vtkSpaceSkipVolumeRepresentation under MPI). Empty (the default): the input's own range; for
   * composite input, the range over all its blocks.
   */
  vtkSetVector2Macro(WholeSecondAxisRange, double);
  vtkGetVector2Macro(WholeSecondAxisRange, double);
  ///@}

  ///@{
  /**
   * The most device memory the voxels may take, in MiB (0, the default: the free device memory
   * less what the mapper's other structures need). A volume above it stays sparse: only the
   * bricks the transfer function, blend mode and shading make visible are kept on the device
   * (uploaded on an edit, the least recently needed evicted), and the image is the in-core one.
   * A view whose visible bricks exceed it is drawn by the CPU backend, said once.
   * GetResidency() reports which ran. The CPU backend ignores it.
   */
  virtual void SetDeviceMemoryBudget(vtkIdType mib);
  vtkGetMacro(DeviceMemoryBudget, vtkIdType);
  /// "in core", "sparse: R of N bricks resident (P MiB pool)", or "none" before the first frame.
  const char* GetResidency();
  /// Bricks resident in the sparse pool after the last frame (0 in core).
  vtkIdType GetResidentBricks();
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
  ///@}

  ///@{
  /**
   * Where the last Render() spent its wall time, in seconds (host clocks; GL calls are
   * asynchronous, so the composite time is the texture upload and the draw's submission):
   * - ScalarRange: the table's range, only when the data changed: for a time step (a volume of
   *   the last one's shape) of one component (8/16-bit integers, float) the engine's upload and
   *   brick value ranges, reduced (no pass of its own over the voxels; Engine::valueRange),
   *   else a pass over the voxels;
   * - Update: the engine's upload and value ranges (data changed, where ScalarRange did not do
   *   them), classification (opacity edit) and hierarchy build (see
   *   GetLastBuildSeconds/GetLastClassifySeconds);
   * - DepthRead: reading the window's depth buffer (waits for the GL work before it);
   * - EngineRender: the engine's frame: depth upload, kernel, image readback (CUDA), or the
   *   CPU ray march; GetLastRenderSeconds() is the same frame as the engine timed it. With the
   *   image kept on the GPU (GPUComposite) the host does not wait for the kernel: this is its
   *   launch, the GPU finishes the frame after Render() returns, and GetLastRenderSeconds() is
   *   the kernel's time (asking for it waits for the frame);
   * - Kernel: the render kernel alone (CUDA events; with the image kept on the GPU asking for it
   *   waits for the frame), or the CPU frame on the CPU backend;
   * - Composite: image texture upload (or the interop copy's submission) and the blending quad;
   * - Mapper: the whole of Render().
   */
  double GetLastScalarRangeSeconds();
  double GetLastUpdateSeconds();
  double GetLastDepthReadSeconds();
  double GetLastEngineRenderSeconds();
  double GetLastKernelSeconds();
  double GetLastCompositeSeconds();
  /**
   * Whether the last frame read the window's depth buffer: only when something besides volumes
   * and 2D actors is visible in the renderer (or it preserves an earlier layer's depth); a scene
   * of volumes alone skips the readback.
   */
  bool GetLastFrameReadDepth();
  double GetLastMapperSeconds();
  ///@}

  ///@{
  vtkIdType GetLeafCount();
  /// Fraction of occupied macro cells in the last classification.
  double GetOccupancy();
  /// "cpu" or "cuda": the backend that drew the last frame ("none" before the first one).
  const char* GetBackendUsed();
  /// The builder that actually ran (after fallbacks), as a name; "none" before the first build.
  const char* GetBuilderUsed();
  /// The sample distance of the last frame in world units, after the engine's bounds (at least
  /// 1/16 of the smallest spacing, at most 2^20 samples per ray); 0 before the first frame.
  double GetSampleDistanceUsed();
  /// Builder Auto: what it chose and why, one line (empty for the other builders).
  const char* GetBuilderChoice();
  /// Bytes of device memory SpaceSkip holds now (all mappers of the process; 0 without CUDA).
  vtkIdType GetDeviceBytesInUse();
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
  /// Volumes of the shape shown before (time steps), and how many of them the Render() that
  /// showed them found on the device (PrefetchTimeStep).
  int GetTimeStepCount();
  int GetPrefetchedTimeStepCount();
  /// How often the colour (scalar-opacity) function was sampled into the engine's table: only
  /// when that function, its range (or the property's unit distance, for opacity) changed.
  int GetColorTableSampleCount();
  int GetOpacityTableSampleCount();
  ///@}

  ///@{
  /**
   * Label map: the scalars (one component of 8- or 16-bit integers; other types are drawn as an
   * ordinary volume, with one warning) are label ids, each drawn with its own colour and opacity;
   * values without a label are transparent, and sampling never draws a label that is not among
   * the voxels around the sample, so no border shows the colours of the ids between its two
   * labels. The labels: when the volume property's colour function has IndexedLookup on, its
   * annotated values with their indexed colours (ParaView's categorical colour map); the ids
   * given to SetLabelColor, SetLabelOpacity or SetLabelVisibility, which override what they set;
   * with neither, every integer of the scalar range. A label's opacity is the scalar opacity
   * function at its id unless set here. Hiding a label or changing which labels have opacity re-
   * classifies bricks over their label sets (no voxel pass): as cheap as an opacity edit. Blend
   * mode composite only. Off by default.
   */
  vtkSetMacro(LabelMap, vtkTypeBool);
  vtkGetMacro(LabelMap, vtkTypeBool);
  vtkBooleanMacro(LabelMap, vtkTypeBool);
  /// NearestLabel: the nearest voxel's label (blocky borders); BlendedLabel (default): of the 8
  /// voxels around the sample, the label whose trilinear weights sum highest (smooth borders).
  enum LabelSamplingTypes
  {
    NearestLabel = 0,
    BlendedLabel = 1
  };
  vtkSetClampMacro(LabelSampling, int, NearestLabel, BlendedLabel);
  vtkGetMacro(LabelSampling, int);
  void SetLabelColor(int id, double r, double g, double b);
  void SetLabelOpacity(int id, double opacity);
  void SetLabelVisibility(int id, vtkTypeBool visible);
  /// Forgets SetLabelVisibility for `id` (its colour and opacity set here stay).
  void RemoveLabelVisibility(int id);
  /// Forgets the labels set on the mapper (the property's stay).
  void RemoveAllLabels();
  ///@}
#ifndef __VTK_WRAP__
  /// The labels set on the mapper, by id (vtkSpaceSkipPropertyTranslator.h).
  const std::map<int, vtkSpaceSkipLabelEdit>& GetLabelEdits() const;
  void SetLabelEdits(const std::map<int, vtkSpaceSkipLabelEdit>& edits);
#endif

  void Render(vtkRenderer* ren, vtkVolume* vol) override;
  void ReleaseGraphicsResources(vtkWindow*) override;

#ifndef __VTK_WRAP__
  /**
   * The engine's and the compositor's knobs (spaceskip::Tuning, Core/spaceskip/Tuning.h; the
   * defaults are the product's behaviour), for benchmarks and tests: the kernels' launch, the
   * sub-brick masks, DistanceGrid's field, the piece bias under MPI, the CUDA blend, the
   * composited rectangle. The blocks of composite input get the same (docs/tuning.md).
   */
  void SetTuning(const spaceskip::Tuning& tuning);
  const spaceskip::Tuning& GetTuning() const;
#endif

#ifndef __VTK_WRAP__
  /**
   * Float compositing of the pieces of several processes (ParaView's ranks under MPI; set by
   * vtkSpaceSkipVolumeRepresentation with its MPI implementation). While one is set and the input
   * is a piece of a larger image (WholeExtent: a vtkImageData piece, or composite input whose
   * blocks lie on the whole image's lattice), every Render() calls Begin(), renders the piece (or
   * each block) exactly (no 8-bit rounding bias) into a float image and hands them to Finish(),
   * whose answer says what this process draws: the pieces of all processes composited
   * in float on one of them, nothing on the others, so that the 8-bit compositing that follows
   * (IceT) only adds empty images to one exact image.
   */
  /// A process's piece image and the exchange (vtkSpaceSkipPieceExchange.h).
  using PieceImage = vtkSpaceSkipPieceImage;
  using PieceExchange = vtkSpaceSkipPieceExchange;
  void SetPieceExchange(const std::shared_ptr<PieceExchange>& exchange);
  /// The whole image's bounds, the same on every process: while a PieceExchange is set the
  /// volume reports them (GetBounds()), so that no renderer culls a piece that is out of view
  /// or empty while the others wait for it. Uninitialized (the default): the input's own.
  void SetWholeBounds(const double bounds[6]);
  /// The smallest coordinate step per axis of the whole vtkRectilinearGrid the input is a piece
  /// of (all processes' pieces; with WholeBounds and WholeExtent, the same on every process): a
  /// non-uniform piece is then resampled on the lattice the whole grid gets serially, so that
  /// the pieces composite as the pieces of one image. 0 (the default): unknown, and a
  /// non-uniform piece under a PieceExchange is not drawn.
  void SetWholeGridSteps(const double steps[3]);
  const std::shared_ptr<PieceExchange>& GetPieceExchange() const;
#endif

  /**
   * Composite input (vtkMultiBlockDataSet, vtkPartitionedDataSet,
   * vtkPartitionedDataSetCollection of vtkImageData): the union of the image blocks' bounds.
   * Each image block is drawn by a mapper of its own (its own hierarchy), front to back, by the
   * vtkSpaceSkipMultiBlockVolumeMapper this mapper hands composite input to, as
   * vtkMultiBlockVolumeMapper does; other blocks are skipped with one warning. The statistics
   * then add up the blocks (times, nodes, leaves, stage counts; the tree height is the largest,
   * the occupancy the voxel-weighted mean, names one per distinct value joined by '/').
   */
  double* GetBounds() override;
  using vtkAbstractVolumeMapper::GetBounds;

  /**
   * The input as a data set; for composite input its first non-empty vtkImageData block
   * (ParaView's vtkPVLODVolume draws a vtkVolumeMapper only when GetInput() has the selected
   * scalars).
   */
  vtkDataSet* GetInput() override;
  using vtkVolumeMapper::GetInput;

protected:
  vtkSpaceSkippingVolumeMapper();
  ~vtkSpaceSkippingVolumeMapper() override;

  int Builder = AutoBuilder;
  int LeafCriterion = Deep;
  int MaxLeafSize = 0;
  int BinCount = 4;
  int MacroCellSize = 8;
  double SampleDistance = 0.0;
  vtkTypeBool InteractiveAdjustSampleDistances = 1;
  double InteractiveUpdateRate = 1.0;
  bool LastRenderInteractive = false;
  double LastRequestedSampleDistance = 0.0;
  int Backend = Auto;
  int FilterMode = ExactFilter;
  vtkTypeBool EarlyRayTermination = 1;
  vtkTypeBool EightBitComposite = 1;
  vtkTypeBool GPUComposite = 1;
  vtkTypeBool UseJittering = 0;
  float GlobalIlluminationReach = 0.0f;
  float VolumetricScatteringBlending = 0.0f;
  int CudaDevice = -1;
  vtkIdType DeviceMemoryBudget = 0;
  int VectorMode = 1; // vtkScalarsToColors::COMPONENT
  int VectorComponent = 0;
  char* Transfer2DYAxisArray = nullptr;
  int Transfer2DYAxisComponent = 0;
  int BlendModeOverride = -1;
  int WholeExtent[6] = { 0, -1, 0, -1, 0, -1 };
  double WholeOrigin[3] = { 0, 0, 0 };
  double WholeScalarRange[2] = { 1, 0 };
  double WholeSecondAxisRange[2] = { 1, 0 };
  vtkTypeBool LabelMap = 0;
  int LabelSampling = BlendedLabel;

  /// vtkImageData, and composite data sets of them (see GetBounds()).
  int FillInputPortInformation(int port, vtkInformation* info) override;

private:
  vtkSpaceSkippingVolumeMapper(const vtkSpaceSkippingVolumeMapper&) = delete;
  void operator=(const vtkSpaceSkippingVolumeMapper&) = delete;

  // Says a warning once per distinct message for the life of the mapper.
  void WarnOnce(const std::string& message);

  // Render() without the piece exchange: draws this input (or keeps it for the composite
  // mapper); with it (MPI), the pieces of all processes composited in float.
  void RenderLocal(vtkRenderer* ren, vtkVolume* vol);
  void RenderExchanged(vtkRenderer* ren, vtkVolume* vol);

  struct vtkInternals;
  std::unique_ptr<vtkInternals> Internals;
  // A block of composite input as vtkSpaceSkipMultiBlockVolumeMapper drives it.
  struct vtkBlock;
};

#endif
