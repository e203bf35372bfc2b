// vtkSpaceSkipInputConverter: the mapper's vtkImageData and scalar array -> a spaceskip::Volume.
// Internal to the module (not wrapped, not installed).
#ifndef vtkSpaceSkipInputConverter_h
#define vtkSpaceSkipInputConverter_h

#include "vtkSmartPointer.h" // For Borrowed
#include "vtkType.h"         // For vtkMTimeType, vtkIdType

#include <functional> // For WarnFunction
#include <string>     // For the problem and warning texts
#include <vector>     // For Converted

class vtkDataArray;
class vtkImageData;
namespace spaceskip
{
class Engine;
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
   */
  bool Select(vtkImageData* input, vtkDataArray* scalars, int cellFlag, int vectorMode,
    int vectorComponent, bool independentComponents, bool composite, const WarnFunction& warnOnce,
    std::string& problem);

  /**
   * Hands the selected volume to the engine when the data, the array or the component changed
   * since the last call (borrowing native single-component arrays, converting the others to
   * float), then recomputes the scalar range. Returns the seconds of that range pass (0 when
   * nothing changed).
   */
  double Update(spaceskip::Engine& engine, const WarnFunction& warnOnce);

  /// Finite range of the scalars the engine reads ({0, 1} when none is finite); with dependent
  /// components, of component 0 (the colour TF's range, as vtkGPUVolumeRayCastMapper's).
  const double* GetScalarRange() const { return this->ScalarRange; }

  /// Dependent components: the finite range of the opacity component (the last), over which
  /// the scalar opacity function is sampled; nullptr otherwise.
  const double* GetOpacityRange() const { return this->Dependent ? this->OpacityRange : nullptr; }
  /// Dependent components: the opacity component's index (its unit distance is used, as VTK's).
  int GetOpacityComponent() const { return this->Dependent ? this->NumberOfComponents - 1 : 0; }

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

  // What the engine was last given; compared by identity and MTime to redo only what changed.
  const void* InputKey = nullptr;
  const void* ScalarsKey = nullptr;
  vtkMTimeType InputMTime = 0;
  vtkMTimeType ScalarsMTime = 0;
  bool HaveVolume = false;
  int Selection = 0; // the component the volume was made from; -1: the magnitude; -2: all
  std::vector<float> Converted; // int/long scalars (or a component, the magnitude) as float
  // The array whose voxels the engine borrows: held so it outlives the engine's use of it.
  vtkSmartPointer<vtkDataArray> Borrowed;
  double ScalarRange[2] = { 0, 1 };
  double OpacityRange[2] = { 0, 1 };
};

#endif
