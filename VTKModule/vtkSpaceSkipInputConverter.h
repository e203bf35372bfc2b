// vtkSpaceSkipInputConverter: the mapper's vtkImageData and scalar array -> a spaceskip::Volume.
// Internal to the module (not wrapped, not installed).
#ifndef vtkSpaceSkipInputConverter_h
#define vtkSpaceSkipInputConverter_h

#include "vtkSmartPointer.h" // For Borrowed
#include "vtkType.h"         // For vtkMTimeType, vtkIdType

#include <functional> // For WarnFunction
#include <memory>     // For the warp
#include <string>     // For the problem and warning texts
#include <vector>     // For Converted

class vtkDataArray;
class vtkImageData;
class vtkRectilinearGrid;
namespace spaceskip
{
class Engine;
struct AxisWarp;
struct VolumePiece;
}

class vtkSpaceSkipInputConverter
{
public:
  using WarnFunction = std::function<void(const std::string&)>;

  /**
   * Picks what this frame draws: `scalars` (vtkAbstractMapper::GetScalars of `input`) and,
   * with several components, the one VectorMode/VectorComponent select, as vtkSmartVolumeMapper
   * does; or, with independent components off, 2 or 4 components and composite blending
   * (`composite`), all of them as vtkGPUVolumeRayCastMapper's dependent components (2: colour
   * value + opacity value, 4: RGB + opacity value). Other dependent cases are said once and
   * drawn as the selected component. False, with `problem` set, when nothing can be drawn (no
   * image, empty extent, no point scalars, wrong length, unsupported type).
   * `yAxis` (with composite blending and one drawn component): a second point array whose
   * component `yComponent` is the 2-D transfer function's y axis (vtkGPUVolumeRayCastMapper's
   * Transfer2DYAxisArray); the engine then gets two float components, the drawn value and
   * that one. Where it cannot be used (dependent components, another length or type) it is
   * said once and the gradient magnitude stays the y axis.
   */
  bool Select(vtkImageData* input, vtkDataArray* scalars, int cellFlag, int vectorMode,
    int vectorComponent, bool independentComponents, bool composite, const WarnFunction& warnOnce,
    std::string& problem, vtkDataArray* yAxis = nullptr, int yComponent = 0);

  /**
   * Hands the selected volume to the engine when the data, the array or the component changed
   * since the last call (borrowing native single-component arrays, converting the others to
   * float), then recomputes the scalar range. Returns the seconds of that range pass (0 when
   * nothing changed). `next` (PrefetchTimeStep): the next time step's array, prefetched right
   * after the volume is set (Prefetch), so that its copy queues behind this step's.
   */
  double Update(spaceskip::Engine& engine, const WarnFunction& warnOnce, vtkDataArray* next = nullptr);

  /**
   * The input is a rectilinear grid's points on the virtual lattice over its bounds, drawn
   * through the grid's coordinates (spaceskip::AxisWarp; vtkSpaceSkipRectilinearImage path 4);
   * nullptr: an image. A change reaches the engine with the next Update.
   */
  void SetWarp(std::shared_ptr<const spaceskip::AxisWarp> warp) { this->Warp = std::move(warp); }

  /// Finite range of the scalars the engine reads ({0, 1} when none is finite); with dependent
  /// components, of component 0 (the colour TF's range, as vtkGPUVolumeRayCastMapper's).
  const double* GetScalarRange() const { return this->ScalarRange; }

  /// Dependent components: the finite range of the opacity component (the last), over which
  /// the scalar opacity function is sampled; with a second array as the 2-D transfer
  /// function's y axis, that array's range (its rows span it); nullptr otherwise.
  const double* GetOpacityRange() const
  {
    return this->Dependent || this->SecondAxis ? this->OpacityRange : nullptr;
  }
  /// Dependent components: the opacity component's index (its unit distance is used, as VTK's).
  int GetOpacityComponent() const { return this->Dependent ? this->NumberOfComponents - 1 : 0; }
  /// A second array is the 2-D transfer function's y axis this frame (Select's `yAxis`).
  bool GetSecondAxis() const { return this->SecondAxis; }

  /**
   * The cells of `image` its vtkGhostType cell array does not mark as duplicates of another
   * piece's (the ghost layers on an image piece's faces), [lo, hi) per axis in its extent's
   * indices: 1 with `cells` set from the array, 2 when nothing is marked (`cells` left as given),
   * 0 when every cell is.
   */
  static int UnmarkedCells(vtkImageData* image, int cells[6]);

  /**
   * The input as a piece of the image of extent `whole` (an empty `whole`: its own extent), and
   * the cells it draws: its unmarked cells (UnmarkedCells), or `owned` ([lo, hi) per axis,
   * whole-extent indices) when given (a block of a composite input). Inactive (the serial path)
   * when the input is the whole image without ghosts. `exact`: no rounding bias (a piece
   * composited in float); else `bias` (Tuning::pieceBias, in 1/255).
   */
  static spaceskip::VolumePiece PieceOf(vtkImageData* input, const int whole[6], const int* owned,
    bool exact, double bias, const WarnFunction& warn);

  /// Whether scalars of VTK type `vtkType` are drawn in place (no conversion to float).
  static bool DrawnInPlace(int vtkType);

  /// vtkSpaceSkippingVolumeMapper::FillRangeCaches.
  static bool FillRangeCaches(vtkDataArray* array);

  /// Forgets what the engine was given (a new engine): the next Update hands the volume again.
  void Reset();

private:
  // This frame's selection (Select).
  vtkImageData* Input = nullptr;
  vtkDataArray* Scalars = nullptr;
  int NumberOfComponents = 1;
  bool Magnitude = false;
  int Component = 0;
  bool Dependent = false; // all components, vtkGPUVolumeRayCastMapper's dependent modes
  bool SecondAxis = false; // the drawn component + YAxis's component YComponent
  vtkDataArray* YAxis = nullptr;
  int YComponent = 0;

  // What the engine was last given; compared by identity and MTime to redo only what changed.
  const void* InputKey = nullptr;
  const void* ScalarsKey = nullptr;
  vtkMTimeType InputMTime = 0;
  vtkMTimeType ScalarsMTime = 0;
  const void* YAxisKey = nullptr; // the second axis's array, component and MTime
  int YAxisComponent = 0;
  vtkMTimeType YAxisMTime = 0;
  bool HaveVolume = false;
  std::shared_ptr<const spaceskip::AxisWarp> Warp;
  const void* WarpKey = nullptr; // the warp the engine's volume has
  int Selection = 0; // the component the volume was made from; -1: the magnitude; -2: all
  std::vector<float> Converted; // int/long scalars (or a component, the magnitude) as float
  // The array whose voxels the engine borrows: held so it outlives the engine's use of it.
  vtkSmartPointer<vtkDataArray> Borrowed;
  // The next time step's array whose upload the engine started (Prefetch): held until the next
  // volume reaches the engine, as Engine::prefetchVolume asks.
  vtkSmartPointer<vtkDataArray> Prefetched;
  double ScalarRange[2] = { 0, 1 };
  double OpacityRange[2] = { 0, 1 };

  /**
   * A time step's scalars before they are shown (Update's `next`): the engine starts uploading
   * `next` (Engine::prefetchVolume) and a later Update that finds it as the scalars takes it from
   * the device. Only for an array drawn in place as the volume set is (its type, components,
   * tuple count, standard layout; no second axis): else said once through `warnOnce`. The array
   * is held until the next volume reaches the engine.
   */
  void Prefetch(spaceskip::Engine& engine, vtkDataArray* next, const WarnFunction& warnOnce);
};

/**
 * A vtkRectilinearGrid as the vtkImageData the converter reads, remade only when the grid (its
 * coordinates, its arrays) changed: kept by identity and MTime, so that the converter hands the
 * volume to the engine again only then.
 * - Each coordinate array uniformly spaced (every step within a relative 1e-6 of the mean step):
 *   the same points as an image (origin and extent from the first coordinates, spacing the mean
 *   steps; a descending array: a positive spacing and -1 in the direction matrix), the grid's
 *   point, cell and field data shallow-copied (no copy of the scalars). Drawn as that image.
 * - Otherwise, with `throughCoordinates` (a whole grid, not a piece; one drawn component, linear
 *   interpolation: the mapper decides), strictly monotonic coordinates, ascending or descending:
 *   the grid's arrays shallow-copied onto the virtual lattice over its bounds (spacing (last -
 *   first) / (n - 1) per axis) and the coordinates as a spaceskip::AxisWarp, through which the
 *   engine samples the grid exactly (trilinear in the grid's cells); nothing resampled, no warning.
 * - Otherwise (strictly monotonic coordinates): one warning naming the grid and its largest
 *   relative step deviation, then every point array of the grid resampled (trilinear within
 *   the grid's cells, as float: what vtkResampleToImage gives, without its per-point cell
 *   search) on a uniform lattice over its bounds with the smallest step per axis,
 *   coarsened so that the lattice holds at most kMaxResampleFactor times the grid's points.
 * - Coordinates that are not strictly monotonic, or non-uniform descending ones: `problem`,
 *   nothing drawn.
 * A piece of a larger grid (MPI: `whole` given, the same on every process) is resampled on the
 * whole grid's lattice (the lattice the serial grid gets), at the lattice points its own
 * coordinates span, with a ghost-cell array that marks every lattice cell outside the cells
 * it owns: the pieces are then pieces of one image, composited as image pieces are.
 */
class vtkSpaceSkipRectilinearImage
{
public:
  using WarnFunction = vtkSpaceSkipInputConverter::WarnFunction;
  /// The resampled lattice of a non-uniform grid holds at most this many times its points.
  static constexpr double kMaxResampleFactor = 4.0;

  /// The whole grid a piece belongs to: its bounds, its smallest coordinate step per axis and
  /// its point extent (all processes' pieces together).
  struct WholeGrid
  {
    double Bounds[6] = { 1, -1, 1, -1, 1, -1 };
    double SmallestStep[3] = { 0, 0, 0 };
    int Extent[6] = { 0, -1, 0, -1, 0, -1 };
    /// Every field known (bounds ascending, steps positive, a non-empty extent).
    bool Valid() const;
  };

  /// The image to draw for `grid` (nullptr, with `problem` set, when nothing can be drawn);
  /// with `whole`, `grid` is a piece of that grid.
  vtkImageData* From(vtkRectilinearGrid* grid, const WarnFunction& warn, std::string& problem,
    const WholeGrid* whole = nullptr, bool throughCoordinates = false);

  /// How the last image was made: 0 none, 1 the uniform grid's arrays, 2 resampled on a lattice
  /// of the grid's own (its extent is not the grid's: a WholeExtent of the grid's pieces does not
  /// apply to it), 3 resampled on the whole grid's lattice (GetLatticeWholeExtent()), 4 the
  /// non-uniform grid's own arrays on the virtual lattice over its bounds, drawn through its
  /// coordinates (GetWarp()).
  int GetPath() const { return this->Path; }
  /// Path 3: the whole grid's lattice's extent (the piece's image lies on it).
  const int* GetLatticeWholeExtent() const { return this->LatticeWhole; }
  /// The last image made (null when none).
  vtkImageData* GetImage() const { return this->Image; }
  /// Lets go of the last image (the input is no longer a grid); the next From makes one again.
  void Release() { *this = vtkSpaceSkipRectilinearImage(); }
  /// Path 4: the grid's coordinates, through which the image (the grid's points on the virtual
  /// lattice over its bounds) is drawn; null on the other paths.
  const std::shared_ptr<const spaceskip::AxisWarp>& GetWarp() const { return this->Warp; }

private:
  vtkSmartPointer<vtkImageData> Image;
  const void* Key = nullptr;
  vtkMTimeType MTime = 0;
  WholeGrid KeyWhole;
  int Path = 0;
  bool KeyThrough = false;
  std::shared_ptr<const spaceskip::AxisWarp> Warp;
  int LatticeWhole[6] = { 0, -1, 0, -1, 0, -1 };
  std::string Problem;
};

#endif
